//! Exact Riemann solver checks: Toro's five tests, two-phase and fluid-structure star states
//! verified by independent jump relations, and the full sampled solution by conservation.

use super::*;
use proptest::prelude::*;

const AIR: Eos = Eos::PerfectGas { gamma: 1.4 };
/// Thesis §2.1.2 stiffened water.
const WATER_SG: Eos = Eos::StiffenedGas { gamma: 7.15, p_c: 2.89e8 };

fn tait_water() -> Eos {
    Eos::tait(2.07e9, 7.15, 1000.0, 1e5)
}

fn st(rho: f64, u: f64, p: f64) -> State1d {
    State1d { rho, u, p }
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs()
}

/// Toro, *Riemann Solvers and Numerical Methods for Fluid Dynamics*, Table 4.3 (γ = 1.4).
#[test]
fn toro_star_states() {
    #[rustfmt::skip]
    let cases = [
        ((1.0, 0.0, 1.0), (0.125, 0.0, 0.1), (0.30313, 0.92745, 0.42632, 0.26557)),
        ((1.0, -2.0, 0.4), (1.0, 2.0, 0.4), (0.00189, 0.0, 0.02185, 0.02185)),
        ((1.0, 0.0, 1000.0), (1.0, 0.0, 0.01), (460.894, 19.5975, 0.57506, 5.99924)),
        ((1.0, 0.0, 0.01), (1.0, 0.0, 100.0), (46.0950, -6.19633, 5.99242, 0.57511)),
        ((5.99924, 19.5975, 460.894), (5.99242, -6.19633, 46.0950),
         (1691.64, 8.68975, 14.2823, 31.0426)),
    ];
    for (i, (l, r, (p, u, rl, rr))) in cases.into_iter().enumerate() {
        let s = solve(&AIR, st(l.0, l.1, l.2), &AIR, st(r.0, r.1, r.2)).unwrap();
        // Half a unit of the fifth significant digit (Toro prints test 2 with fewer: half a unit
        // of its last printed decimal, 5e-6; u* = 0 there by symmetry).
        let tol =
            |x: f64| if i == 1 { 5e-6 } else { 0.5 * 10f64.powf(x.abs().log10().floor() - 4.0) };
        let ok = |got: f64, want: f64| {
            (got - want).abs() <= tol(want) || (want == 0.0 && got.abs() < 1e-14)
        };
        assert!(ok(s.p, p), "test {}: p* {} vs {p}", i + 1, s.p);
        assert!(ok(s.u, u), "test {}: u* {} vs {u}", i + 1, s.u);
        assert!(ok(s.rho_l, rl), "test {}: rho*L {} vs {rl}", i + 1, s.rho_l);
        assert!(ok(s.rho_r, rr), "test {}: rho*R {} vs {rr}", i + 1, s.rho_r);
    }
}

