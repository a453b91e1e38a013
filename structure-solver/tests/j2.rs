//! Materials: elastic stress and tangent against finite differences of the energy, J2 consistent
//! tangents against finite differences of the return maps, J2 uniaxial loading, unloading and
//! reverse yield against the closed form for the 3D and the plane-stress returns, the
//! safeguarded fallback of the plane-stress return on increments 3 Newton updates cannot
//! handle, and the through-thickness rules.

use structure_solver::material::j2::{J2State3d, J2StatePlane};
use structure_solver::material::{Elastic, ThicknessRule, J2};

fn steel() -> J2 {
    J2 { elastic: Elastic { e: 200e9, nu: 0.3, rho: 7800.0 }, sigma_y: 250e6, h: 2e9 }
}

#[test]
fn elastic_stress_is_the_energy_gradient_and_tangent_the_stress_gradient() {
    let m = steel().elastic;
    let eps = [1e-3, -4e-4, 2.5e-4, 7e-4, -3e-4, 5e-4];
    let s = m.stress_3d(&eps);
    let c = m.tangent_3d();
    let h = 1e-7;
    for i in 0..6 {
        let (mut ep, mut em) = (eps, eps);
        ep[i] += h;
        em[i] -= h;
        let fd = (m.energy_3d(&ep) - m.energy_3d(&em)) / (2.0 * h);
        assert!(
            (fd - s[i]).abs() < 1e-6 * s.iter().map(|v| v.abs()).fold(0.0, f64::max),
            "3D stress {i}: {fd} vs {}",
            s[i]
        );
        let (sp, sm) = (m.stress_3d(&ep), m.stress_3d(&em));
        for j in 0..6 {
            let fd = (sp[j] - sm[j]) / (2.0 * h);
            assert!((fd - c[j][i]).abs() < 1e-6 * m.e, "3D tangent ({j},{i})");
        }
    }
    let eps = [1e-3, -4e-4, 7e-4];
    let s = m.stress_plane_stress(&eps);
    let c = m.tangent_plane_stress();
    for i in 0..3 {
        let (mut ep, mut em) = (eps, eps);
        ep[i] += h;
        em[i] -= h;
        let fd = (m.energy_plane_stress(&ep) - m.energy_plane_stress(&em)) / (2.0 * h);
        assert!((fd - s[i]).abs() < 1e-6 * 3e8, "plane stress {i}: {fd} vs {}", s[i]);
        let (sp, sm) = (m.stress_plane_stress(&ep), m.stress_plane_stress(&em));
        for j in 0..3 {
            assert!(((sp[j] - sm[j]) / (2.0 * h) - c[j][i]).abs() < 1e-6 * m.e);
        }
    }
}

/// Largest `|∂σ/∂ε (central differences) - C| / E` of a return map `stress` at `eps`.
fn tangent_error<const N: usize>(
    eps: [f64; N],
    c: &[[f64; N]; N],
    e: f64,
    stress: impl Fn(&[f64; N]) -> [f64; N],
) -> f64 {
    let h = 1e-9;
    let mut worst: f64 = 0.0;
    for i in 0..N {
        let (mut ep, mut em) = (eps, eps);
        ep[i] += h;
        em[i] -= h;
        let (sp, sm) = (stress(&ep), stress(&em));
        for j in 0..N {
            worst = worst.max(((sp[j] - sm[j]) / (2.0 * h) - c[j][i]).abs() / e);
        }
    }
    worst
}

#[test]
fn j2_3d_consistent_tangent_matches_finite_differences_of_the_return_map() {
    let m = steel();
    let state = J2State3d { eps_p: [1e-3, -5e-4, -5e-4, 2e-4, 0.0, -1e-4], alpha: 1.2e-3 };
    let eps = [4.5e-3, -1.5e-3, -2.0e-3, 3e-3, 1e-3, -2e-3];
    let (_, new, c) = m.update_3d(&eps, &state);
    assert!(new.alpha > state.alpha, "the point must be plastic for this test");
    let worst = tangent_error(eps, &c, m.elastic.e, |e| m.update_3d(e, &state).0);
    println!("3D tangent vs FD: max error / E = {worst:.3e}");
    assert!(worst < 1e-6);
}

