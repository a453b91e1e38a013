//! Sze, Liu & Lo (2004, Finite Elem. Anal. Des. 40:1551), slit annular plate under a line
//! force. Inner radius 6, outer radius 10, h = 0.03, E = 21e6, ν = 0; clamped along one side
//! of the slit, a transverse line force q = 0.8 per unit length (q_max) along the other.
//! Mesh: 10 (radial) x 80 (circumferential) 4-node shells, the paper's S4R mesh, and a mesh
//! twice as fine split into triangles (flat triangles lock here). Reference: the paper's table
//! (W_A at the inner radius, W_B at the outer, on the loaded side), as committed in MBDyn's test suite
//! (tests/plates/sze2004/sze33/sze33_ref.dat, "mesh: 10x80; 6x30 quite similar").

mod common;

use common::{displacement, max_error, run_table, Table};
use structure_solver::assembly::{Curve, FeModel, Part};
use structure_solver::elements::ShellSection;
use structure_solver::mesh::{generate, Mesh};

const ROWS: &[(f64, &[f64])] = &[
    (0.025, &[1.305, 1.789]),
    (0.05, &[2.455, 3.370]),
    (0.075, &[3.435, 4.720]),
    (0.10, &[4.277, 5.876]),
    (0.125, &[5.007, 6.872]),
    (0.15, &[5.649, 7.736]),
    (0.20, &[6.725, 9.160]),
    (0.25, &[7.602, 10.288]),
    (0.30, &[8.340, 11.213]),
    (0.35, &[8.974, 11.992]),
    (0.40, &[9.529, 12.661]),
    (0.45, &[10.023, 13.247]),
    (0.50, &[10.468, 13.768]),
    (0.55, &[10.876, 14.240]),
    (0.60, &[11.257, 14.674]),
    (0.65, &[11.620, 15.081]),
    (0.70, &[11.970, 15.469]),
    (0.75, &[12.310, 15.842]),
    (0.80, &[12.642, 16.202]),
    (0.85, &[12.966, 16.550]),
    (0.90, &[13.282, 16.886]),
    (0.95, &[13.590, 17.212]),
    (1.00, &[13.891, 17.528]),
];

fn run(mesh: Mesh, name: &str, tol: f64) {
    let sec = ShellSection { e: 21e6, nu: 0.0, rho: 1.0, h: 0.03 };
    let mut m = FeModel::new(&mesh, |_| Part::Shell(sec)).unwrap();
    m.fix(mesh.node_set("u0").unwrap(), [true; 6]);
    // line force on the free side (θ = 2π, set u1), consistent nodal shares
    let edge = mesh.node_set("u1").unwrap();
    let q = 0.8;
    let seg = 4.0 / (edge.len() - 1) as f64;
    for (k, &n) in edge.iter().enumerate() {
        let w = if k == 0 || k + 1 == edge.len() { 0.5 } else { 1.0 };
        m.point_load(n, 2, q * seg * w, Curve::Linear);
    }
    let a = edge[0];
    let b = edge[edge.len() - 1];
    assert!((mesh.nodes[a][0] - 6.0).abs() < 1e-9 && (mesh.nodes[b][0] - 10.0).abs() < 1e-9);
    let table = Table { name, columns: &["W_A", "W_B"], rows: ROWS };
    let errors = run_table(&mut m, &table, |m| vec![displacement(m, a)[2], displacement(m, b)[2]]);
    assert!(max_error(&errors) < tol, "{name}: max error {}", max_error(&errors));
}

#[test]
#[cfg_attr(debug_assertions, ignore = "benchmark of several seconds: run with --release")]
fn quads_10x80_follow_the_reference() {
    run(
        generate::annulus(6.0, 10.0, [0.0, 2.0 * std::f64::consts::PI], 80, 10),
        "slit plate quads 10x80",
        0.02,
    );
}

/// Flat triangles with a constant-strain membrane lock on the twisted surface: on the paper's
/// mesh split in two they are 2.6% stiff at q_max (W_A), so, as for the hemisphere, they run
/// on a mesh twice as fine (DESIGN §8), where they are within about 1.1%.
#[test]
#[cfg_attr(debug_assertions, ignore = "benchmark of several seconds: run with --release")]
fn triangles_20x160_follow_the_reference() {
    run(
        generate::annulus(6.0, 10.0, [0.0, 2.0 * std::f64::consts::PI], 160, 20).to_triangles(),
        "slit plate triangles 20x160x2",
        0.015,
    );
}
