//! Time integrators on a spring-mass chain implementing `Model`: discrete periods of central
//! differences and of Newmark / implicit midpoint against their known dispersion, observed
//! orders, energy conservation of the midpoint rule, the critical step.

use faer::sparse::Triplet;
use structure_solver::model::{Model, Tangent};
use structure_solver::time::{
    critical_dt, kinetic_energy, CentralDifference, Implicit, ImplicitScheme,
};

/// Masses on the x axis joined by springs `k` (+ cubic `k3 δ³`), node 0 tied to the ground by
/// `k_ground`; only `ux` is free.
struct Chain {
    n: usize,
    k: f64,
    k3: f64,
    k_ground: f64,
    mass: Vec<f64>,
    fixed: Vec<bool>,
    u: Vec<f64>,
    committed: Vec<f64>,
}

impl Chain {
    fn new(n: usize, m: f64, k: f64, k_ground: f64) -> Chain {
        let mut mass = vec![0.0; 6 * n];
        let mut fixed = vec![true; 6 * n];
        for i in 0..n {
            mass[6 * i] = m;
            fixed[6 * i] = false;
        }
        Chain {
            n,
            k,
            k3: 0.0,
            k_ground,
            mass,
            fixed,
            u: vec![0.0; 6 * n],
            committed: vec![0.0; 6 * n],
        }
    }

    fn energy(&self) -> f64 {
        let mut e = 0.5 * self.k_ground * self.u[0] * self.u[0];
        for i in 1..self.n {
            let d = self.u[6 * i] - self.u[6 * (i - 1)];
            e += 0.5 * self.k * d * d + 0.25 * self.k3 * d.powi(4);
        }
        e
    }
}

impl Model for Chain {
    fn n_nodes(&self) -> usize {
        self.n
    }
    fn lumped_mass(&self) -> &[f64] {
        &self.mass
    }
    fn constrained(&self) -> &[bool] {
        &self.fixed
    }
    fn prescribed(&self, _t: f64, _out: &mut [f64]) {}
    fn apply_increment(&mut self, du: &[f64]) {
        for (u, d) in self.u.iter_mut().zip(du) {
            *u += d;
        }
    }
    fn internal_force(&mut self, f: &mut [f64]) {
        f.fill(0.0);
        f[0] += self.k_ground * self.u[0];
        for i in 1..self.n {
            let d = self.u[6 * i] - self.u[6 * (i - 1)];
            let s = self.k * d + self.k3 * d * d * d;
            f[6 * i] += s;
            f[6 * (i - 1)] -= s;
        }
    }
    fn external_force(&mut self, _t: f64, f: &mut [f64]) {
        f.fill(0.0);
    }
    fn tangent(&mut self, _t: f64, out: &mut Tangent) {
        out.clear();
        let out = &mut out.entries;
        out.push(Triplet::new(0, 0, self.k_ground));
        for i in 1..self.n {
            let d = self.u[6 * i] - self.u[6 * (i - 1)];
            let k = self.k + 3.0 * self.k3 * d * d;
            let (a, b) = (6 * (i - 1), 6 * i);
            out.extend([
                Triplet::new(a, a, k),
                Triplet::new(b, b, k),
                Triplet::new(a, b, -k),
                Triplet::new(b, a, -k),
            ]);
        }
    }
    fn commit(&mut self) {
        self.committed.clone_from(&self.u);
    }
    fn revert(&mut self) {
        self.u.clone_from(&self.committed);
    }
    fn stable_dt(&self) -> f64 {
        // ω_max² <= 4k/m + k_ground/m.
        2.0 / ((4.0 * self.k + self.k_ground) / self.mass[0]).sqrt()
    }
    fn displacement(&self, out: &mut [[f64; 3]]) {
        for (i, o) in out.iter_mut().enumerate() {
            *o = [self.u[6 * i], self.u[6 * i + 1], self.u[6 * i + 2]];
        }
    }
}