#[test]
fn j2_plane_stress_consistent_tangent_matches_finite_differences_of_the_return_map() {
    let m = steel();
    let state = J2StatePlane { eps_p: [1e-3, -4e-4, 5e-4], alpha: 1.1e-3 };
    for eps in [[5e-3, -1e-3, 2e-3], [3e-3, 3.1e-3, 0.0], [1e-3, -2e-3, 6e-3]] {
        let (_, new, c) = m.update_plane_stress(&eps, &state);
        assert!(new.alpha > state.alpha, "the point must be plastic for this test");
        let worst = tangent_error(eps, &c, m.elastic.e, |e| m.update_plane_stress(e, &state).0);
        println!("plane-stress tangent vs FD at {eps:?}: max error / E = {worst:.3e}");
        assert!(worst < 1e-6);
    }
}

/// Closed-form uniaxial response on the path 0 -> ε1 -> ε (ε below ε1): stress, plastic strain
/// (axial component) and equivalent plastic strain.
fn uniaxial_closed_form(m: &J2, eps1: f64, eps: f64, loading: bool) -> (f64, f64, f64) {
    let (e, h, sy) = (m.elastic.e, m.h, m.sigma_y);
    let et = e * h / (e + h);
    let ey = sy / e;
    let load = |x: f64| if x <= ey { e * x } else { sy + et * (x - ey) };
    if loading {
        let s = load(eps);
        return (s, eps - s / e, (s - sy).max(0.0) / h);
    }
    let smax = load(eps1);
    let alpha1 = (smax - sy).max(0.0) / h;
    let eps_r = eps1 - 2.0 * smax / e;
    let s = if eps >= eps_r { smax - e * (eps1 - eps) } else { -smax - et * (eps_r - eps) };
    let alpha = alpha1 + (-s - smax).max(0.0) / h;
    (s, eps - s / e, alpha)
}

/// Drives `ε_xx` along 0 -> 1% -> -1% with the lateral strains solved (Newton with the
/// consistent tangent) so the lateral stresses vanish; checks every step against the closed form.
#[test]
fn j2_3d_uniaxial_loading_unloading_and_reverse_yield_match_the_closed_form() {
    let m = steel();
    let (e, nu) = (m.elastic.e, m.elastic.nu);
    let mut state = J2State3d::default();
    let mut lateral = 0.0;
    let (n, eps1) = (200, 0.01);
    let mut newton_max = 0;
    let mut worst = [0.0f64; 4];
    for k in 1..=3 * n {
        let (eps11, loading) = if k <= n {
            (eps1 * k as f64 / n as f64, true)
        } else {
            (eps1 - eps1 * (k - n) as f64 / n as f64, false)
        };
        let mut it = 0;
        let (sigma, new) = loop {
            let eps = [eps11, lateral, lateral, 0.0, 0.0, 0.0];
            let (s, new, c) = m.update_3d(&eps, &state);
            if s[1].abs() < 1e-6 || it > 20 {
                break (s, new);
            }
            // σ_yy(ε_yy = ε_zz = x): slope c11 + c12.
            lateral -= s[1] / (c[1][1] + c[1][2]);
            it += 1;
        };
        newton_max = newton_max.max(it);
        state = new;
        let (s, ep, alpha) = uniaxial_closed_form(&m, eps1, eps11, loading);
        let lat = -nu * s / e - 0.5 * ep;
        worst[0] = worst[0].max((sigma[0] - s).abs() / m.sigma_y);
        worst[1] = worst[1].max((state.eps_p[0] - ep).abs());
        worst[2] = worst[2].max((state.alpha - alpha).abs());
        worst[3] = worst[3].max((lateral - lat).abs());
        assert!(sigma[2].abs() < 1e-3 && sigma[3].abs() < 1e-6);
    }
    println!("3D uniaxial: max |Δσ|/σy {:.2e}, |Δεp| {:.2e}, |Δα| {:.2e}, |Δε_lat| {:.2e}, Newton its <= {newton_max}", worst[0], worst[1], worst[2], worst[3]);
    assert!(worst[0] < 1e-9 && worst[1] < 1e-12 && worst[2] < 1e-12 && worst[3] < 1e-12);
    // The path went through reverse yield: the final stress is on the reversed branch.
    assert!(state.alpha > 2.0 * 0.01 - 1e-3);
}

