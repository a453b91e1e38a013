use super::*;
use crate::case::Scheme;

/// m u'' + k u = F with the fluid load F = -(p0 + C v_w + K_f u_w) at the fluid's end time,
/// wall state as received (DESIGN §4's 1-DOF check).
const M: f64 = 1.0;
const K: f64 = 10.0;
const C: f64 = 0.5;
const KF: f64 = 2.0;
const P0: f64 = 1.0;
const U0: f64 = 0.1;
const T: f64 = 2.0;

fn fluid(u: f64, v: f64) -> f64 {
    -(P0 + C * v + KF * u)
}

/// Closed form of m u'' + C u' + (k + K_f) u = -p0, u(0) = U0, u'(0) = 0.
fn exact(t: f64) -> f64 {
    let kk = K + KF;
    let ueq = -P0 / kk;
    let g = C / (2.0 * M);
    let wd = (kk / M - g * g).sqrt();
    let w0 = U0 - ueq;
    ueq + (-g * t).exp() * (w0 * (wd * t).cos() + g * w0 / wd * (wd * t).sin())
}

/// Runs the coupling sequence (start-up, then PREDICT / fluid / CORRECT) to `t_end` in steps
/// of `dt`, the last one shortened as the launcher does, and returns u(t_end).
fn run_to(scheme: Scheme, dt: f64, t_end: f64) -> f64 {
    run_sub(scheme, dt, t_end, None)
}

/// [`run_to`] with `substeps` central-difference substeps per coupling step.
fn run_sub(scheme: Scheme, dt: f64, t_end: f64, substeps: Option<u32>) -> f64 {
    run_restarted(scheme, dt, t_end, substeps, None)
}

/// [`run_sub`], the scheme's state rebuilt from its history after CORRECT of step
/// `restart_after` as a restart does: a fresh `Staggered` restored, the dynamics copied.
fn run_restarted(
    scheme: Scheme,
    dt: f64,
    t_end: f64,
    substeps: Option<u32>,
    restart_after: Option<usize>,
) -> f64 {
    let n = (t_end / dt * (1.0 - 1e-12)).ceil() as usize;
    let params = Diagonal { m: vec![M], k: vec![K], c: vec![0.0] };
    let mut d = Oscillators::new(params, &[U0], &[0.0]);
    let mut s = Staggered::new(scheme, 1).with_substeps(substeps);
    let f0 = fluid(d.u[0], d.v[0]); // fluid Init
    let mut pending = None;
    if s.start(&mut d, &[f0], dt.min(t_end)).unwrap() {
        pending = Some(fluid(s.up[0], s.vp[0])); // C0: fluid's start-up half step
    }
    for step in 0..n {
        let t_from = step as f64 * dt;
        let h = if step + 1 == n { t_end - t_from } else { dt };
        let load = if s.predict_reads_load(step as u64) { pending.take() } else { None };
        s.predict(&mut d, h, load.as_ref().map(std::slice::from_ref)).unwrap();
        let f = fluid(s.up[0], s.vp[0]);
        s.correct(&mut d, &[f], h).unwrap();
        if restart_after == Some(step) {
            let history = s.history();
            let mut fresh = Staggered::new(scheme, 1).with_substeps(substeps);
            fresh
                .restore(|name| history.iter().find(|(k, _)| *k == name).map(|(_, v)| v.clone()))
                .unwrap();
            s = fresh;
            d = d.clone();
        }
    }
    d.u[0]
}

/// A scheme restored from its history after any step continues bitwise (substeps included);
/// a missing or mis-sized entry is refused by name.
#[test]
fn a_restored_history_continues_bitwise() {
    let (dt, t_end) = (T / 50.0, T + 0.37 * T / 50.0);
    for scheme in [Scheme::C0, Scheme::Css, Scheme::A6] {
        for substeps in [None, Some(3)] {
            let whole = run_sub(scheme, dt, t_end, substeps);
            for at in [0, 1, 17, 49] {
                let again = run_restarted(scheme, dt, t_end, substeps, Some(at));
                assert_eq!(whole.to_bits(), again.to_bits(), "{scheme:?} {substeps:?} at {at}");
            }
        }
    }
    let mut s = Staggered::new(Scheme::C0, 2);
    let err = s.restore(|name| (name != "a_hat").then(|| vec![0.0; 2])).unwrap_err();
    assert!(err.contains("`a_hat` is missing"), "{err}");
    let err = s.restore(|_| Some(vec![0.0; 2])).unwrap_err();
    assert!(err.contains("`times` holds 2 values, expected 3"), "{err}");
}