/// Checks the wave between `k` and the star state with relations the solver does not use:
/// a shock (`p* > p_k`) must satisfy the Rankine-Hugoniot mass and momentum relations at the
/// reported speed (and energy for a gas, with `h = e + p/ρ` from the EOS); a rarefaction must keep
/// the Riemann invariant `u ∓ 2c/(g - 1)` and the isentrope (Tait: `p* = p(ρ*)`).
fn check_wave(
    eos: &Eos,
    k: State1d,
    u_star: f64,
    p_star: f64,
    rho_star: f64,
    speed: (f64, f64),
    dir: f64,
) {
    let rel = 1e-10;
    if p_star > k.p {
        let s = speed.0;
        assert_eq!(speed.0, speed.1);
        let m_k = k.rho * (k.u - s);
        let m_s = rho_star * (u_star - s);
        // The fluxes are differences of terms of size ρ(|u| + |s|): a weak flux through a fast
        // shock (a near-vacuum state hit by a strong one) is exact only to round-off of those.
        let scale = k.rho * (k.u.abs() + s.abs());
        assert!((m_s - m_k).abs() <= rel * scale.max(m_k.abs()), "mass {m_k} vs {m_s}");
        let mom_k = m_k * (k.u - s) + k.p;
        let mom_s = m_s * (u_star - s) + p_star;
        let mom_scale = scale * (k.u.abs() + s.abs()) + k.p;
        assert!((mom_s - mom_k).abs() <= rel * mom_scale, "momentum {mom_k} vs {mom_s}");
        if eos.is_barotropic() {
            assert!(close(eos.tait_pressure(rho_star), p_star, rel));
        } else {
            let h = |rho: f64, p: f64, v: f64| eos.internal_energy(rho, p) + p / rho + 0.5 * v * v;
            let (hk, hs) = (h(k.rho, k.p, k.u - s), h(rho_star, p_star, u_star - s));
            assert!(close(hs, hk, rel), "energy {hk} vs {hs}");
        }
    } else {
        let (g, pi) = eos.stiffness();
        let inv = |rho: f64, u: f64, p: f64| u + dir * 2.0 * eos.sound_speed(rho, p) / (g - 1.0);
        let (a, b) = (inv(k.rho, k.u, k.p), inv(rho_star, u_star, p_star));
        assert!(
            (a - b).abs() <= rel * (k.u.abs() + eos.sound_speed(k.rho, k.p)),
            "invariant {a} vs {b}"
        );
        let entropy = |rho: f64, p: f64| (p + pi) / rho.powf(g);
        assert!(close(entropy(rho_star, p_star), entropy(k.rho, k.p), rel));
        let c_star = eos.sound_speed(rho_star, p_star);
        assert!(
            close(speed.1, u_star - dir * c_star, rel)
                || (speed.1 - (u_star - dir * c_star)).abs() < 1e-12
        );
    }
}

/// Both waves of a solved problem, and the star state sampled on each side of the contact.
fn check_solution(eos_l: &Eos, l: State1d, eos_r: &Eos, r: State1d) -> RiemannSolution {
    let sol = RiemannSolution::new(eos_l, l, eos_r, r).unwrap();
    let s = sol.star;
    check_wave(eos_l, l, s.u, s.p, s.rho_l, sol.left_wave(), 1.0);
    check_wave(eos_r, r, s.u, s.p, s.rho_r, sol.right_wave(), -1.0);
    let eps = 1e-9 * (1.0 + s.u.abs());
    let (a, b) = (sol.sample(s.u - eps), sol.sample(s.u + eps));
    assert!(a.left && !b.left);
    assert_eq!((a.rho, a.u, a.p), (s.rho_l, s.u, s.p));
    assert_eq!((b.rho, b.u, b.p), (s.rho_r, s.u, s.p));
    sol
}

#[test]
fn toro_tests_satisfy_jump_relations() {
    for (l, r) in [
        (st(1.0, 0.0, 1.0), st(0.125, 0.0, 0.1)),
        (st(1.0, -2.0, 0.4), st(1.0, 2.0, 0.4)),
        (st(1.0, 0.0, 1000.0), st(1.0, 0.0, 0.01)),
        (st(1.0, 0.0, 0.01), st(1.0, 0.0, 100.0)),
        (st(5.99924, 19.5975, 460.894), st(5.99242, -6.19633, 46.0950)),
    ] {
        check_solution(&AIR, l, &AIR, r);
    }
}

