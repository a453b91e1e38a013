//! `piston-fluid` coupled to `rigid-structure` through `fsi run`: a mass on a spring and damper
//! closing an acoustic column, F = -A (p0 + ρ0 c0 v). The body obeys
//! m u'' + (c + A ρ0 c0) u' + k u = -A p0, whose exact solution the displacement in
//! `structure_probes.csv` is compared with; the error over three step sizes gives each scheme's
//! observed temporal order (DESIGN §4, §8 item 7).

use fsi_system_tests::{observed_orders, Fsi, Oscillator, Scratch};
use std::time::Duration;

const OSC: Oscillator =
    Oscillator { m: 1.0, k: 3947.8, c: 2.0, area: 1e-3, p0: 1e5, rho0: 1.2, c0: 340.0 };

/// One period of the 10 Hz spring.
const T_END: f64 = 0.1;

/// The case text of `o` coupled with `scheme` at step `dt`.
fn case(o: &Oscillator, scheme: &str, dt: f64) -> String {
    format!(
        r#"[case]
name = "oscillator"
[coupling]
scheme = "{scheme}"
dt = {dt:e}
t_end = {T_END}
timeout_s = 10
[fluid]
command = ["piston-fluid"]
[fluid.piston]
area = {}
p0 = {:e}
rho0 = {}
c0 = {}
[structure]
command = ["rigid-structure"]
[structure.rigid]
mass = {}
stiffness = {}
damping = {}
probe = "piston"
"#,
        o.area, o.p0, o.rho0, o.c0, o.m, o.k, o.c
    )
}
/// Runs `scheme` at dt, dt/2, dt/4 and returns the relative errors.
fn errors(scheme: &str, dts: &[f64]) -> Vec<f64> {
    let scratch = Scratch::new();
    dts.iter()
        .map(|&dt| {
            let case =
                scratch.case(&format!("{scheme}-{}", (1.0 / dt).round()), &case(&OSC, scheme, dt));
            let out = scratch.path().join(format!("out-{}", (1.0 / dt).round()));
            let done = Fsi::run(&scratch, &case, &out, &[]).wait(Duration::from_secs(20));
            assert!(done.status.success(), "fsi run {scheme} dt {dt} failed:\n{}", done.stderr);
            OSC.max_error(&out, "piston", T_END)
        })
        .collect()
}

fn check_order(scheme: &str, dts: [f64; 3], lo: f64, hi: f64) {
    let e = errors(scheme, &dts);
    let p = observed_orders(&e);
    let es: Vec<String> = e.iter().map(|x| format!("{x:.3e}")).collect();
    println!("{scheme}: dt {dts:?} relative errors {es:?} observed orders {p:.3?}");
    for (i, &order) in p.iter().enumerate() {
        assert!(
            (lo..=hi).contains(&order),
            "{scheme}: order {order:.3} between dt {} and {} outside [{lo}, {hi}] (errors {es:?})",
            dts[i],
            dts[i + 1]
        );
    }
}

#[test]
fn c0_converges_at_second_order() {
    check_order("C0", [1e-3, 5e-4, 2.5e-4], 1.9, 2.6);
}

#[test]
fn a6_converges_at_second_order() {
    check_order("A6", [1e-3, 5e-4, 2.5e-4], 1.9, 2.6);
}

#[test]
fn css_converges_at_first_order() {
    // Smaller steps: CSS's first-order error, proportional to the fluid's damping, must dominate
    // the integrator's second-order one before the order settles.
    check_order("CSS", [2.5e-4, 1.25e-4, 6.25e-5], 0.8, 1.2);
}

#[test]
fn exact_solution_satisfies_the_oscillator_equation() {
    // Central differences of the exact solution against m u'' + (c + A ρ0 c0) u' + k u = -A p0.
    let o = OSC;
    let h = 1e-6;
    for t in [0.0123, 0.05, 0.0871] {
        let (a, b, c) = (o.displacement(t - h), o.displacement(t), o.displacement(t + h));
        let (v, acc) = ((c - a) / (2.0 * h), (c - 2.0 * b + a) / (h * h));
        let residual = o.m * acc + (o.c + o.area * o.rho0 * o.c0) * v + o.k * b + o.area * o.p0;
        assert!(residual.abs() < 1e-3 * o.area * o.p0, "t = {t}: residual {residual}");
    }
    assert!(o.displacement(0.0).abs() < 1e-15);
}

/// Two runs at once, with different ambient pressures, each match their own exact solution:
/// neither reads the other's samples.
#[test]
fn concurrent_runs_do_not_see_each_others_data() {
    let scratch = Scratch::new();
    let low = OSC;
    let high = Oscillator { p0: 3e5, ..OSC };
    let dt = 2.5e-4;
    let runs: Vec<_> = [("low", low), ("high", high)]
        .iter()
        .map(|(name, o)| {
            let case = scratch.case(name, &case(o, "C0", dt));
            let out = scratch.path().join(name);
            (Fsi::run(&scratch, &case, &out, &[]), out, *o)
        })
        .collect();
    for (fsi, out, o) in runs {
        let done = fsi.wait(Duration::from_secs(20));
        assert!(done.status.success(), "{}", done.stderr);
        let e = o.max_error(&out, "piston", T_END);
        println!("concurrent run p0 = {:e}: relative error {e:.3e}", o.p0);
        // A mixed-up load would be off by the ratio of the pressures (3x), an O(1) error.
        assert!(e < 1e-2, "p0 = {}: relative error {e}", o.p0);
    }
}
