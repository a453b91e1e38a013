//! Cylindrical arc length (`statics::arc_length`) through the snap-through of a shallow
//! two-bar truss (von Mises truss) of corotational beams: half span `a`, rise `h`, one beam per
//! bar pinned at its support, the apex held on the symmetry axis. The discrete model's energy
//! is exact in closed form, `U(w) = 2 [½ EA/L₀ (L - L₀)² + ½ 3EI/L₀ β²]` with
//! `L = √(a² + (h - w)²)` and `β` the chord rotation (the apex rotation is zero by symmetry and
//! the pinned end condenses the bending stiffness to `3EI/L₀`), so the path is `P(w) = U'(w)`:
//! a limit point at `P_max`, the load falling through zero near `w = h` to a second limit point
//! (a minimum, shallower than `-P_max` because the bending energy keeps growing) and rising
//! again on the inverted branch. Load control cannot pass the first limit point. And the Sze
//! pull-out cylinder, whose limit point lies where the published load-controlled table jumps.

use structure_solver::assembly::{Curve, FeModel, Part};
use structure_solver::elements::BeamSection;
use structure_solver::mesh::{Cell, CellKind, Mesh};
use structure_solver::statics::{arc_length, ArcLengthSettings, NewtonSettings};

const A: f64 = 1.0;
const H: f64 = 0.1;
const P0: f64 = 40.0;

fn section() -> BeamSection {
    BeamSection { e: 1e7, nu: 0.3, rho: 1.0, area: 1e-2, iy: 1e-6, iz: 1e-6, j: 2e-6 }
}

/// Closed-form load `P(w)` of the discrete truss at apex deflection `w`.
fn load(w: f64) -> f64 {
    let s = section();
    let l0 = (A * A + H * H).sqrt();
    let l = (A * A + (H - w).powi(2)).sqrt();
    let beta = H.atan2(A) - (H - w).atan2(A);
    -2.0 * s.e * s.area / l0 * (l - l0) * (H - w) / l + 6.0 * s.e * s.iy * A * beta / (l0 * l * l)
}

/// The extremum of `sign · load` on `[lo, hi]` (golden section): `(w, load(w))`.
fn extremum(sign: f64, mut lo: f64, mut hi: f64) -> (f64, f64) {
    let g = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..200 {
        let (x1, x2) = (hi - g * (hi - lo), lo + g * (hi - lo));
        if sign * load(x1) < sign * load(x2) {
            lo = x1;
        } else {
            hi = x2;
        }
    }
    let w = 0.5 * (lo + hi);
    (w, load(w))
}

/// The limit load `P_max` and its deflection.
fn limit_load() -> (f64, f64) {
    extremum(1.0, 0.0, H)
}

fn truss() -> FeModel {
    let mesh = Mesh {
        nodes: vec![[-A, 0.0, 0.0], [0.0, 0.0, H], [A, 0.0, 0.0]],
        cells: vec![
            Cell { kind: CellKind::Line2, nodes: vec![0, 1] },
            Cell { kind: CellKind::Line2, nodes: vec![1, 2] },
        ],
        ..Mesh::default()
    };
    let mut m = FeModel::new(&mesh, |_| Part::Beam(section(), [0.0, 1.0, 0.0])).unwrap();
    m.fix(&[0, 1, 2], [false, true, false, true, false, true]); // the x-z plane
    m.fix(&[0, 2], [true, false, true, false, false, false]); // pins
    m.fix(&[1], [true, false, false, false, true, false]); // apex on the symmetry axis
    m.point_load(1, 2, -P0, Curve::Linear);
    m
}

