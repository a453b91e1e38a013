//! J2 beams by fibres (`elements::beam::FibreBeam`): elastic fibres reproduce the elastic beam
//! (force and tangent), the plastic hinge moment of pure bending against `Σ wᵢ|ξᵢ| σy b h²/4`
//! at 5 and 8 fibres through the depth (8: against `M_p = σy b h²/4`), a cantilever under a
//! tip load driven to collapse by displacement control, its collapse load against `M_p / L`,
//! and elastic unloading from the collapse plateau.

use nalgebra::{Matrix3, Vector3};
use structure_solver::assembly::{Curve, FeModel, Part};
use structure_solver::elements::rotation::exp;
use structure_solver::elements::{BeamSection, BeamYield, Element};
use structure_solver::mesh::generate;
use structure_solver::statics::{displacement_control, NewtonSettings};

const E: f64 = 200e9;
const SIGMA_Y: f64 = 25e6;
const B: f64 = 0.05;
const H: f64 = 0.05;

fn section() -> BeamSection {
    BeamSection::rectangle(E, 0.3, 7800.0, B, H)
}

fn plastic(points: usize) -> BeamYield {
    BeamYield { sigma_y: SIGMA_Y, hardening: 0.0, points }
}

#[test]
fn elastic_fibres_reproduce_the_elastic_beam() {
    let x0 = [Vector3::new(0.1, 0.2, -0.1), Vector3::new(0.9, 0.5, 0.3)];
    let up = Vector3::new(0.0, 0.0, 1.0);
    let elastic = Element::beam2([0, 1], &x0, up, &section());
    let y = BeamYield { sigma_y: f64::INFINITY, hardening: 0.0, points: 2 };
    let fibres = Element::beam2_j2([0, 1], &x0, up, &section(), y);
    let x = [x0[0] + Vector3::new(1e-3, -2e-3, 0.5e-3), x0[1] + Vector3::new(-1e-3, 3e-3, 2e-3)];
    let r = [exp(&Vector3::new(0.01, -0.02, 0.015)), exp(&Vector3::new(-0.01, 0.005, 0.02))];
    let (mut fa, mut fb) = (vec![0.0; 12], vec![0.0; 12]);
    let mut state = vec![0.0; fibres.n_state()];
    let old = state.clone();
    elastic.force(&x, &r, &[], &mut [], &mut fa);
    fibres.force(&x, &r, &old, &mut state, &mut fb);
    let scale = fa.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let df = fa.iter().zip(&fb).fold(0.0f64, |m, (a, b)| m.max((a - b).abs())) / scale;
    let (ka, kb) = (elastic.tangent(&x, &r, &[], None), fibres.tangent(&x, &r, &old, None));
    let dk = (&ka - &kb).abs().max() / ka.abs().max();
    // and the fibre tangent against central differences of its force
    let kd = fibres.tangent_by_differences(&x, &r, &old, None);
    let dd = (&kb - &kd).abs().max() / kb.abs().max();
    println!("elastic fibres vs elastic beam: force {df:.2e}, tangent {dk:.2e}; tangent vs differences {dd:.2e}");
    assert!(df < 1e-10 && dk < 1e-10);
    assert!(dd < 1e-6);
}

/// Pure bending of one beam by opposite end rotations about local `y` in 200 increments to
/// 20 times the yield curvature: the end moment.
fn hinge_moment(points: usize) -> f64 {
    let l = 0.5;
    let x0 = [Vector3::zeros(), Vector3::new(l, 0.0, 0.0)];
    let el = Element::beam2_j2([0, 1], &x0, Vector3::y(), &section(), plastic(points));
    let kappa_y = 2.0 * SIGMA_Y / (E * H);
    let mut state = vec![0.0; el.n_state()];
    let mut trial = state.clone();
    let mut f = vec![0.0; 12];
    let steps = 200;
    for n in 1..=steps {
        let th = 20.0 * kappa_y * l * n as f64 / steps as f64;
        let r: [Matrix3<f64>; 2] =
            [exp(&Vector3::new(0.0, -th / 2.0, 0.0)), exp(&Vector3::new(0.0, th / 2.0, 0.0))];
        el.force(&x0, &r, &state, &mut trial, &mut f);
        std::mem::swap(&mut state, &mut trial);
    }
    f[6 + 4]
}

#[test]
fn plastic_hinge_moment_matches_the_fibre_rule_and_the_fully_plastic_moment() {
    use structure_solver::material::ThicknessRule;
    let mp = SIGMA_Y * B * H * H / 4.0;
    for points in [5, 8] {
        let m = hinge_moment(points);
        let rule = ThicknessRule::gauss(points).plastic_moment_factor() * mp;
        println!("beam hinge, {points} fibres through the depth: M = {m:.3} N m vs Σ w|ξ| σy b h²/4 = {rule:.3} ({:+.2e}), M/M_p = {:.4}", m / rule - 1.0, m / mp);
        assert!((m / rule - 1.0).abs() < 1e-6, "{points} points: {m} vs {rule}");
        if points >= 8 {
            assert!((m / mp - 1.0).abs() < 0.02);
        } else {
            assert!(m / mp < 0.95);
        }
    }
}