/// Water / air shock tubes with stiffened-gas and Tait water: rarefaction in water and shock in
/// air, the reverse, and a collision (two shocks), in both orientations.
#[test]
fn two_phase_star_states() {
    for water in [WATER_SG, tait_water()] {
        let cases = [
            (st(1000.0, 0.0, 1e9), st(50.0, 0.0, 1e5)),
            (st(1000.0, 0.0, 1e5), st(50.0, 0.0, 1e8)),
            (st(1000.0, 100.0, 1e5), st(1.3, -100.0, 1e5)),
            (st(1000.0, -5.0, 3e7), st(1.3, 0.0, 1e5)),
        ];
        for (w, a) in cases {
            let w = if water.is_barotropic() { st(water.tait_density(w.p), w.u, w.p) } else { w };
            let sol = check_solution(&water, w, &AIR, a);
            // Mirror image: the same star state with u -> -u.
            let m = solve(&AIR, st(a.rho, -a.u, a.p), &water, st(w.rho, -w.u, w.p)).unwrap();
            assert!(close(m.p, sol.star.p, 1e-12) && close(m.rho_r, sol.star.rho_l, 1e-12));
            assert!((m.u + sol.star.u).abs() <= 1e-12 * (1.0 + sol.star.u.abs()));
        }
    }
    // Stiffened-gas water at 1e9 Pa expanding into air at 1e5 Pa: a strong air shock.
    let s = solve(&WATER_SG, st(1000.0, 0.0, 1e9), &AIR, st(50.0, 0.0, 1e5)).unwrap();
    assert!(s.p > 1e5 && s.p < 1e9 && s.u > 0.0 && s.rho_r > 50.0 && s.rho_l < 1000.0);
}

/// Conservation of the sampled solution: for `X` beyond all waves,
/// `∫_{-X}^{X} q(x, 1) dx = X (q_l + q_r) - (f_r - f_l)` for mass, momentum and energy.
fn check_conservation(eos_l: &Eos, l: State1d, eos_r: &Eos, r: State1d) {
    let sol = RiemannSolution::new(eos_l, l, eos_r, r).unwrap();
    let x = 1.2
        * [sol.left_wave().0, sol.right_wave().0, sol.left_wave().1, sol.right_wave().1]
            .iter()
            .fold(0.0f64, |m, v| m.max(v.abs()));
    let cons = |eos: &Eos, rho: f64, u: f64, p: f64| {
        let q = eos.prim_to_cons(&[rho, u, 0.0, 0.0, p]);
        [q[0], q[1], q[4]]
    };
    let flux = |eos: &Eos, s: State1d| {
        let q = cons(eos, s.rho, s.u, s.p);
        [q[1], q[1] * s.u + s.p, (q[2] + s.p) * s.u]
    };
    let n = 400_000;
    let h = 2.0 * x / n as f64;
    let mut integral = [0.0; 3];
    for i in 0..n {
        let s = sol.sample(-x + (i as f64 + 0.5) * h);
        let q = cons(if s.left { eos_l } else { eos_r }, s.rho, s.u, s.p);
        for k in 0..3 {
            integral[k] += h * q[k];
        }
    }
    let (ql, qr) = (cons(eos_l, l.rho, l.u, l.p), cons(eos_r, r.rho, r.u, r.p));
    let (fl, fr) = (flux(eos_l, l), flux(eos_r, r));
    // A barotropic (Tait) shock does not conserve the carried energy: mass and momentum only.
    let checked = if eos_l.is_barotropic() || eos_r.is_barotropic() { 2 } else { 3 };
    for k in 0..checked {
        let exact = x * (ql[k] + qr[k]) - (fr[k] - fl[k]);
        let scale = x * (ql[k].abs() + qr[k].abs()) + fl[k].abs() + fr[k].abs();
        assert!(
            (integral[k] - exact).abs() <= 2e-5 * scale,
            "component {k}: {} vs {exact}",
            integral[k]
        );
    }
}

#[test]
fn sampled_solutions_conserve() {
    check_conservation(&AIR, st(1.0, 0.0, 1.0), &AIR, st(0.125, 0.0, 0.1));
    check_conservation(&AIR, st(1.0, -2.0, 0.4), &AIR, st(1.0, 2.0, 0.4));
    check_conservation(&AIR, st(1.0, 0.0, 1000.0), &AIR, st(1.0, 0.0, 0.01));
    check_conservation(&WATER_SG, st(1000.0, 0.0, 1e9), &AIR, st(50.0, 0.0, 1e5));
    check_conservation(&AIR, st(50.0, 0.0, 1e8), &WATER_SG, st(1000.0, 0.0, 1e5));
    let tait = tait_water();
    check_conservation(&tait, st(tait.tait_density(1e9), 0.0, 1e9), &AIR, st(50.0, 0.0, 1e5));
    check_conservation(&AIR, st(50.0, 0.0, 1e8), &tait, st(1000.0, 0.0, 1e5));
    check_conservation(&tait, st(1000.0, 20.0, 1e5), &tait, st(1000.0, -20.0, 1e5));
}