#[test]
fn j2_plane_stress_uniaxial_loading_unloading_and_reverse_yield_match_the_closed_form() {
    let m = steel();
    let (e, nu) = (m.elastic.e, m.elastic.nu);
    let mut state = J2StatePlane::default();
    let mut lateral = 0.0;
    let (n, eps1) = (200, 0.01);
    let mut worst = [0.0f64; 5];
    for k in 1..=3 * n {
        let (eps11, loading) = if k <= n {
            (eps1 * k as f64 / n as f64, true)
        } else {
            (eps1 - eps1 * (k - n) as f64 / n as f64, false)
        };
        let mut it = 0;
        let (sigma, new) = loop {
            let (s, new, c) = m.update_plane_stress(&[eps11, lateral, 0.0], &state);
            if s[1].abs() < 1e-6 || it > 20 {
                break (s, new);
            }
            lateral -= s[1] / c[1][1];
            it += 1;
        };
        state = new;
        let (s, ep, alpha) = uniaxial_closed_form(&m, eps1, eps11, loading);
        let lat = -nu * s / e - 0.5 * ep;
        // Thickness strain: elastic -ν σ/E and plastic -(εp_xx + εp_yy) = -εp/2.
        let thick = -nu / e * (sigma[0] + sigma[1]) - (state.eps_p[0] + state.eps_p[1]);
        worst[0] = worst[0].max((sigma[0] - s).abs() / m.sigma_y);
        worst[1] = worst[1].max((state.eps_p[0] - ep).abs());
        worst[2] = worst[2].max((state.alpha - alpha).abs());
        worst[3] = worst[3].max((lateral - lat).abs());
        worst[4] = worst[4].max((thick - lat).abs());
    }
    println!("plane-stress uniaxial: max |Δσ|/σy {:.2e}, |Δεp| {:.2e}, |Δα| {:.2e}, |Δε_yy| {:.2e}, |Δε_zz| {:.2e}", worst[0], worst[1], worst[2], worst[3], worst[4]);
    assert!(
        worst[0] < 1e-9
            && worst[1] < 1e-12
            && worst[2] < 1e-12
            && worst[3] < 1e-12
            && worst[4] < 1e-12
    );
}

/// The reason shells need the plane-stress return (DESIGN §6): a 3D radial return applied to the
/// plane-stress trial misses `σ_zz = 0` and underestimates stress and plastic strain.
#[test]
fn radial_return_on_a_plane_stress_trial_is_wrong_and_the_plane_stress_return_is_not() {
    let m = steel();
    let (mut s_ps, mut s_3d) = ([0.0; 3], [0.0; 6]);
    let (mut a_ps, mut a_3d) = (0.0, 0.0);
    // Uniaxial stress increments of a hypoelastic update: the trial is the elastic plane-stress
    // stress rate times the strain increment (lateral strain from the elastic ratio, as an
    // explicit shell would do with the current tangent).
    let n = 1000;
    let de = 0.01 / n as f64;
    for _ in 0..n {
        let t = [s_ps[0] + m.elastic.e * de, s_ps[1], s_ps[2]];
        let r = m.return_plane_stress(t, a_ps, 50, 1e-14);
        s_ps = r.sigma;
        a_ps = r.alpha;
        let t = [s_3d[0] + m.elastic.e * de, s_3d[1], 0.0, s_3d[2], 0.0, 0.0];
        let r = m.return_3d(&t, a_3d);
        s_3d = [r.sigma[0], r.sigma[1], r.sigma[3], 0.0, 0.0, 0.0];
        a_3d = r.alpha;
    }
    let rel_s = (s_3d[0] - s_ps[0]) / s_ps[0];
    let rel_a = (a_3d - a_ps) / a_ps;
    println!(
        "3D return on plane-stress trials: stress {:+.2}%, plastic strain {:+.2}%",
        100.0 * rel_s,
        100.0 * rel_a
    );
    assert!(rel_s.abs() > 1e-3 && rel_a.abs() > 1e-2);
}

#[test]
fn plane_stress_return_with_three_newton_updates_is_converged_for_explicit_increments() {
    let m = steel();
    // From a yielded state, trials up to 20% outside the yield surface (an explicit step moves
    // the trial by far less).
    let mut worst: f64 = 0.0;
    for k in 1..=10 {
        let kappa = m.yield_stress(1e-3);
        let dir = [1.0, -0.4 + 0.08 * k as f64, 0.1 * k as f64];
        let xi =
            (dir[0] * dir[0] - dir[0] * dir[1] + dir[1] * dir[1] + 3.0 * dir[2] * dir[2]).sqrt();
        let trial = dir.map(|d| d * kappa / xi * (1.0 + 0.02 * k as f64));
        let exact = m.return_plane_stress(trial, 1e-3, 50, 1e-15);
        let three = m.return_plane_stress(trial, 1e-3, 3, 0.0);
        for i in 0..3 {
            worst = worst.max((exact.sigma[i] - three.sigma[i]).abs() / m.sigma_y);
        }
    }
    println!("3 Newton updates vs converged: max |Δσ|/σy = {worst:.2e}");
    assert!(worst < 1e-8);
}

