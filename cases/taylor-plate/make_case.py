#!/usr/bin/env python3
"""Writes case.toml: Taylor's (1941) air-backed plate, the incident wave as the initial condition.

The exponential wave p_i = p_m e^{-t/theta} is put in the water column at t = 0 as a right-running
simple wave with its front at the plate: at each grid node x_j < x_p of the uniform box mesh,
p = p0 + p_m exp((x_j - x_p)/(c0 theta)), rho from the isentrope of the stiffened gas and
u = 2 (c - c0)/(gamma - 1) (the left-running Riemann invariant u - 2c/(gamma-1) of the water at rest).
The fluid has only piecewise-constant initial regions, so each node gets its own half-space
region x > x_j - h/2 (later regions win): the nodal values are exact, no staircase error.

Run: python3 cases/taylor-plate/make_case.py > cases/taylor-plate/case.toml
     python3 cases/taylor-plate/make_case.py --shells > cases/taylor-plate/case-shells.toml
     python3 cases/taylor-plate/make_case.py --smooth > cases/taylor-plate/case-smooth.toml

The first moves the plate with rigid-structure (a rigid body with one x dof); the second with
structure-solver: one MITC4 shell (plate.msh, 0.2 m square, the column's 0.1 m square
centred on it) free only in x, its mass rho t A the rigid body's; its four nodes are probed,
and their mean velocity is the plate's.

--smooth writes the case of the temporal order study (tests/tests/coupling_order.rs): the same
rigid plate hit by a smooth pulse p_i(t) = p_m sin^4(pi t / T_p) on [0, T_p], zero after, whose
pressure and first three derivatives are continuous (the exponential wave starts with a jump,
which makes the load non-smooth in time and the observed orders drop). The same simple-wave
construction puts it in the column: p = p0 + p_i((x_p - x_j)/c0) at each node x_j. p_m is small
enough that the wet face stays far from p_cut (the plate lags the pulse, so the water behind
the peak is pulled below p0 by about (2 m / Z) max|p_i'|, 0.5 p_m here) and the plate moves by
about 8 um, far under the 2.5 mm between it and the nearest node plane. The column is coarser
(h = 5 mm, the pulse over 65 cells) and shorter (the wave the plate reflects is not back from
the left boundary before t_end), and the fluid takes 4 fixed substeps per coupling step of
2.5e-6 s: 6.25e-7 s, 93% of the stable step at CFL 0.9 (the tet column's CFL length is about
h/4), so that the study's four levels stay cheap.
"""
import math
import sys

# Water: stiffened gas; air: perfect gas; both at the ambient p0 (no pressure difference on the plate).
GAMMA, PC, RHO0, P0 = 4.4, 6e8, 1000.0, 1e5
AIR_RHO, AIR_GAMMA = 1.2, 1.4
PM, THETA = 1e6, 2e-4          # incident peak [Pa], decay time [s]
AREAL_MASS = 100.0             # plate areal mass m [kg/m^2]
SECTION = 0.1                  # the column's square section side [m]
LO, HI, CELLS = -1.0, 0.2, 480 # box along x: h = 2.5 mm
XP = 1.25e-3                   # the plate, midway between two grid planes
DT, T_END = 2e-6, 4e-4         # coupling step, end time

SHELLS = "--shells" in sys.argv[1:]
SMOOTH = "--smooth" in sys.argv[1:]
assert not (SHELLS and SMOOTH), "--smooth moves the rigid plate"
SUBSTEPS, CFL = None, 0.5
if SMOOTH:
    PM, T_P = 1e5, 2e-4            # the sin^4 pulse: peak [Pa], duration [s]
    LO, HI, CELLS = -0.5, 0.1, 120 # h = 5 mm
    XP = 2.5e-3                    # midway between two grid planes
    DT, T_END = 2.5e-6, 2.5e-4     # the study's coarsest coupling step; the pulse and 0.8 m/Z
    SUBSTEPS, CFL = 4, 0.9
    SEEDS = (-0.25, 0.05)          # the water and the air
else:
    SEEDS = (-0.5, 0.1)
PLATE_SIDE = 0.2               # the wet square (rigid) and the shell (plate.msh) [m]
# The shell: Taylor's plate does not deform, and one element's twist (its nodes take the load
# unequally, since the fluid splits the quad into two triangles) must stay small against its
# translation, so it is 20 mm thick and 100 times as stiff as steel; rho t A is the rigid mass.
SHELL_E, SHELL_T = 2e13, 0.02
h = (HI - LO) / CELLS
c0 = math.sqrt(GAMMA * (P0 + PC) / RHO0)
half = SECTION / 2


def pulse(s):
    """The smooth incident pressure over p0 at the time s after its front."""
    return PM * math.sin(math.pi * s / T_P) ** 4 if 0.0 <= s <= T_P else 0.0


def wave(x):
    if SMOOTH:
        p = P0 + pulse((XP - x) / c0)
    else:
        p = P0 + PM * math.exp((x - XP) / (c0 * THETA))
    rho = RHO0 * ((p + PC) / (P0 + PC)) ** (1.0 / GAMMA)
    c = math.sqrt(GAMMA * (p + PC) / rho)
    return rho, 2.0 * (c - c0) / (GAMMA - 1.0), p


