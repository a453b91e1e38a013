//! The spring of a rigid body's reference node (`[[structure.rigid_bodies]]`, `spring`): a
//! plate made one rigid body of mass `m` on a spring `k` along x with a preload `P` starts at
//! rest at `u = 0`, away from its equilibrium `u_e = P / k`, so `u(t) = u_e (1 - cos ωt)` with
//! `ω = sqrt(k/m)`. Central differences and the implicit midpoint rule must give the period
//! `2π/ω` within 1e-3 (their frequency errors at `ωΔt = 0.05` are about 1e-4 and 2e-4) and the
//! peak `2 u_e`; the stable step holds the spring's `2/ω` (the element bound and the power
//! iteration through the internal force); bad keys are refused naming the field.

use std::path::Path;

use interface_protocol::case::Case;
use structure_solver::assembly::RotaryInertia;
use structure_solver::build::{build, Structure};
use structure_solver::model::Model;
use structure_solver::time::{critical_dt, CentralDifference, Implicit, ImplicitScheme};

const K: f64 = 100.0;
const PRELOAD: f64 = 2.0;
/// The body: the plate's ρ h A = 1 · 0.1 · 1 plus the mass added at the reference.
const ADDED: f64 = 1.0;
const MASS: f64 = ADDED + 0.1;

/// A 1 x 1 plate of 2 x 2 shells (E small: its element bound far above the spring's), all one
/// rigid body on a spring along x, `spring` the key's value; the reference moves along x only.
fn case(spring: &str, integrator: &str) -> String {
    format!(
        r#"[structure]
mesh = {{ generator = "rectangle", lx = 1.0, ly = 1.0, nx = 2, ny = 2 }}
material = {{ e = 1e-2, nu = 0.3, rho = 1.0 }}
element = "shell"
thickness = 0.1
integrator = "{integrator}"
dt = 1e-3
t_end = 1e-2
[[structure.rigid_bodies]]
set = "all"
reference = [0.5, 0.5, 0.0]
mass = {ADDED}
spring = {spring}
[[structure.bc]]
set = "all_reference"
fixed = ["uy", "uz", "rx", "ry", "rz"]
"#
    )
}

fn built(spring: &str, integrator: &str) -> anyhow::Result<Structure> {
    let case = Case::parse(&case(spring, integrator), Path::new("case.toml"), &[])?;
    build(&case, RotaryInertia::Physical)
}

fn spring_x() -> String {
    format!("{{ stiffness = [{K}, 0.0, 0.0], preload = [{PRELOAD}, 0.0, 0.0] }}")
}

/// The reference node's ux over five periods of `step` (`dt` per step) from rest.
fn history(s: &mut Structure, mut step: impl FnMut(&mut dyn Model)) -> Vec<(f64, f64)> {
    let master = s.model.rigid_bodies()[0].master;
    let dt = 0.05 / (K / MASS).sqrt();
    let n = (5.0 * 2.0 * std::f64::consts::PI / 0.05).ceil() as usize;
    let mut u = vec![[0.0; 3]; s.model.n_nodes()];
    let mut out = vec![(0.0, 0.0)];
    for i in 1..=n {
        step(&mut s.model);
        s.model.displacement(&mut u);
        out.push((i as f64 * dt, u[master][0]));
    }
    out
}

/// Period from the upward crossings of `u - u_e` (linear interpolation) and the peak.
fn period_and_peak(series: &[(f64, f64)], u_e: f64) -> (f64, f64) {
    let ups: Vec<f64> = series
        .windows(2)
        .filter(|w| w[0].1 < u_e && w[1].1 >= u_e)
        .map(|w| {
            let (a, b) = (w[0].1 - u_e, w[1].1 - u_e);
            w[0].0 + (w[1].0 - w[0].0) * a / (a - b)
        })
        .collect();
    assert!(ups.len() >= 4, "only {} upward crossings", ups.len());
    let period = (ups.last().unwrap() - ups[0]) / (ups.len() - 1) as f64;
    (period, series.iter().map(|p| p.1).fold(f64::MIN, f64::max))
}

