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
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "../../scripts"))
from gmsh_quads import write_quads  # noqa: E402

Z, A = 1e-3, 40.5e-3
D = A / 1000.0
n = int(sys.argv[1]) if len(sys.argv) > 1 else 12
xs = [-D + (A + D) * k / n for k in range(n + 1)]
nodes = [(x, y, Z) for y in xs for x in xs]


def node(i, j):
    return j * (n + 1) + i + 1


quads = [(node(i, j), node(i + 1, j), node(i + 1, j + 1), node(i, j + 1)) for j in range(n) for i in range(n)]

write_quads("plate", nodes, quads)