fn run(scheme: Scheme, n: usize) -> f64 {
    run_to(scheme, T / n as f64, T)
}

fn observed_order(scheme: Scheme) -> f64 {
    let e: Vec<f64> = [100, 200, 400].iter().map(|&n| (run(scheme, n) - exact(T)).abs()).collect();
    let orders = [(e[0] / e[1]).log2(), (e[1] / e[2]).log2()];
    eprintln!("{scheme:?}: errors {e:?}, observed orders {orders:?}");
    assert!((orders[0] - orders[1]).abs() < 0.2, "{scheme:?}: errors {e:?}, orders {orders:?}");
    orders[1]
}

#[test]
fn c0_is_second_order() {
    let p = observed_order(Scheme::C0);
    assert!((1.8..2.3).contains(&p), "C0 order {p}");
}

#[test]
fn a6_is_second_order() {
    let p = observed_order(Scheme::A6);
    assert!((1.8..2.3).contains(&p), "A6 order {p}");
}

#[test]
fn css_is_first_order() {
    let p = observed_order(Scheme::Css);
    assert!((0.8..1.2).contains(&p), "CSS order {p}");
}

#[test]
fn diagonal_integrators_match_the_damped_oscillator() {
    // Uncoupled m u'' + c u' + k u = 0 with the structure's own integrators, CSS with zero load.
    let (m, k, c) = (2.0, 8.0, 0.4);
    let params = Diagonal { m: vec![m], k: vec![k], c: vec![c] };
    let exact = |t: f64| {
        let g = c / (2.0 * m);
        let wd = (k / m - g * g).sqrt();
        (-g * t).exp() * ((wd * t).cos() + g / wd * (wd * t).sin())
    };
    for scheme in [Scheme::Css, Scheme::A6] {
        let err = |n: usize| {
            let dt = 3.0 / n as f64;
            let mut d = Oscillators::new(params.clone(), &[1.0], &[0.0]);
            let mut s = Staggered::new(scheme, 1);
            s.start(&mut d, &[0.0], dt).unwrap();
            for _ in 0..n {
                s.predict(&mut d, dt, None).unwrap();
                s.correct(&mut d, &[0.0], dt).unwrap();
            }
            (d.u[0] - exact(3.0)).abs()
        };
        let p = (err(200) / err(400)).log2();
        assert!((1.9..2.1).contains(&p), "{scheme:?}: order {p}");
    }
}

/// A run whose last step is shortened (t_end not a multiple of Δt) keeps each scheme's
/// order: the predictors take the step's own length.
#[test]
fn a_shortened_last_step_keeps_the_order() {
    let t_end = T + 0.37 * T / 100.0;
    for (scheme, lo, hi) in
        [(Scheme::C0, 1.8, 2.3), (Scheme::A6, 1.8, 2.3), (Scheme::Css, 0.8, 1.2)]
    {
        let e: Vec<f64> = [100, 200, 400]
            .iter()
            .map(|&n| (run_to(scheme, T / n as f64, t_end) - exact(t_end)).abs())
            .collect();
        let p = (e[1] / e[2]).log2();
        assert!((lo..hi).contains(&p), "{scheme:?}: errors {e:?}, order {p}");
    }
}

/// Four and five central-difference substeps per coupling step keep C0 second order and CSS
/// first order, a shortened last step included; one substep is the plain scheme bitwise.
#[test]
fn subcycled_structure_keeps_the_order() {
    let t_end = T + 0.37 * T / 100.0;
    for m in [4, 5] {
        for (scheme, lo, hi) in [(Scheme::C0, 1.8, 2.3), (Scheme::Css, 0.8, 1.2)] {
            let e: Vec<f64> = [100, 200, 400]
                .iter()
                .map(|&n| (run_sub(scheme, T / n as f64, t_end, Some(m)) - exact(t_end)).abs())
                .collect();
            let p = (e[1] / e[2]).log2();
            eprintln!("{scheme:?}, {m} substeps: errors {e:?}, order {p}");
            assert!((lo..hi).contains(&p), "{scheme:?}, {m} substeps: errors {e:?}, order {p}");
        }
    }
    for scheme in [Scheme::C0, Scheme::Css, Scheme::A6] {
        let one = run_sub(scheme, T / 100.0, t_end, Some(1));
        assert_eq!(one.to_bits(), run_to(scheme, T / 100.0, t_end).to_bits(), "{scheme:?}");
    }
}