/// A cantilever of `n` J2 beams under a tip load `P` (reference 1 N along `z`), the tip
/// deflection driven by displacement control through `targets`: the load factors.
fn cantilever(n: usize, points: usize, targets: &[f64]) -> Vec<f64> {
    let l = 1.0;
    let mesh = generate::line([0.0; 3], [l, 0.0, 0.0], n);
    let (sec, y) = (section(), plastic(points));
    let mut m = FeModel::new(&mesh, |_| Part::BeamJ2(sec, [0.0, 1.0, 0.0], y)).unwrap();
    m.fix(mesh.node_set("start").unwrap(), [true; 6]);
    let tip = mesh.node_set("end").unwrap()[0];
    m.point_load(tip, 2, 1.0, Curve::Linear);
    let s = NewtonSettings { tol: 1e-7, max_iter: 30, max_cuts: 6 };
    displacement_control(&mut m, 6 * tip + 2, targets, &s, |_, _| {})
        .unwrap()
        .iter()
        .map(|c| c.t)
        .collect()
}

#[test]
fn cantilever_collapses_at_the_plastic_moment_and_unloads_elastically() {
    let l = 1.0;
    let i = B * H * H * H / 12.0;
    let mp = SIGMA_Y * B * H * H / 4.0;
    // yield deflection P_y L³ / (3 E I), P_y = σy I / (c L)
    let w_y = SIGMA_Y * i / (H / 2.0 * l) * l.powi(3) / (3.0 * E * i);
    // load to 12 yield deflections in 60 steps, then unload by 0.2 w_y in 4 (a larger first
    // unloading step starts Newton from the collapse mechanism's tangent, whose hinge rotation
    // reverses the root's yield in the first iterate of a perfectly plastic section)
    let mut targets: Vec<f64> = (1..=60).map(|k| 0.2 * w_y * k as f64).collect();
    for k in 1..=4 {
        targets.push(targets[59] - 0.05 * w_y * k as f64);
    }
    // what 8 Gauss fibres through the depth can carry: Σ wᵢ|ξᵢ| M_p (1.0115 M_p)
    let rule = structure_solver::material::ThicknessRule::gauss(8).plastic_moment_factor() * mp;
    let mut excess = Vec::new();
    for n in [20, 40] {
        let p = cantilever(n, 8, &targets);
        let k_elastic = p[0] / targets[0];
        let collapse = p[59];
        let unload = (p[59] - p[63]) / (targets[59] - targets[63]);
        let plateau = (p[59] - p[54]) / p[59];
        println!("cantilever {n} J2 beams, 8 fibres: initial stiffness {k_elastic:.4e} vs 3EI/L³ {:.4e}; load at 12 w_y {collapse:.2} N vs M_p/L {:.2} N ({:+.2}%) and Σ w|ξ| M_p/L {:.2} N ({:+.2}%); rise over the last w_y {plateau:.2e}; unloading stiffness / initial {:.6}", 3.0 * E * i / l.powi(3), mp / l, 100.0 * (collapse * l / mp - 1.0), rule / l, 100.0 * (collapse * l / rule - 1.0), unload / k_elastic);
        assert!((k_elastic / (3.0 * E * i / l.powi(3)) - 1.0).abs() < 1e-3);
        // the displacement-based element spreads the root hinge over its linear curvature:
        // the collapse load converges to the rule's limit from above as the root element
        // shrinks
        assert!(collapse * l / rule > 1.0 - 1e-9);
        assert!((collapse * l / mp - 1.0).abs() < 0.03, "collapse load {collapse} vs {}", mp / l);
        assert!(plateau < 1e-3, "the load still rises by {plateau} over the last yield deflection");
        assert!(
            (unload / k_elastic - 1.0).abs() < 1e-3,
            "unloading is elastic: {unload} vs {k_elastic}"
        );
        excess.push(collapse * l / rule - 1.0);
    }
    assert!(excess[1] < 0.6 * excess[0], "collapse load converges with the mesh: {excess:?}");
    assert!(excess[1] < 0.01, "40 beams: {:.2}% above the rule's limit", 100.0 * excess[1]);
}

