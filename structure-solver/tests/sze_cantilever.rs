//! Sze, Liu & Lo (2004, Finite Elem. Anal. Des. 40:1551), §3.1: cantilever strip under end
//! shear. L = 10, b = 1, h = 0.1, E = 1.2e6, ν = 0, P_max = 4, clamped at x = 0; the paper's
//! 16x1 mesh of 4-node shells and the same mesh split into 32 triangles. Reference: the
//! paper's table of tip deflections (S4R, 16x1), as reproduced in Elmer's test suite
//! (fem/tests/Shell_*Cantilever*, "refres": P/Pmax, -u_tip, w_tip).

mod common;

use common::{displacement, max_error, run_table, Table};
use structure_solver::assembly::{Curve, FeModel, Part};
use structure_solver::elements::ShellSection;
use structure_solver::mesh::{generate, Mesh};

const ROWS: &[(f64, &[f64])] = &[
    (0.05, &[0.026, 0.663]),
    (0.10, &[0.103, 1.309]),
    (0.15, &[0.224, 1.922]),
    (0.20, &[0.381, 2.493]),
    (0.25, &[0.563, 3.015]),
    (0.30, &[0.763, 3.488]),
    (0.35, &[0.971, 3.912]),
    (0.40, &[1.184, 4.292]),
    (0.45, &[1.396, 4.631]),
    (0.50, &[1.604, 4.933]),
    (0.55, &[1.807, 5.202]),
    (0.60, &[2.002, 5.444]),
    (0.65, &[2.190, 5.660]),
    (0.70, &[2.370, 5.855]),
    (0.75, &[2.541, 6.031]),
    (0.80, &[2.705, 6.190]),
    (0.85, &[2.861, 6.335]),
    (0.90, &[3.010, 6.467]),
    (0.95, &[3.151, 6.588]),
    (1.00, &[3.286, 6.698]),
];

fn cantilever(mesh: &Mesh) -> FeModel {
    let sec = ShellSection { e: 1.2e6, nu: 0.0, rho: 1.0, h: 0.1 };
    let mut m = FeModel::new(mesh, |_| Part::Shell(sec)).unwrap();
    m.fix(mesh.node_set("u0").unwrap(), [true; 6]);
    for &n in mesh.node_set("u1").unwrap() {
        m.point_load(n, 2, 4.0 / 2.0, Curve::Linear);
    }
    m
}

fn check(mesh: Mesh, name: &str, tol_final: f64, tol_all: f64) {
    let mut m = cantilever(&mesh);
    let tip: Vec<usize> = mesh.node_set("u1").unwrap().to_vec();
    let table = Table { name, columns: &["-u_tip", "w_tip"], rows: ROWS };
    let errors = run_table(&mut m, &table, |m| {
        let (mut u, mut w) = (0.0, 0.0);
        for &n in &tip {
            let d = displacement(m, n);
            u -= d[0] / tip.len() as f64;
            w += d[2] / tip.len() as f64;
        }
        vec![u, w]
    });
    let last = errors.last().unwrap();
    assert!(last.iter().all(|e| e.abs() < tol_final), "{name}: final errors {last:?}");
    // the first rows' -u (0.026) has only two significant digits: compare w there
    let rest: Vec<Vec<f64>> = errors.iter().skip(3).cloned().collect();
    assert!(max_error(&rest) < tol_all, "{name}: max error {}", max_error(&rest));
    assert!(errors.iter().all(|e| e[1].abs() < tol_all), "{name}: w errors");
}

#[test]
fn quads_16x1_follow_the_reference() {
    check(generate::rectangle(10.0, 1.0, 16, 1), "cantilever quads 16x1", 0.02, 0.02);
}

#[test]
fn triangles_16x1_follow_the_reference() {
    check(
        generate::rectangle(10.0, 1.0, 16, 1).to_triangles(),
        "cantilever triangles 16x1x2",
        0.02,
        0.02,
    );
}

/// Displacement control (the path solver for limit points) on the same problem: the tip
/// deflection is driven through the table's `w_tip` values and the load factor it returns must
/// be the table's `P / P_max`.
#[test]
fn displacement_control_recovers_the_load_factors() {
    use structure_solver::statics::{displacement_control, NewtonSettings};
    let mesh = generate::rectangle(10.0, 1.0, 16, 1);
    let mut m = cantilever(&mesh);
    let tip = mesh.node_set("u1").unwrap()[0];
    let targets: Vec<f64> = ROWS.iter().map(|r| r.1[1]).collect();
    let s = NewtonSettings { tol: 1e-7, max_iter: 25, max_cuts: 0 };
    let steps = displacement_control(&mut m, 6 * tip + 2, &targets, &s, |_, _| {}).unwrap();
    for (c, row) in steps.iter().zip(ROWS) {
        let e = (c.t - row.0) / row.0;
        println!("w_tip {:.3}: P/Pmax {:.4} vs {:.3} ({:+.2}%)", row.1[1], c.t, row.0, 100.0 * e);
        assert!(e.abs() < 0.01, "load factor {} vs {}", c.t, row.0);
    }
}