#[test]
fn thickness_rules_integrate_polynomials_and_give_the_plastic_moment_factor() {
    for n in 1..=10 {
        let g = ThicknessRule::gauss(n);
        for p in 0..2 * n {
            let q: f64 = g.points.iter().zip(&g.weights).map(|(x, w)| w * x.powi(p as i32)).sum();
            let exact = if p % 2 == 0 { 2.0 / (p as f64 + 1.0) } else { 0.0 };
            assert!((q - exact).abs() < 1e-13, "Gauss {n} degree {p}: {q}");
        }
    }
    for n in 2..=10 {
        let l = ThicknessRule::lobatto(n);
        assert_eq!((l.points[0], l.points[n - 1]), (-1.0, 1.0));
        for p in 0..2 * n - 2 {
            let q: f64 = l.points.iter().zip(&l.weights).map(|(x, w)| w * x.powi(p as i32)).sum();
            let exact = if p % 2 == 0 { 2.0 / (p as f64 + 1.0) } else { 0.0 };
            assert!((q - exact).abs() < 1e-13, "Lobatto {n} degree {p}: {q}");
        }
    }
    // Five Gauss points reach 0.945 M_p (DESIGN §8).
    let f5 = ThicknessRule::gauss(5).plastic_moment_factor();
    assert!((f5 - 0.9448).abs() < 1e-4, "{f5}");
    assert!(ThicknessRule::gauss(8).plastic_moment_factor() > 0.98);
}

/// `f = ½ σᵀPσ - ⅓ κ(α)²` of a plane-stress return's result, relative to `κ²`.
fn yield_residual(m: &J2, r: &structure_solver::material::PlaneStressReturn) -> f64 {
    let s = r.sigma;
    let xi2 = 2.0 / 3.0 * (s[0] * s[0] + s[1] * s[1] - s[0] * s[1]) + 2.0 * s[2] * s[2];
    let kappa = m.yield_stress(r.alpha);
    (0.5 * xi2 - kappa * kappa / 3.0) / (kappa * kappa)
}

#[test]
fn plane_stress_return_falls_back_when_three_updates_are_not_enough() {
    use structure_solver::material::lanes::Lanes;
    let m = steel();
    let sy = m.sigma_y;
    // Trials far outside the surface (a large step, a shock): 3 Newton updates from the
    // radial-return estimate leave the yield condition violated.
    let trials = [
        [30.0 * sy, 29.0 * sy, 0.0],
        [10.0 * sy, 9.0 * sy, 0.1 * sy],
        [-5.0 * sy, -5.0 * sy, 0.0],
        [200.0 * sy, 190.0 * sy, 5.0 * sy],
    ];
    for trial in trials {
        let three = m.return_plane_stress(trial, 0.0, 3, 0.0);
        let safe = m.return_plane_stress(trial, 0.0, 3, 1e-12);
        let (r3, rs) = (yield_residual(&m, &three), yield_residual(&m, &safe));
        println!(
            "trial {:?} σy: 3 updates f/κ² = {r3:.2e}, with fallback {rs:.2e}",
            trial.map(|t| t / sy)
        );
        assert!(r3.abs() > 1e-7, "3 updates are enough here: {r3:e}");
        assert!(rs.abs() <= 1e-11, "the fallback must satisfy the yield condition: {rs:e}");
        assert!(safe.dgamma > 0.0 && safe.alpha > 0.0);
    }
    // Lane by lane: a hard lane among easy and elastic ones gives each lane the result of the
    // same return on its own.
    let easy = [1.1 * sy, 0.2 * sy, 0.1 * sy];
    let elastic = [0.3 * sy, 0.1 * sy, 0.0];
    let lanes: [[f64; 3]; 4] = [easy, trials[0], elastic, trials[2]];
    let t: [Lanes<4>; 3] = std::array::from_fn(|k| Lanes(lanes.map(|l| l[k])));
    let r = m.return_plane_stress(t, Lanes([1e-3; 4]), 3, 1e-12);
    for (l, trial) in lanes.iter().enumerate() {
        let one = m.return_plane_stress(*trial, 1e-3, 3, 1e-12);
        for k in 0..3 {
            assert_eq!(r.sigma[k].0[l], one.sigma[k], "lane {l} component {k}");
        }
        assert_eq!(r.alpha.0[l], one.alpha, "lane {l} plastic strain");
    }
}