/// A case whose beam material has `sigma_y` builds J2 beams (8 fibres through the depth when
/// the part gives no points) on a rectangle; a general section with `sigma_y` is refused,
/// naming the part's section.
#[test]
fn cases_with_a_yield_stress_build_j2_beams_on_rectangles_only() {
    use interface_protocol::case::Case;
    use structure_solver::build::build;
    use structure_solver::elements::RotaryInertia;
    let case = |section: &str| {
        let text = format!(
            r#"[structure]
mesh = {{ generator = "line", from = [0.0, 0.0, 0.0], to = [1.0, 0.0, 0.0], n = 4 }}
integrator = "static"
steps = 1
[structure.materials.steel]
e = 200e9
nu = 0.3
rho = 7800.0
sigma_y = 250e6
[[structure.parts]]
element = "beam"
section = {section}
up = [0.0, 1.0, 0.0]
[[structure.bc]]
set = "start"
fixed = ["ux", "uy", "uz", "rx", "ry", "rz"]
"#
        );
        Case::parse(&text, std::path::Path::new("beam.toml"), &[]).unwrap()
    };
    let s = build(&case("{ rectangle = [0.01, 0.02] }"), RotaryInertia::Physical).unwrap();
    let els = s.model.elements();
    assert_eq!(els.len(), 4);
    // 3 stations x 8 x 8 fibres x (εp, α)
    assert!(els.iter().all(|e| e.n_state() == 3 * 8 * 8 * 2));
    let general = case("{ area = 2e-4, iy = 6.7e-9, iz = 1.7e-9, j = 4.6e-9 }");
    let Err(err) = build(&general, RotaryInertia::Physical) else {
        panic!("a general section with sigma_y was accepted");
    };
    let msg = format!("{err:#}");
    assert!(msg.contains("structure.parts[0].section") && msg.contains("rectangle"), "{msg}");
}

/// The same cantilever (10 J2 beams, 5 fibres) in explicit time: the tip load ramped over 5
/// first-mode periods to 0.95 of the rule's collapse load (past first yield at 2/3 of it),
/// held with mass-proportional damping `α M` (α = ω1) until at rest: the tip deflection and
/// the summed plastic strain against the static load-controlled solution (the dynamic path
/// yields a little more: 10%).
#[test]
fn explicit_run_past_yield_settles_on_the_static_solution() {
    use structure_solver::model::Model;
    use structure_solver::statics::load_steps;
    use structure_solver::time::{critical_dt, CentralDifference};
    let (l, n) = (1.0, 10);
    let mesh = generate::line([0.0; 3], [l, 0.0, 0.0], n);
    let (sec, y) = (section(), plastic(5));
    let rule = structure_solver::material::ThicknessRule::gauss(5).plastic_moment_factor();
    let p = 0.95 * rule * SIGMA_Y * B * H * H / 4.0 / l;
    let tip = mesh.node_set("end").unwrap()[0];
    let model = |curve: Curve| {
        let mut m = FeModel::new(&mesh, |_| Part::BeamJ2(sec, [0.0, 1.0, 0.0], y)).unwrap();
        m.fix(mesh.node_set("start").unwrap(), [true; 6]);
        m.point_load(tip, 2, p, curve);
        m
    };
    // static
    let mut st = model(Curve::Linear);
    let s = NewtonSettings { tol: 1e-8, max_iter: 30, max_cuts: 6 };
    load_steps(&mut st, &[0.25, 0.5, 0.75, 0.9, 1.0], &s, |_, _| {}).unwrap();
    let mut u = vec![[0.0; 3]; st.n_nodes()];
    st.displacement(&mut u);
    let w_static = u[tip][2];
    // explicit
    let inertia = B * H * H * H / 12.0;
    let w1 = 1.875_104_f64.powi(2) * (E * inertia / (7800.0 * B * H * l.powi(4))).sqrt();
    let ramp = 5.0 * 2.0 * std::f64::consts::PI / w1;
    let mut ex = model(Curve::Table(vec![(0.0, 0.0), (ramp, 1.0)]));
    let est = critical_dt(&mut ex, 0.0, 200, 1e-9);
    let dt = 0.8 * est.element.min(est.power);
    let nd = ex.n_dof();
    let mut cd = CentralDifference::new(&mut ex, 0.0, vec![0.0; nd], None);
    let mass = ex.lumped_mass().to_vec();
    let mut damping = vec![0.0; nd];
    while cd.state.t < 2.0 * ramp {
        for i in 0..nd {
            damping[i] = -w1 * mass[i] * cd.state.v[i];
        }
        cd.step(&mut ex, dt, Some(&damping));
    }
    ex.displacement(&mut u);
    let w_explicit = u[tip][2];
    let e = w_explicit / w_static - 1.0;
    let alpha = |m: &FeModel| {
        (0..n).map(|k| m.element_state(k).iter().skip(1).step_by(2).sum::<f64>()).sum::<f64>()
    };
    let (a_static, a_explicit) = (alpha(&st), alpha(&ex));
    println!("J2 cantilever at 0.95 of collapse: tip w explicit {w_explicit:.5e} vs static {w_static:.5e} ({:+.3}%), elastic {:.5e}; summed equivalent plastic strain {a_explicit:.4e} vs {a_static:.4e}; dt {dt:.2e}", 100.0 * e, p * l.powi(3) / (3.0 * E * inertia));
    assert!(w_static > 1.05 * p * l.powi(3) / (3.0 * E * inertia), "the static run yields");
    assert!(e.abs() < 0.01, "explicit {w_explicit} vs static {w_static}");
    assert!((a_explicit / a_static - 1.0).abs() < 0.1);
}