#[test]
fn arc_length_follows_the_truss_through_both_limit_points() {
    let (w_star, p_max) = limit_load();
    let (w_low, p_low) = extremum(-1.0, H, 2.0 * H);
    let mut m = truss();
    let settings = ArcLengthSettings {
        newton: NewtonSettings { tol: 1e-10, max_iter: 20, max_cuts: 8 },
        initial: 0.01,
        min: 1e-8,
        max: 0.005,
        desired_iterations: 4,
        max_steps: 400,
        start: 0.0,
    };
    let mut path: Vec<(f64, f64)> = Vec::new();
    let steps = arc_length(&mut m, &settings, |m, c| {
        let mut u = vec![[0.0; 3]; m.n_nodes()];
        m.displacement(&mut u);
        path.push((-u[1][2], c.t));
        -u[1][2] < 2.3 * H
    })
    .unwrap();
    // the path on the closed form, and moving forward in w all the way
    let mut worst = 0.0f64;
    for (k, &(w, lambda)) in path.iter().enumerate() {
        worst = worst.max((lambda * P0 - load(w)).abs() / p_max);
        if k > 0 {
            assert!(w > path[k - 1].0, "the path turned back at step {k}: w = {w}");
        }
    }
    // the first local extremum of sign · λ: a parabola through it and its neighbours
    let peak = |sign: f64| {
        let k = (1..path.len() - 1)
            .find(|&i| {
                sign * path[i].1 >= sign * path[i - 1].1 && sign * path[i].1 > sign * path[i + 1].1
            })
            .expect("no limit point on the path");
        let [(x0, y0), (x1, y1), (x2, y2)] = [path[k - 1], path[k], path[k + 1]];
        let d1 = (y1 - y0) / (x1 - x0);
        let d2 = ((y2 - y1) / (x2 - x1) - d1) / (x2 - x0);
        let b = d1 - d2 * (x0 + x1);
        let xs = -b / (2.0 * d2);
        (xs, y0 + d1 * (xs - x0) + d2 * (xs - x0) * (xs - x1))
    };
    let (w_max, l_max) = peak(1.0);
    let (w_min, l_min) = peak(-1.0);
    let e_max = (l_max * P0 - p_max) / p_max;
    let e_min = (l_min * P0 - p_low) / p_max;
    println!(
        "two-bar truss, {} arc-length steps to w = {:.4}: max |λ P0 - P(w)| / P_max on the path \
         {worst:.2e}",
        steps.len(),
        path.last().unwrap().0
    );
    println!(
        "limit point: λ P0 = {:.6} at w = {w_max:.5} vs closed form P_max = {p_max:.6} at \
         w* = {w_star:.5} ({e_max:+.2e})",
        l_max * P0
    );
    println!(
        "second limit point: λ P0 = {:.6} at w = {w_min:.5} vs closed form {p_low:.6} at \
         {w_low:.5} ({e_min:+.2e} of P_max)",
        l_min * P0
    );
    assert!(worst < 1e-6, "path off the closed form by {worst:e} P_max");
    assert!(e_max.abs() < 1e-4 && e_min.abs() < 1e-4, "limit loads {e_max:e}, {e_min:e}");
    assert!((w_max - w_star).abs() < 1e-2 * H && (w_min - w_low).abs() < 1e-2 * H);
    // past the limit point the load falls below zero, and rises again after the second one
    let k_max = path.iter().position(|p| p.0 > w_max).unwrap();
    assert!(path[k_max..].iter().any(|p| p.1 * P0 < 0.5 * p_low), "the load never fell");
    assert!(path.last().unwrap().1 > path[path.len() - 2].1 && path.last().unwrap().0 > w_min);
}

/// Load control on the same truss stops at the limit point: past `P_max` Newton finds no
/// equilibrium nearby (or jumps to the far branch), which the arc length avoids.
#[test]
fn load_control_cannot_pass_the_limit_point() {
    use structure_solver::statics::load_steps;
    let (_, p_max) = limit_load();
    let mut m = truss();
    let targets: Vec<f64> = (1..=12).map(|k| k as f64 * 0.1 * p_max / P0).collect();
    let s = NewtonSettings { tol: 1e-10, max_iter: 20, max_cuts: 4 };
    let mut w = Vec::new();
    let r = load_steps(&mut m, &targets, &s, |m, _| {
        let mut u = vec![[0.0; 3]; m.n_nodes()];
        m.displacement(&mut u);
        w.push(-u[1][2]);
    });
    println!(
        "load control to 1.2 P_max: {} of 12 targets converged ({}), w after 1.1 P_max: {:?}",
        w.len(),
        if r.is_ok() { "ok" } else { "failed" },
        w.get(10)
    );
    // either it fails past P_max or it lands beyond the snap (w > h)
    assert!(r.is_err() || w[10] > H, "load control passed the limit point on the near branch");
}