/// Runs a unit oscillator (ω = 1, u0 = 1) and returns the displacement history.
fn oscillator(scheme: Option<ImplicitScheme>, dt: f64, steps: usize) -> Vec<f64> {
    let mut m = Chain::new(1, 1.0, 0.0, 1.0);
    m.u[0] = 1.0;
    m.commit();
    let mut hist = vec![1.0];
    match scheme {
        None => {
            let mut cd = CentralDifference::new(&mut m, 0.0, vec![0.0; 6], None);
            for _ in 0..steps {
                cd.step(&mut m, dt, None);
                hist.push(m.u[0]);
            }
        }
        Some(s) => {
            let mut im = Implicit::new(&mut m, s, 0.0, vec![0.0; 6], None);
            im.params.tol = 1e-14;
            for _ in 0..steps {
                im.step(&mut m, dt, None).unwrap();
                hist.push(m.u[0]);
            }
        }
    }
    hist
}

/// Largest deviation of the measured `cos ΩΔt = (u_{n+1} + u_{n-1}) / (2 u_n)` from `expected`.
fn dispersion_error(hist: &[f64], expected: f64) -> f64 {
    hist.windows(3)
        .filter(|w| w[1].abs() > 0.3)
        .map(|w| ((w[0] + w[2]) / (2.0 * w[1]) - expected).abs())
        .fold(0.0, f64::max)
}

#[test]
fn central_difference_period_follows_its_discrete_dispersion_with_order_two() {
    let mut period_errors = Vec::new();
    for dt in [0.2, 0.1, 0.05] {
        let hist = oscillator(None, dt, (40.0 / dt) as usize);
        let cos_exact = 1.0 - dt * dt / 2.0;
        let err = dispersion_error(&hist, cos_exact);
        let omega = cos_exact.acos() / dt;
        println!("central difference dt {dt}: |cos ΩΔt - (1 - (ωΔt)²/2)| <= {err:.2e}, period error {:.4e}", 1.0 / omega - 1.0);
        assert!(err < 1e-10);
        period_errors.push((1.0 / omega - 1.0).abs());
    }
    for w in period_errors.windows(2) {
        let order = (w[0] / w[1]).log2();
        println!("central difference period order {order:.3}");
        assert!((order - 2.0).abs() < 0.05);
    }
}

#[test]
fn newmark_and_midpoint_periods_follow_the_trapezoidal_dispersion() {
    for scheme in [ImplicitScheme::Newmark, ImplicitScheme::Midpoint] {
        let mut period_errors = Vec::new();
        for dt in [0.4, 0.2, 0.1] {
            let hist = oscillator(Some(scheme), dt, (40.0 / dt) as usize);
            let q = (dt / 2.0) * (dt / 2.0);
            let cos_exact = (1.0 - q) / (1.0 + q);
            let err = dispersion_error(&hist, cos_exact);
            let omega = 2.0 * (dt / 2.0f64).atan() / dt;
            println!(
                "{scheme:?} dt {dt}: dispersion error {err:.2e}, period error {:.4e}",
                1.0 / omega - 1.0
            );
            assert!(err < 1e-10);
            // Amplitude is conserved (no numerical damping).
            let amp = hist.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            assert!((amp - 1.0).abs() < 1e-9);
            period_errors.push((1.0 / omega - 1.0).abs());
        }
        for w in period_errors.windows(2) {
            let order = (w[0] / w[1]).log2();
            println!("{scheme:?} period order {order:.3}");
            assert!((order - 2.0).abs() < 0.1);
        }
    }
}