fn check(label: &str, series: &[(f64, f64)]) {
    let u_e = PRELOAD / K;
    let (period, peak) = period_and_peak(series, u_e);
    let exact = 2.0 * std::f64::consts::PI * (MASS / K).sqrt();
    println!(
        "{label}: period {period:.6} s against 2π sqrt(m/k) = {exact:.6} s (error {:.2e}), \
         peak {peak:.6} against 2 P/k = {:.6}",
        period / exact - 1.0,
        2.0 * u_e
    );
    assert!((period / exact - 1.0).abs() < 1e-3, "{label}: period {period} against {exact}");
    assert!((peak / (2.0 * u_e) - 1.0).abs() < 1e-3, "{label}: peak {peak}");
}

#[test]
fn a_rigid_body_on_a_spring_oscillates_at_sqrt_k_over_m_explicit_and_implicit() {
    let mut s = built(&spring_x(), "central_difference").unwrap();
    assert!((s.model.rigid_bodies()[0].mass() - MASS).abs() < 1e-12);
    let dt = 0.05 / (K / MASS).sqrt();
    let mut cd = CentralDifference::new(&mut s.model, 0.0, s.v0.clone(), None);
    let series = history(&mut s, |m| cd.step(m, dt, None));
    check("central differences", &series);

    let mut s = built(&spring_x(), "midpoint").unwrap();
    let mut im = Implicit::new(&mut s.model, ImplicitScheme::Midpoint, 0.0, s.v0.clone(), None);
    let series = history(&mut s, |m| {
        im.step(m, dt, None).expect("a midpoint step");
    });
    check("implicit midpoint", &series);
}

#[test]
fn the_stable_step_holds_the_spring() {
    // Springs on x and y: the stiffer axis sets the step, 2 sqrt(m / k_max).
    let mut s =
        built(&format!("{{ stiffness = [{K}, {}, 0.0] }}", 4.0 * K), "central_difference").unwrap();
    let free_y = |t: &str| t.replace("fixed = [\"uy\", ", "fixed = [");
    let case = Case::parse(
        &free_y(&case(&format!("{{ stiffness = [{K}, {}, 0.0] }}", 4.0 * K), "central_difference")),
        Path::new("case.toml"),
        &[],
    )
    .unwrap();
    let mut free = build(&case, RotaryInertia::Physical).unwrap();
    let exact_x = 2.0 * (MASS / K).sqrt();
    let exact_xy = 2.0 * (MASS / (4.0 * K)).sqrt();
    let held = critical_dt(&mut s.model, 0.0, 100, 1e-6);
    let both = critical_dt(&mut free.model, 0.0, 100, 1e-6);
    println!(
        "stable step: y held {:.6} (power {:.6}) against 2 sqrt(m/kx) = {exact_x:.6}; y free \
         {:.6} (power {:.6}) against 2 sqrt(m/ky) = {exact_xy:.6}",
        held.element, held.power, both.element, both.power
    );
    assert!((held.element / exact_x - 1.0).abs() < 1e-9, "{held:?}");
    assert!((both.element / exact_xy - 1.0).abs() < 1e-9, "{both:?}");
    // The power iteration sees the spring through the internal force.
    assert!((held.power / exact_x - 1.0).abs() < 1e-2, "{held:?}");
    assert!((both.power / exact_xy - 1.0).abs() < 1e-2, "{both:?}");
}

#[test]
fn bad_spring_keys_name_their_field() {
    let err =
        |spring: &str| format!("{:#}", built(spring, "central_difference").err().expect("refused"));
    let f = "structure.rigid_bodies[0].spring";
    let e = err("{ stiffness = [-1.0, 0.0, 0.0] }");
    assert!(e.contains(&format!("{f}.stiffness[0]")) && e.contains(">= 0"), "{e}");
    let e = err("{ stiffness = [0.0, 0.0, 0.0] }");
    assert!(e.contains(&format!("{f}.stiffness")) && e.contains("at least one axis"), "{e}");
    let e = err("{ stiffness = [1.0, 0.0, 0.0], preload = [0.0, nan, 0.0] }");
    assert!(e.contains(&format!("{f}.preload[1]")), "{e}");
    let e = err("{ stiffness = [1.0, 0.0, 0.0], anchor = [0.0, 0.0, 0.0] }");
    assert!(e.contains("anchor"), "{e}");
    let e = err("{ preload = [1.0, 0.0, 0.0] }");
    assert!(e.contains("stiffness"), "{e}");
}