/// Mass and momentum only for Tait (its energy is not conserved across a shock).
#[test]
fn sampled_tait_solution_is_continuous_and_monotone_in_fans() {
    let water = st(tait_water().tait_density(1e8), 0.0, 1e8);
    let sol = RiemannSolution::new(&tait_water(), water, &AIR, st(1.3, 0.0, 1e5)).unwrap();
    let (head, tail) = sol.left_wave();
    assert!(head < tail);
    let mut prev = sol.sample(head - 1e-9);
    for i in 1..=100 {
        let s = sol.sample(head + (tail - head) * i as f64 / 100.0);
        assert!(s.p <= prev.p && s.rho <= prev.rho && s.u >= prev.u);
        assert!(close(tait_water().tait_pressure(s.rho), s.p, 1e-9));
        prev = s;
    }
    assert!(close(prev.p, sol.star.p, 1e-9) && close(prev.u, sol.star.u, 1e-9));
}

/// Non-finite input ends in an error, never a hang or a panic.
#[test]
fn non_finite_input_is_an_error() {
    let bad = solve(&AIR, st(f64::NAN, 0.0, 1.0), &AIR, st(1.0, 0.0, 1.0));
    assert!(matches!(bad, Err(RiemannError::NoConvergence { .. })), "{bad:?}");
    assert!(fluid_structure(&AIR, 1.0, f64::NAN, 1.0, 0.0).is_err());
    assert!(fluid_structure(&AIR, 1.0, 0.0, f64::INFINITY, 0.0).is_err());
}

#[test]
fn vacuum_is_reported() {
    let err = solve(&AIR, st(1.0, -20.0, 0.4), &AIR, st(1.0, 20.0, 0.4)).unwrap_err();
    assert!(matches!(err, RiemannError::Vacuum { p_floor, gap } if p_floor == 0.0 && gap > 0.0));
}

/// DESIGN §8.3: a wall moving at 10 m/s into air at rest (ρ = 1.3, p = 1e5, γ = 1.4; with
/// ρ = 1.2 or 1.225 the numbers differ by 3-4%): shock 334.2 m/s, p - p0 = 4345 Pa,
/// ρ - ρ0 = 0.0401. The normal points from the fluid into the wall, which moves towards the fluid.
#[test]
fn piston_into_air() {
    let (rho0, p0) = (1.3, 1e5);
    let ws = fluid_structure(&AIR, rho0, 0.0, p0, -10.0).unwrap();
    // Shock speed (away from the wall, lab frame) from mass conservation.
    let speed = ws.rho * 10.0 / (ws.rho - rho0);
    assert!((ws.p - p0 - 4345.0).abs() < 0.5, "{}", ws.p - p0);
    assert!((ws.rho - rho0 - 0.0401).abs() < 5e-5, "{}", ws.rho - rho0);
    assert!((speed - 334.2).abs() < 0.05, "{speed}");
    check_wave(&AIR, st(rho0, 0.0, p0), -10.0, ws.p, ws.rho, (-speed, -speed), 1.0);
    // The full profile: undisturbed beyond the shock, the wall state behind it.
    let sol = RiemannSolution::wall(&AIR, st(rho0, 0.0, p0), -10.0).unwrap();
    assert!((sol.left_wave().0 + speed).abs() <= 1e-9 * speed);
    let behind = sol.sample(-0.5 * speed);
    assert!(close(behind.p, ws.p, 1e-13) && close(behind.rho, ws.rho, 1e-13));
    assert!((behind.u + 10.0).abs() < 1e-9 && sol.sample(-1.01 * speed).p == p0);
}

