#!/usr/bin/env python3
"""Writes plate.msh (gmsh 4.1): a quarter of the clamped steel plate as N x N shells.

Mid-surface z = 1 mm (between the fluid grids' node planes), x and y from -A/1000 to A = 40.5 mm:
the quarter starts a thousandth of its side beyond the symmetry planes x = 0 and y = 0, so that
the surface spans the fluid domain there (no gap, no leak path) while the extra width carries a
thousandth more mass than its load. The edges x = A and y = A are clamped; they lie inside the
fluid (water flows round them), between the node planes of the three fluid grids.
Quadrilateral node order gives the normal +z (away from the bubble). Units: metres.

Run: python3 cases/bubble-plate/make_mesh.py [N] > cases/bubble-plate/plate.msh
"""
import sys

Z, A = 1e-3, 40.5e-3
D = A / 1000.0
n = int(sys.argv[1]) if len(sys.argv) > 1 else 12
xs = [-D + (A + D) * k / n for k in range(n + 1)]
nodes = [(x, y, Z) for y in xs for x in xs]


def node(i, j):
    return j * (n + 1) + i + 1


quads = [(node(i, j), node(i + 1, j), node(i + 1, j + 1), node(i, j + 1)) for j in range(n) for i in range(n)]

print("$MeshFormat\n4.1 0 8\n$EndMeshFormat")
print('$PhysicalNames\n1\n2 1 "plate"\n$EndPhysicalNames')
print(f"$Entities\n0 0 1 0\n1 {-D} {-D} {Z} {A} {A} {Z} 1 1 0\n$EndEntities")
print(f"$Nodes\n1 {len(nodes)} 1 {len(nodes)}\n2 1 0 {len(nodes)}")
for i in range(len(nodes)):
    print(i + 1)
for x, y, z in nodes:
    print(f"{x!r} {y!r} {z!r}")
print("$EndNodes")
print(f"$Elements\n1 {len(quads)} 1 {len(quads)}\n2 1 3 {len(quads)}")
for e, q in enumerate(quads):
    print(e + 1, *q)
print("$EndElements")
