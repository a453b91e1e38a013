//! Sze, Liu & Lo (2004, Finite Elem. Anal. Des. 40:1551), §3.2: slit annular plate under a
//! line force. Inner radius 6, outer radius 10, h = 0.03, E = 21e6, ν = 0; clamped along one
//! side of the slit, a transverse line force q = 0.8 per unit length (q_max) along the other.
//! Mesh: 10 (radial) x 80 (circumferential) 4-node shells, the size DESIGN §8 lists for the
//! paper's S4R mesh, and the same mesh split into triangles.
//!
//! Reference: only the values at q_max are used here, W_A = 13.891 (inner edge) and
//! W_B = 17.528 (outer edge) (Sze et al. 2004, Table 4, as quoted by the PENGoLINS
//! documentation, docs/benchmarks/slit_annular.md); the intermediate rows of the table could
//! not be recovered reliably, so intermediate steps are only checked for monotonic growth.

mod common;

use common::displacement;
use structure_solver::assembly::{Curve, FeModel, Part};
use structure_solver::elements::ShellSection;
use structure_solver::mesh::{generate, Mesh};
use structure_solver::statics::{load_steps, NewtonSettings};

fn run(mesh: Mesh, name: &str, tol: f64) {
    let sec = ShellSection { e: 21e6, nu: 0.0, rho: 1.0, h: 0.03 };
    let mut m = FeModel::new(&mesh, |_| Part::Shell(sec)).unwrap();
    m.fix(mesh.node_set("u0").unwrap(), [true; 6]);
    // line force on the free side (θ = 2π, set u1): 10 radial segments of length 0.4
    let edge = mesh.node_set("u1").unwrap();
    let q = 0.8;
    let seg = 4.0 / (edge.len() - 1) as f64;
    for (k, &n) in edge.iter().enumerate() {
        let w = if k == 0 || k + 1 == edge.len() { 0.5 } else { 1.0 };
        m.point_load(n, 2, q * seg * w, Curve::Linear);
    }
    let a = mesh.nearest_node([6.0, -1e-9, 0.0]);
    let b = mesh.nearest_node([10.0, -1e-9, 0.0]);
    assert!(edge.contains(&a) && edge.contains(&b));
    let targets: Vec<f64> = (1..=10).map(|i| i as f64 / 10.0).collect();
    let s = NewtonSettings { tol: 1e-6, max_iter: 40, max_cuts: 10 };
    let mut w = Vec::new();
    load_steps(&mut m, &targets, &s, |m, c| {
        let (wa, wb) = (displacement(m, a)[2], displacement(m, b)[2]);
        println!("{name}: q/q_max {:.2}: W_A {wa:.4}, W_B {wb:.4} ({} iterations)", c.t, c.iterations);
        w.push((wa, wb));
    })
    .unwrap();
    assert!(w.windows(2).all(|p| p[1].0 > p[0].0 && p[1].1 > p[0].1), "{name}: deflection must grow");
    let (wa, wb) = *w.last().unwrap();
    let (ea, eb) = ((wa - 13.891) / 13.891, (wb - 17.528) / 17.528);
    println!("{name}: final W_A {wa:.4} vs 13.891 ({:+.2}%), W_B {wb:.4} vs 17.528 ({:+.2}%)", 100.0 * ea, 100.0 * eb);
    assert!(ea.abs() < tol && eb.abs() < tol, "{name}: final errors {ea:.4} {eb:.4}");
}

#[test]
fn quads_10x80_reach_the_reference() {
    run(generate::annulus(6.0, 10.0, [0.0, 2.0 * std::f64::consts::PI], 80, 10), "slit plate quads 10x80", 0.02);
}

/// The constant-strain membrane of the flat triangle is stiffer: -2.6% / -2.0% at q_max on
/// the same mesh, held to 3%.
#[test]
fn triangles_10x80_reach_the_reference() {
    run(generate::annulus(6.0, 10.0, [0.0, 2.0 * std::f64::consts::PI], 80, 10).to_triangles(), "slit plate triangles 10x80x2", 0.03);
}