/// The one-sided problem equals App. A's mirrored symmetric problem (star velocity 0 in the wall
/// frame), and the gas rarefaction matches the closed form of thesis Eq. A.14-A.15.
#[test]
fn fluid_structure_matches_mirror_and_closed_form() {
    for eos in [AIR, WATER_SG, tait_water()] {
        let (rho, p) = if eos == AIR { (1.3, 1e5) } else { (1000.0, 3e7) };
        let rho = if eos.is_barotropic() { eos.tait_density(p) } else { rho };
        for (un, wn) in [(0.0, -10.0), (0.0, 10.0), (3.0, 50.0), (-20.0, 100.0), (400.0, -20.0)] {
            let ws = fluid_structure(&eos, rho, un, p, wn).unwrap();
            let rel = un - wn;
            let m = solve(&eos, st(rho, rel, p), &eos, st(rho, -rel, p)).unwrap();
            assert!(close(ws.p, m.p, 1e-12) && close(ws.rho, m.rho_l, 1e-12), "{eos:?} {un} {wn}");
            assert!(m.u.abs() <= 1e-12 * rel.abs().max(1.0));
            let dir = 1.0;
            let sol = RiemannSolution::new(&eos, st(rho, un, p), &eos, st(rho, 2.0 * wn - un, p))
                .unwrap();
            check_wave(&eos, st(rho, un, p), wn, ws.p, ws.rho, sol.left_wave(), dir);
            if rel < 0.0 && !eos.is_barotropic() {
                let (g, pc) = eos.stiffness();
                let c = eos.sound_speed(rho, p);
                let p_exact =
                    (p + pc) * (1.0 + 0.5 * (g - 1.0) * rel / c).powf(2.0 * g / (g - 1.0)) - pc;
                let rho_exact = rho * ((p_exact + pc) / (p + pc)).powf(1.0 / g);
                assert!(close(ws.p, p_exact, 1e-12) && close(ws.rho, rho_exact, 1e-12));
            }
        }
    }
}

/// DESIGN §8.4 water side: the shell recedes from the water at 10 m/s, a rarefaction to
/// ρ* ≈ 993.3. Tait (k1 = 2.066e9 in that case) by the closed form `c* = c - (β - 1)/2 · 10`.
#[test]
fn water_rarefaction_of_the_1d_fsi_case() {
    let sg = fluid_structure(&WATER_SG, 1000.0, 0.0, 3e7, 10.0).unwrap();
    let tait = Eos::tait(2.066e9, 7.15, 1000.0, 3e7);
    let tt = fluid_structure(&tait, 1000.0, 0.0, 3e7, 10.0).unwrap();
    assert!((sg.rho - 993.3).abs() < 0.1, "{}", sg.rho);
    assert!((tt.rho - 993.3).abs() < 0.1, "{}", tt.rho);
    let Eos::Tait { rho0, alpha, beta, .. } = tait else { unreachable!() };
    let c = tait.sound_speed(1000.0, 3e7) - 0.5 * (beta - 1.0) * 10.0;
    let rho_exact = rho0 * (c * c * rho0 / (alpha * beta)).powf(1.0 / (beta - 1.0));
    assert!(close(tt.rho, rho_exact, 1e-12) && close(tt.p, tait.tait_pressure(rho_exact), 1e-12));
}

#[test]
fn receding_wall_can_open_a_vacuum() {
    let c = AIR.sound_speed(1.3, 1e5);
    assert!(fluid_structure(&AIR, 1.3, 0.0, 1e5, 4.9 * c).is_ok());
    assert!(matches!(
        fluid_structure(&AIR, 1.3, 0.0, 1e5, 5.1 * c),
        Err(RiemannError::Vacuum { .. })
    ));
}

