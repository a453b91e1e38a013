//! Sze, Liu & Lo (2004, Finite Elem. Anal. Des. 40:1551): pull-out of an open cylinder.
//! L = 10.35, R = 4.953, h = 0.094, E = 10.5e6, ν = 0.3125, free ends, two opposite radial
//! forces P at mid-length, P_max = 40000. One eighth (axis z, θ ∈ [0, 90°], z ∈ [0, L/2])
//! with three symmetry planes on the paper's 24x36 mesh (24 axial, 36 circumferential);
//! P/4 at A = (0, R, 0). Reference: the paper's table (w_A radial at A, -u_B radial at
//! mid-length 90° from A, -u_C radial at the free end 90° from A), as committed in MBDyn's test suite
//! (tests/plates/sze2004/sze35/sze35_ref.dat); the path turns sharply between 0.50 and 0.525
//! P_max, which load control with step cutting passes.

mod common;

use common::{displacement, run_table, Table};
use structure_solver::assembly::{Curve, FeModel, Part};
use structure_solver::elements::ShellSection;
use structure_solver::mesh::generate;

const ROWS: &[(f64, &[f64])] = &[
    (0.025, &[0.819, 0.864, 0.872]),
    (0.05, &[1.260, 1.471, 1.493]),
    (0.075, &[1.527, 1.901, 1.946]),
    (0.10, &[1.707, 2.217, 2.293]),
    (0.15, &[1.936, 2.641, 2.792]),
    (0.20, &[2.079, 2.904, 3.106]),
    (0.25, &[2.180, 3.087, 3.310]),
    (0.30, &[2.257, 3.227, 3.452]),
    (0.35, &[2.321, 3.342, 3.556]),
    (0.40, &[2.376, 3.443, 3.632]),
    (0.45, &[2.425, 3.539, 3.688]),
    (0.50, &[2.473, 3.653, 3.718]),
    (0.525, &[2.543, 4.061, 3.580]),
    (0.55, &[2.577, 4.171, 3.518]),
    (0.60, &[2.618, 4.274, 3.452]),
    (0.65, &[2.648, 4.338, 3.410]),
    (0.70, &[2.672, 4.385, 3.378]),
    (0.75, &[2.692, 4.423, 3.353]),
    (0.80, &[2.710, 4.455, 3.332]),
    (0.85, &[2.726, 4.483, 3.313]),
    (0.90, &[2.741, 4.508, 3.297]),
    (0.95, &[2.755, 4.530, 3.283]),
    (1.00, &[2.768, 4.551, 3.269]),
];

#[test]
#[cfg_attr(debug_assertions, ignore = "benchmark of several seconds: run with --release")]
fn quads_24x36_follow_the_reference() {
    let (r, l) = (4.953, 10.35);
    let mesh = generate::cylinder(r, l / 2.0, [0.0, generate::QUARTER], 36, 24);
    let sec = ShellSection { e: 10.5e6, nu: 0.3125, rho: 1.0, h: 0.094 };
    let mut m = FeModel::new(&mesh, |_| Part::Shell(sec)).unwrap();
    m.symmetry(mesh.node_set("v0").unwrap(), 2); // z = 0
    m.symmetry(mesh.node_set("u0").unwrap(), 1); // θ = 0: y = 0
    m.symmetry(mesh.node_set("u1").unwrap(), 0); // θ = 90°: x = 0
    let a = mesh.nearest_node([0.0, r, 0.0]);
    let b = mesh.nearest_node([r, 0.0, 0.0]);
    let c = mesh.nearest_node([r, 0.0, l / 2.0]);
    m.point_load(a, 1, 40000.0 / 4.0, Curve::Linear);
    let table =
        Table { name: "pull-out quads 24x36", columns: &["w_A", "-u_B", "-u_C"], rows: ROWS };
    let errors = run_table(&mut m, &table, |m| {
        vec![displacement(m, a)[1], -displacement(m, b)[0], -displacement(m, c)[0]]
    });
    let last = errors.last().unwrap();
    assert!(last.iter().all(|e| e.abs() < 0.02), "final errors {last:?}");
    assert!(common::max_error(&errors) < 0.02, "max error {}", common::max_error(&errors));
}