MASS = AREAL_MASS * SECTION**2
# The shell's four nodes: their mean velocity is the plate's momentum over its mass (the load
# reaches them unequally, since the fluid splits the quad into two triangles, and the one
# element's twist is free to take the difference).
CORNER_PROBES = "\n".join(
    f'[[structure.probes]]\nname = "plate{k}"\npoint = [{XP}, {y}, {z}]\n'
    for k, (y, z) in enumerate([(-0.1, -0.1), (0.1, -0.1), (0.1, 0.1), (-0.1, 0.1)])
)
if SHELLS:
    STRUCTURE = f"""[structure]
command = ["structure-solver"]
mesh = {{ generator = "gmsh", file = "plate.msh" }}
material = {{ e = {SHELL_E:g}, nu = 0.3, rho = {MASS / (SHELL_T * PLATE_SIDE**2)!r} }}
thickness = {SHELL_T}
element = "mitc4"
integrator = "central_difference"
wet_set = "all"

[[structure.bc]]
set = "all"
fixed = ["uy", "uz", "rx", "ry", "rz"]

{CORNER_PROBES}"""
else:
    STRUCTURE = f"""[structure]
command = ["rigid-structure"]

[structure.rigid]
mass = {round(MASS, 12)!r}
dofs = ["x"]
reference = [{XP}, 0.0, 0.0]
wet_nodes = [[0.0, -0.1, -0.1], [0.0, 0.1, -0.1], [0.0, 0.1, 0.1], [0.0, -0.1, 0.1]]
wet_elements = [[0, 1, 2, 3]]
probe = "plate"
"""

if SMOOTH:
    WAVE = f"""a
# right-running smooth pulse p0 + p_m sin^4(pi s / T_p), s = (x_p - x)/c0 in [0, T_p], p_m {PM:g} Pa,
# T_p {T_P:g} s,"""
    NAME, DESCRIPTION = "taylor-plate-smooth", "Taylor's air-backed plate hit by a smooth pulse (temporal order study)"
else:
    WAVE = f"""a
# right-running exponential wave p0 + p_m e^(-(x_p - x)/(c0 theta)), p_m {PM:g} Pa, theta {THETA:g} s,"""
    NAME = "taylor-plate-shells" if SHELLS else "taylor-plate"
    DESCRIPTION = "Taylor's air-backed plate: an exponential wave in water hits a free rigid plate"
SUBSTEPS_LINE = f"\nsubsteps = {SUBSTEPS}" if SUBSTEPS else ""

print(f"""# Taylor's air-backed plate (1941), generated by make_case.py (edit that, not this file).
# Water (stiffened gas gamma {GAMMA}, p_c {PC:g}, rho0 {RHO0}, p0 {P0:g}; c0 = {c0:.4f} m/s) in a
# one-cell-thick tet column x in [{LO}, {HI}], section {SECTION} m x {SECTION} m, {CELLS} cells; {WAVE}
# its front at the plate x_p = {XP}; air (rho {AIR_RHO}, p {P0:g}) behind. The plate: an embedded
# square wider than the column, {"a shell" if SHELLS else "a rigid body"} of m A = {AREAL_MASS} kg/m^2 x {SECTION**2:g} m^2 with one
# x dof and no spring, moved by {"structure-solver (one MITC4 shell, plate.msh)" if SHELLS else "rigid-structure"} through fsi (C0).
[case]
name = "{NAME}"
description = "{DESCRIPTION}"

[coupling]
scheme = "C0"
dt = {DT:g}
t_end = {T_END:g}
timeout_s = 60.0

{STRUCTURE}
[fluid]
command = ["fluid-solver"]
probes = [{{ name = "water", at = [-0.1, 0.0, 0.0] }}, {{ name = "air", at = [0.05, 0.0, 0.0] }}]

[fluid.fluids.water]
eos = {{ kind = "stiffened_gas", gamma = {GAMMA}, p_c = {PC!r} }}

[fluid.fluids.air]
eos = {{ kind = "perfect_gas", gamma = {AIR_GAMMA} }}

[fluid.mesh]
box = {{ lo = [{LO}, -{half}, -{half}], hi = [{HI}, {half}, {half}], cells = [{CELLS}, 1, 1], shape = "tet" }}

[fluid.initial]
fluid = "water"
state = [{RHO0}, 0.0, 0.0, 0.0, {P0!r}]
regions = [""")
# Each node from the pulse's tail (all of the column for the exponential wave) to the plate.
j = 0 if not SMOOTH else max(0, math.floor((XP - c0 * T_P - LO) / h) + 1)
while LO + j * h < XP:
    x = LO + j * h
    rho, u, p = wave(x)
    print(f'  {{ region = {{ shape = "half_space", point = [{x - h / 2:.17g}, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }}, '
          f'state = [{rho:.17g}, {u:.17g}, 0.0, 0.0, {p:.17g}] }},')
    j += 1
print(f"""  {{ region = {{ shape = "half_space", point = [{XP}, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }}, fluid = "air", state = [{AIR_RHO}, 0.0, 0.0, 0.0, {P0!r}] }},
]

[fluid.boundary]
xmin = {{ kind = "far_field", state = [{RHO0}, 0.0, 0.0, 0.0, {P0!r}] }}
xmax = {{ kind = "far_field", state = [{AIR_RHO}, 0.0, 0.0, 0.0, {P0!r}] }}
ymin = {{ kind = "symmetry" }}
ymax = {{ kind = "symmetry" }}
zmin = {{ kind = "symmetry" }}
zmax = {{ kind = "symmetry" }}

[fluid.embedded]
tracking = "collision"
loads = "facets"
p_cut = 0.0
seeds = [
  {{ at = [{SEEDS[0]}, 0.0, 0.0], active = true }},  # the water
  {{ at = [{SEEDS[1]}, 0.0, 0.0], active = true }},   # the air
]

[fluid.numerics]
flux = "roe"
limiter = "van_albada"
cfl = {CFL}

[fluid.time]
t_end = {T_END:g}{SUBSTEPS_LINE}

[output]
fields_every = 0
checkpoint_every = 0
probes_every = 1""")