/// DESIGN §5.1 cavitation: water at 1 atm (Tait, and stiffened gas) behind a wall receding at
/// 1, 10 and 100 m/s. Without the cut-off the exact solver returns tension (`p* < 0`, about
/// `p0 - ρc w`); with it `p* = p_cut`, `ρ*` on the node's isentrope at `p_cut`, and the clip is
/// flagged. A wall at rest or advancing is not clipped and keeps the exact star state bitwise.
#[test]
fn cavitation_cutoff_holds_receding_water_at_the_vapour_pressure() {
    let tait = tait_water();
    let sg = Eos::StiffenedGas { gamma: 7.15, p_c: 2.89e8 };
    for eos in [tait, sg] {
        let cut = PressureCutoff::default_for(&eos);
        assert_eq!(cut.p_cut, WATER_VAPOUR_PRESSURE_20C);
        let (rho, p) = (1000.0, if eos.is_barotropic() { tait.tait_pressure(1000.0) } else { 1e5 });
        let z = rho * eos.sound_speed(rho, p);
        for w in [1.0, 10.0, 100.0] {
            let exact = fluid_structure(&eos, rho, 0.0, p, w).unwrap();
            // Acoustic estimate p - ρcw, within the nonlinear correction of a strong rarefaction.
            assert!(exact.p < 0.0 && close(exact.p, p - z * w, 0.2), "{eos:?} {w}: {}", exact.p);
            let c = fluid_structure_with_cutoff(&eos, rho, 0.0, p, w, cut).unwrap();
            assert!(c.clipped && c.state.p == cut.p_cut, "{eos:?} {w}: {c:?}");
            let (g, pi) = eos.stiffness();
            let rho_cut = rho * ((cut.p_cut + pi) / (p + pi)).powf(1.0 / g);
            assert!(close(c.state.rho, rho_cut, 1e-13) && c.state.rho < rho);
            if eos.is_barotropic() {
                assert!(close(eos.tait_pressure(c.state.rho), cut.p_cut, 1e-6));
            }
        }
        for w in [0.0, -10.0, 0.05] {
            let exact = fluid_structure(&eos, rho, 0.0, p, w).unwrap();
            let c = fluid_structure_with_cutoff(&eos, rho, 0.0, p, w, cut).unwrap();
            assert!(!c.clipped && c.state == exact, "{eos:?} {w}");
        }
    }
    // DESIGN §5.1: 1 atm Tait water, 0.1 m/s of recession, p* about -4.4e4 Pa.
    let p01 = fluid_structure(&tait, 1000.0, 0.0, tait.tait_pressure(1000.0), 0.1).unwrap().p;
    assert!((p01 + 4.4e4).abs() < 0.1e4, "{p01}");
}

/// A receding wall faster than the escape speed opens a void: an error without the cut-off, the
/// cut-off pressure with it (stiffened water, whose floor -p_c lies below p_cut).
#[test]
fn cavitation_cutoff_replaces_a_void_and_gases_keep_the_error() {
    let escape = 2.0 * WATER_SG.sound_speed(1000.0, 1e5) / (7.15 - 1.0);
    let w = 1.2 * escape;
    assert!(matches!(
        fluid_structure(&WATER_SG, 1000.0, 0.0, 1e5, w),
        Err(RiemannError::Vacuum { .. })
    ));
    let cut = PressureCutoff::default_for(&WATER_SG);
    let c = fluid_structure_with_cutoff(&WATER_SG, 1000.0, 0.0, 1e5, w, cut).unwrap();
    assert!(c.clipped && c.state.p == WATER_VAPOUR_PRESSURE_20C && c.state.rho > 0.0);
    // A perfect gas: off by default; a cut-off at the floor p = 0 would hold a void, so it does
    // not act and the vacuum stays an error.
    assert_eq!(PressureCutoff::default_for(&AIR), PressureCutoff::OFF);
    let c = AIR.sound_speed(1.3, 1e5);
    let zero = PressureCutoff { p_cut: 0.0 };
    assert!(matches!(
        fluid_structure_with_cutoff(&AIR, 1.3, 0.0, 1e5, 5.1 * c, zero),
        Err(RiemannError::Vacuum { .. })
    ));
    // A gas with a positive cut-off clips to it like a liquid.
    let c1 =
        fluid_structure_with_cutoff(&AIR, 1.3, 0.0, 1e5, 5.1 * c, PressureCutoff { p_cut: 10.0 })
            .unwrap();
    assert!(c1.clipped && c1.state.p == 10.0);
}