/// The ledger: on a free mass under a constant load every scheme, subcycled or not, moves
/// it exactly (uniform acceleration), so its work F u(T) equals the kinetic energy ½ m v(T)²
/// to round-off; on the spring-mass under the mock fluid it closes the structure's energy
/// balance, ½ m v² + ½ k u² - its start, to the central differences' O(Δt²) (CSS, C0) and
/// to round-off with A6's implicit midpoint rule.
#[test]
fn the_ledger_is_the_work_of_the_applied_load() {
    let (m, f) = (2.0, 3.0);
    for scheme in [Scheme::Css, Scheme::C0, Scheme::A6] {
        for substeps in [1, 3] {
            let params = Diagonal { m: vec![m], k: vec![0.0], c: vec![0.0] };
            let mut d = Oscillators::new(params, &[0.0], &[0.0]);
            let mut s = Staggered::new(scheme, 1).with_substeps(Some(substeps));
            let dt = 0.01;
            s.start(&mut d, &[f], dt).unwrap();
            for step in 0..50 {
                s.predict(&mut d, dt, (s.predict_reads_load(step)).then_some(&[f][..])).unwrap();
                s.correct(&mut d, &[f], dt).unwrap();
            }
            let (w, u, v) = (s.interface_work(), d.u[0], d.v[0]);
            assert!((w - f * u).abs() < 1e-13 * w, "{scheme:?}/{substeps}: {w} vs F u {}", f * u);
            assert!((w - 0.5 * m * v * v).abs() < 1e-12 * w, "{scheme:?}/{substeps}: {w}");
        }
    }
    let imbalance = |scheme: Scheme, n: usize| {
        let dt = T / n as f64;
        let params = Diagonal { m: vec![M], k: vec![K], c: vec![0.0] };
        let mut d = Oscillators::new(params, &[U0], &[0.0]);
        let energy = |d: &Oscillators| 0.5 * M * d.v[0] * d.v[0] + 0.5 * K * d.u[0] * d.u[0];
        let e0 = energy(&d);
        let mut s = Staggered::new(scheme, 1);
        let f0 = fluid(d.u[0], d.v[0]);
        let mut pending = None;
        if s.start(&mut d, &[f0], dt).unwrap() {
            pending = Some(fluid(s.up[0], s.vp[0]));
        }
        for step in 0..n as u64 {
            let early = s.predict_reads_load(step).then(|| pending.take().unwrap());
            s.predict(&mut d, dt, early.as_ref().map(std::slice::from_ref)).unwrap();
            let f = fluid(s.up[0], s.vp[0]);
            s.correct(&mut d, &[f], dt).unwrap();
        }
        (energy(&d) - e0 - s.interface_work()).abs()
    };
    for scheme in [Scheme::Css, Scheme::C0] {
        let (a, b) = (imbalance(scheme, 200), imbalance(scheme, 400));
        let p = (a / b).log2();
        assert!(p > 1.8, "{scheme:?}: energy imbalance {a:e}, {b:e}, order {p}");
    }
    // The implicit midpoint rule balances a linear structure's energy exactly.
    let e = imbalance(Scheme::A6, 200);
    assert!(e < 1e-13, "A6: energy imbalance {e:e}");
}

/// A coupling step 3.2 times the structure's stable step 2/ω: without substeps central
/// differences blow up; with the substeps the stable step asks for, the free vibration keeps
/// its amplitude.
#[test]
fn substeps_from_the_stable_step_keep_central_differences_stable() {
    let (m, k) = (1.0f64, 1e4f64);
    let stable = 2.0 * (m / k).sqrt();
    let dt = 3.2 * stable;
    let run = |auto: bool| {
        let params = Diagonal { m: vec![m], k: vec![k], c: vec![0.0] };
        let mut d = Oscillators::new(params, &[1.0], &[0.0]);
        let mut s = Staggered::new(Scheme::C0, 1);
        if auto {
            s.set_stable_step(0.9 * stable);
        }
        assert_eq!(s.substeps(dt), if auto { 4 } else { 1 });
        s.start(&mut d, &[0.0], dt).unwrap();
        let mut peak = 0.0f64;
        for step in 0..200 {
            s.predict(&mut d, dt, (step == 0).then_some(&[0.0][..])).unwrap();
            s.correct(&mut d, &[0.0], dt).unwrap();
            peak = peak.max(d.u[0].abs());
        }
        peak
    };
    let plain = run(false);
    assert!(plain.is_nan() || plain > 1e10, "central differences stable without substeps: {plain}");
    // Free vibration from u = 1 at rest: central differences keep |u| <= 1, and 200 steps of
    // a period near 4 coupling steps come within a few percent of the peak.
    let peak = run(true);
    assert!((0.95..=1.0 + 1e-12).contains(&peak), "peak {peak}");
}