/// The Sze, Liu & Lo (2004) pull-out cylinder (the model of `sze_pullout.rs`: one eighth,
/// 24x36 quads, P/4 at A) followed by arc length from the unloaded state: the path has a limit
/// point where the paper's load-controlled table jumps (between 0.50 and 0.525 P_max), the load
/// then falls before rising again, and both branches pass through the table's points.
#[test]
#[cfg_attr(debug_assertions, ignore = "benchmark of several seconds: run with --release")]
fn pullout_cylinder_limit_point() {
    use structure_solver::elements::ShellSection;
    use structure_solver::mesh::generate;
    const ROWS: &[(f64, [f64; 3])] = &[
        (0.25, [2.180, 3.087, 3.310]),
        (0.40, [2.376, 3.443, 3.632]),
        (0.50, [2.473, 3.653, 3.718]),
        (0.55, [2.577, 4.171, 3.518]),
        (0.60, [2.618, 4.274, 3.452]),
    ];
    let (r, l) = (4.953, 10.35);
    let mesh = generate::cylinder(r, l / 2.0, [0.0, generate::QUARTER], 36, 24);
    let sec = ShellSection { e: 10.5e6, nu: 0.3125, rho: 1.0, h: 0.094 };
    let mut m = FeModel::new(&mesh, |_| Part::Shell(sec)).unwrap();
    m.symmetry(mesh.node_set("v0").unwrap(), 2);
    m.symmetry(mesh.node_set("u0").unwrap(), 1);
    m.symmetry(mesh.node_set("u1").unwrap(), 0);
    let a = mesh.nearest_node([0.0, r, 0.0]);
    let b = mesh.nearest_node([r, 0.0, 0.0]);
    let c = mesh.nearest_node([r, 0.0, l / 2.0]);
    m.point_load(a, 1, 40000.0 / 4.0, Curve::Linear);
    let settings = ArcLengthSettings {
        newton: NewtonSettings { tol: 1e-6, max_iter: 20, max_cuts: 8 },
        initial: 1.0,
        min: 1e-6,
        max: 1.0,
        desired_iterations: 3,
        max_steps: 200,
        start: 0.0,
    };
    let mut path: Vec<(f64, [f64; 3])> = Vec::new();
    let t0 = std::time::Instant::now();
    arc_length(&mut m, &settings, |m, conv| {
        let mut u = vec![[0.0; 3]; m.n_nodes()];
        m.displacement(&mut u);
        path.push((conv.t, [u[a][1], -u[b][0], -u[c][0]]));
        conv.t < 0.62
    })
    .unwrap();
    let lam: Vec<f64> = path.iter().map(|p| p.0).collect();
    let k = (1..lam.len() - 1)
        .find(|&i| lam[i] >= lam[i - 1] && lam[i] > lam[i + 1])
        .expect("no limit point on the path");
    let j = (k + 1..lam.len() - 1)
        .find(|&i| lam[i] <= lam[i - 1] && lam[i] < lam[i + 1])
        .expect("the load never rose again");
    println!(
        "pull-out cylinder: {} arc-length steps in {:.1?}; limit point λ = {:.4} (w_A {:.4}, \
         -u_B {:.4}), load falls to λ = {:.4} (-u_B {:.4}) before rising",
        path.len(),
        t0.elapsed(),
        lam[k],
        path[k].1[0],
        path[k].1[1],
        lam[j],
        path[j].1[1]
    );
    assert!(lam[k] > 0.50 && lam[k] < 0.525, "limit load {} outside the table's jump", lam[k]);
    assert!(lam[j] < lam[k] - 1e-3, "no fall of the load after the limit point");
    // the table's points on the branch before the limit point and on the last one
    let mut worst = 0.0f64;
    for (lf, refs) in ROWS {
        let branch = if *lf < lam[k] { 0..k + 1 } else { j..lam.len() };
        let i = branch.clone().skip(1).find(|&i| lam[i] >= *lf).expect("table load on the path");
        let s = (lf - lam[i - 1]) / (lam[i] - lam[i - 1]);
        let got: Vec<f64> =
            (0..3).map(|q| path[i - 1].1[q] + s * (path[i].1[q] - path[i - 1].1[q])).collect();
        let e: Vec<f64> = got.iter().zip(refs).map(|(g, r)| (g - r) / r).collect();
        println!(
            "  P/Pmax {lf:.3}: w_A {:.4} / {:.3} ({:+.2}%), -u_B {:.4} / {:.3} ({:+.2}%), \
             -u_C {:.4} / {:.3} ({:+.2}%)",
            got[0],
            refs[0],
            100.0 * e[0],
            got[1],
            refs[1],
            100.0 * e[1],
            got[2],
            refs[2],
            100.0 * e[2]
        );
        worst = e.iter().fold(worst, |w, e| w.max(e.abs()));
    }
    assert!(worst < 0.02, "table error {worst}");
}