/// The two-phase solver with the cut-off: water pulled apart from water (and from air) is held at
/// `p_cut` on both wave curves; unclipped problems equal [`solve`] bitwise.
#[test]
fn two_phase_cutoff() {
    let tait = tait_water();
    let cut = PressureCutoff::default_for(&tait);
    let p = tait.tait_pressure(1000.0);
    // Water pulled apart at 20 m/s; water pulled from air that leaves at 1000 m/s (the air
    // rarefies to p_cut).
    for (eos_r, r) in [(tait, st(1000.0, 10.0, p)), (AIR, st(1.2, 1000.0, 1e5))] {
        let l = st(1000.0, -10.0, p);
        let c = solve_with_cutoff(&tait, l, &eos_r, r, cut).unwrap();
        assert!(c.clipped && c.state.p == cut.p_cut, "{c:?}");
        assert!(close(tait.tait_pressure(c.state.rho_l), cut.p_cut, 1e-6));
        let (g, pi) = eos_r.stiffness();
        assert!(close(c.state.rho_r, r.rho * ((cut.p_cut + pi) / (r.p + pi)).powf(1.0 / g), 1e-13));
        let calm = solve_with_cutoff(&tait, st(1000.0, 1.0, p), &eos_r, st(r.rho, -1.0, r.p), cut)
            .unwrap();
        let exact = solve(&tait, st(1000.0, 1.0, p), &eos_r, st(r.rho, -1.0, r.p)).unwrap();
        assert!(!calm.clipped && calm.state == exact);
    }
}

fn gas_state() -> impl Strategy<Value = State1d> {
    (-3.0f64..3.0, -3.0f64..3.0, -6.0f64..6.0)
        .prop_map(|(lr, u, lp)| st(10f64.powf(lr), u * 100.0, 10f64.powf(lp)))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]
    /// Any pair of gas states: either a star state satisfying the jump relations, or `Vacuum`
    /// exactly when the pressure-positivity condition `2(c_l + c_r)/(γ - 1) <= Δu` holds.
    #[test]
    fn random_gas_problems(l in gas_state(), r in gas_state()) {
        let vacuum = 5.0 * (AIR.sound_speed(l.rho, l.p) + AIR.sound_speed(r.rho, r.p)) <= r.u - l.u;
        match RiemannSolution::new(&AIR, l, &AIR, r) {
            Ok(sol) => {
                prop_assert!(!vacuum);
                let s = sol.star;
                check_wave(&AIR, l, s.u, s.p, s.rho_l, sol.left_wave(), 1.0);
                check_wave(&AIR, r, s.u, s.p, s.rho_r, sol.right_wave(), -1.0);
            }
            Err(e) => prop_assert!(vacuum, "{e}"),
        }
    }
}

/// Two water models against each other: Tait at 1e8 Pa expanding into stiffened gas at 1e5 Pa,
/// and the reverse.
#[test]
fn tait_against_stiffened_water() {
    let tait = tait_water();
    let hi = st(tait.tait_density(1e8), 0.0, 1e8);
    check_solution(&tait, hi, &WATER_SG, st(1000.0, 0.0, 1e5));
    check_solution(&WATER_SG, st(1000.0, 0.0, 1e8), &tait, st(1000.0, 0.0, 1e5));
}

