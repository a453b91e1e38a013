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
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "../../scripts"))
from gmsh_quads import write_quads  # noqa: E402

X, Y0, TIP, HALF = 0.5e-3, -2e-3, 50e-3, 0.8008e-3
n = int(sys.argv[1]) if len(sys.argv) > 1 else 26  # elements along y (2 mm each by default)
ys = [Y0 + (TIP - Y0) * k / n for k in range(n + 1)]
nodes = [(X, y, z) for y in ys for z in (-HALF, HALF)]
quads = [(2 * k + 1, 2 * k + 3, 2 * k + 4, 2 * k + 2) for k in range(n)]

write_quads("panel", nodes, quads)