#[test]
fn displacement_error_of_every_integrator_has_observed_order_two() {
    for scheme in [None, Some(ImplicitScheme::Newmark), Some(ImplicitScheme::Midpoint)] {
        let mut errs = Vec::new();
        for dt in [0.1, 0.05, 0.025] {
            let steps = (10.0 / dt) as usize;
            let hist = oscillator(scheme, dt, steps);
            errs.push((hist[steps] - (steps as f64 * dt).cos()).abs());
        }
        let orders: Vec<f64> = errs.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
        println!(
            "{scheme:?}: errors {:?}, orders {orders:.3?}",
            errs.iter().map(|e| format!("{e:.3e}")).collect::<Vec<_>>()
        );
        assert!(orders.iter().all(|p| (p - 2.0).abs() < 0.1));
    }
}

#[test]
fn implicit_midpoint_conserves_energy_of_a_linear_chain_to_the_newton_tolerance() {
    let mut m = Chain::new(12, 2.0, 50.0, 10.0);
    for i in 0..12 {
        m.u[6 * i] = 0.1 * ((i * 37 % 11) as f64 - 5.0) / 5.0;
    }
    m.commit();
    let v0: Vec<f64> =
        (0..72).map(|d| if d % 6 == 0 { ((d * 13 % 7) as f64 - 3.0) * 0.2 } else { 0.0 }).collect();
    let mut im = Implicit::new(&mut m, ImplicitScheme::Midpoint, 0.0, v0, None);
    im.params.tol = 1e-12;
    let e0 = m.energy() + kinetic_energy(&m, &im.state.v);
    let mut worst: f64 = 0.0;
    let mut its = 0;
    for _ in 0..2000 {
        let info = im.step(&mut m, 0.05, None).unwrap();
        its = its.max(info.iterations);
        let e = m.energy() + kinetic_energy(&m, &im.state.v);
        worst = worst.max((e - e0).abs() / e0);
    }
    println!("midpoint, linear chain, 2000 steps: max relative energy error {worst:.2e}, Newton iterations <= {its}");
    assert!(worst < 1e-10);
    // Nonlinear springs: Newton converges in a few iterations.
    m.k3 = 5e3;
    let mut max_its = 0;
    for _ in 0..200 {
        max_its = max_its.max(im.step(&mut m, 0.05, None).unwrap().iterations);
    }
    println!("midpoint, cubic springs: Newton iterations <= {max_its}");
    assert!(max_its <= 8);
}

#[test]
fn central_difference_is_stable_below_the_estimated_critical_step_and_not_above() {
    let n = 10;
    let mut m = Chain::new(n, 1.0, 100.0, 100.0);
    // Ground spring k at node 0 and n springs: a fixed-free chain of n masses,
    // ω_j = 2 sqrt(k/m) sin((2j-1)π / (2(2n+1))).
    let w_max =
        20.0 * ((2 * n - 1) as f64 * std::f64::consts::PI / (2.0 * (2 * n + 1) as f64)).sin();
    let exact = 2.0 / w_max;
    let est = critical_dt(&mut m, 0.0, 400, 1e-6);
    println!(
        "critical step: exact {exact:.6e}, power {:.6e}, Gershgorin {:.6e}, element {:.6e}",
        est.power, est.gershgorin, est.element
    );
    assert!(est.gershgorin <= exact && est.element <= exact);
    assert!((est.power - exact).abs() / exact < 0.01);
    let run = |dt: f64, steps: usize| {
        let mut m = Chain::new(n, 1.0, 100.0, 100.0);
        for i in 0..n {
            m.u[6 * i] = if i % 2 == 0 { 1e-3 } else { -1e-3 };
        }
        m.commit();
        let mut cd = CentralDifference::new(&mut m, 0.0, vec![0.0; 6 * n], None);
        for _ in 0..steps {
            cd.step(&mut m, dt, None);
        }
        m.u.iter().fold(0.0f64, |a, v| a.max(v.abs()))
    };
    let (below, above) = (run(0.99 * exact, 5000), run(1.01 * exact, 200));
    println!("max |u| after 5000 steps at 0.99 Δt_cr: {below:.3e}; after 200 steps at 1.01 Δt_cr: {above:.3e}");
    assert!(below < 1e-2 && above > 1.0 && above.is_finite());
}