fn water_air_problem() -> impl Strategy<Value = (bool, State1d, State1d)> {
    (any::<bool>(), 0.0f64..1.0, -1.0f64..1.0, -2.0f64..1.0, -1.0f64..1.0, 3.0f64..8.0).prop_map(
        |(tait, pw, uw, lra, ua, lpa)| {
            let water = if tait { tait_water() } else { WATER_SG };
            let p_w = 1e5 + 1e9 * pw;
            let rho_w = if tait { water.tait_density(p_w) } else { 990.0 + 20.0 * pw };
            (tait, st(rho_w, 100.0 * uw, p_w), st(10f64.powf(lra), 300.0 * ua, 10f64.powf(lpa)))
        },
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]
    /// Random water (stiffened or Tait) | air problems: a star state satisfying the jump relations
    /// on both sides, or `Vacuum` exactly when both rarefactions down to zero air pressure still
    /// cannot close the velocity gap:
    /// `Δu >= 2c_a/(γ - 1) + 2c_w/(g - 1)(1 - (π/(p_w + π))^((g-1)/2g))`.
    #[test]
    fn random_water_air_problems((tait, w, a) in water_air_problem()) {
        let water = if tait { tait_water() } else { WATER_SG };
        let (g, pi) = water.stiffness();
        let c_w = water.sound_speed(w.rho, w.p);
        let reach = 5.0 * AIR.sound_speed(a.rho, a.p)
            + 2.0 * c_w / (g - 1.0) * (1.0 - (pi / (w.p + pi)).powf((g - 1.0) / (2.0 * g)));
        match RiemannSolution::new(&water, w, &AIR, a) {
            Ok(sol) => {
                prop_assert!(a.u - w.u < reach);
                let s = sol.star;
                check_wave(&water, w, s.u, s.p, s.rho_l, sol.left_wave(), 1.0);
                check_wave(&AIR, a, s.u, s.p, s.rho_r, sol.right_wave(), -1.0);
            }
            Err(e) => prop_assert!(a.u - w.u >= reach * (1.0 - 1e-12), "{e}"),
        }
    }
}

/// The closed-form root of the one-sided problem (`Side::root`: rarefactions of every EOS, gas
/// shocks) is Newton's root of `f(p*) = u_n - w_n` to round-off, from strong rarefactions near the
/// escape speed to strong shocks, on air, stiffened water and Tait water (rarefactions).
#[test]
fn closed_form_wall_root_is_newtons() {
    let cases: [(Eos, f64, f64); 3] =
        [(AIR, 1.2, 1e5), (WATER_SG, 1000.0, 1e5), (tait_water(), 1000.0, 1e5)];
    let mut worst: f64 = 0.0;
    for (eos, rho, p) in cases {
        let side = wave_curve::Side::new(&eos, rho, 0.0, p);
        let escape = 2.0 * side.c / (eos.stiffness().0 - 1.0);
        for k in -99..=200 {
            // From 0.99 of the escape speed (receding) to twice the sound speed (approaching).
            let du = if k < 0 { 0.01 * k as f64 * escape } else { 0.01 * k as f64 * side.c };
            let Some(root) = side.root(du) else {
                assert!(eos.is_barotropic() && du > 0.0, "{eos:?}: no closed form for {du}");
                continue;
            };
            let root = root.unwrap();
            let newton = solve_increasing(
                |q| {
                    let (f, df) = side.f(q);
                    (f - du, df)
                },
                side.p_floor(),
                p + rho * side.c * du,
            )
            .unwrap();
            let scale = newton + side.pi;
            worst = worst.max((root - newton).abs() / scale);
            assert!((root - newton).abs() <= 1e-13 * scale, "{eos:?}, du {du}: {root} vs {newton}");
        }
        // Past the escape speed: the same vacuum as Newton's.
        let beyond = side.root(-1.01 * escape).unwrap();
        assert!(matches!(beyond, Err(RiemannError::Vacuum { gap, .. }) if gap > 0.0), "{beyond:?}");
    }
    println!("closed-form wall root against Newton: largest difference {worst:e} of p̂*");
}
