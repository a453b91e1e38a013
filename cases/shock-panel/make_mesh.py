#!/usr/bin/env python3
"""Writes panel.msh (gmsh 4.1): the steel panel of Giordano et al. (2005) as one strip of shells.

Mid-surface x = 0.5 mm (the panel occupies x in [0, 1] mm), y from -2 mm (one element below the
tube floor y = 0, clamped with the row at y = 0, so the fluid sees no gap at the root) to the tip
at y = 50 mm, z in [-0.8008, 0.8008] mm: the one-cell fluid slab's width (z in [-0.8, 0.8] mm)
and a thousandth more, so that the surface spans the slab (no gap at its symmetry planes) while
the strip's mass per width and the load the slab puts on it agree to 0.1% (a strip wider than the
slab would carry the mass of the extra width without its load).
Quadrilateral node order gives the normal +x (downstream). Units: metres.

Run: python3 cases/shock-panel/make_mesh.py [N_ALONG] > cases/shock-panel/panel.msh
"""
import sys

X, Y0, TIP, HALF = 0.5e-3, -2e-3, 50e-3, 0.8008e-3
n = int(sys.argv[1]) if len(sys.argv) > 1 else 26  # elements along y (2 mm each by default)
ys = [Y0 + (TIP - Y0) * k / n for k in range(n + 1)]
nodes = [(X, y, z) for y in ys for z in (-HALF, HALF)]
quads = [(2 * k + 1, 2 * k + 3, 2 * k + 4, 2 * k + 2) for k in range(n)]

print("$MeshFormat\n4.1 0 8\n$EndMeshFormat")
print('$PhysicalNames\n1\n2 1 "panel"\n$EndPhysicalNames')
print(f"$Entities\n0 0 1 0\n1 {X} {Y0} {-HALF} {X} {TIP} {HALF} 1 1 0\n$EndEntities")
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
