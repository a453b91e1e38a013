//! The structure side of the staggered schemes CSS, C0 and A6 (DESIGN §4, thesis §3.2 after
//! Farhat, van der Zee and Geuzaine, CMAME 2006), as functions over slices of generalized
//! coordinates, and `Staggered`, the state that answers the structure's commands of the
//! coupling sequence (START, PREDICT, CORRECT). Solvers supply their dynamics through `Dynamics`.
//!
//! Notation: `u`, `v`, `a` displacement, velocity, acceleration; `f` the fluid load; `dt` the
//! coupling step of the step being taken (the last one is shortened).

use crate::case::Scheme;

/// α0 and α1 of the C0 position predictor (third order).
pub const C0_ALPHA0: f64 = 0.5;
pub const C0_ALPHA1: f64 = 0.375;

/// `out = v + h a` (central-difference half kick, e.g. v^{n+1/2} = v^n + Δt/2 a^n).
pub fn kick(v: &[f64], a: &[f64], h: f64, out: &mut [f64]) {
    for ((o, v), a) in out.iter_mut().zip(v).zip(a) {
        *o = v + h * a;
    }
}

/// `out = u + h v` (central-difference drift, u^{n+1} = u^n + Δt v^{n+1/2}).
pub fn drift(u: &[f64], v: &[f64], h: f64, out: &mut [f64]) {
    kick(u, v, h, out);
}

/// C0 start: the state predicted for t^{1/2}, u^0 + Δt/2 v^0 + Δt²/8 a^0 and v^0 + Δt/2 a^0.
pub fn c0_start_prediction(
    u: &[f64],
    v: &[f64],
    a: &[f64],
    dt: f64,
    up: &mut [f64],
    vp: &mut [f64],
) {
    for i in 0..u.len() {
        up[i] = u[i] + 0.5 * dt * v[i] + dt * dt / 8.0 * a[i];
        vp[i] = v[i] + 0.5 * dt * a[i];
    }
}

/// C0 predictor for t^{n+3/2}: u^P = u^{n+1} + Δt(α0+α1) v^{n+1/2} - Δt α1 v^{n-1/2},
/// v^P = 2 v^{n+1/2} - v^{n-1/2}.
pub fn c0_prediction(
    u_next: &[f64],
    v_half: &[f64],
    v_half_prev: &[f64],
    dt: f64,
    up: &mut [f64],
    vp: &mut [f64],
) {
    for i in 0..u_next.len() {
        up[i] =
            u_next[i] + dt * (C0_ALPHA0 + C0_ALPHA1) * v_half[i] - dt * C0_ALPHA1 * v_half_prev[i];
        vp[i] = 2.0 * v_half[i] - v_half_prev[i];
    }
}

/// C0 load at t^{n+1}: F^{n+1} = (F^{n+1/2} + F^{n+3/2}) / 2.
pub fn c0_load_average(f_before: &[f64], f_after: &[f64], out: &mut [f64]) {
    for ((o, a), b) in out.iter_mut().zip(f_before).zip(f_after) {
        *o = 0.5 * (a + b);
    }
}

/// A6 predictor for t^{n+1/2}: u^P = u^n + Δt/2 v^n, v^P = v^n + Δt/2 â^n.
pub fn a6_prediction(u: &[f64], v: &[f64], a_hat: &[f64], dt: f64, up: &mut [f64], vp: &mut [f64]) {
    drift(u, v, 0.5 * dt, up);
    kick(v, a_hat, 0.5 * dt, vp);
}

/// A6 acceleration estimate â^n = (v^n - v^{n-1}) / Δt.
pub fn a6_acceleration_estimate(v: &[f64], v_prev: &[f64], dt: f64, out: &mut [f64]) {
    for ((o, v), p) in out.iter_mut().zip(v).zip(v_prev) {
        *o = (v - p) / dt;
    }
}

/// The structure's equations of motion M a = f - f_int(u, v), as the schemes need them.
pub trait Dynamics {
    /// Explicit central difference: the `a` that solves M a = f - f_int(u, v_half + h a) (h = Δt/2
    /// after a step, 0 at the start where `v_half` is v^0).
    fn acceleration(&self, f: &[f64], u: &[f64], v_half: &[f64], h: f64, a: &mut [f64]);
    /// One implicit midpoint step with the load `f` over the step: u^{n+1} = u^n + Δt/2 (v^n +
    /// v^{n+1}), M (v^{n+1} - v^n) = Δt (f - f_int((u^n+u^{n+1})/2, (v^n+v^{n+1})/2)), in place.
    fn implicit_midpoint(&self, f: &[f64], dt: f64, u: &mut [f64], v: &mut [f64]);
}

/// Uncoupled linear oscillators m_i a_i + c_i v_i + k_i u_i = f_i (a rigid body in principal axes).
#[derive(Debug, Clone, PartialEq)]
pub struct Diagonal {
    pub m: Vec<f64>,
    pub k: Vec<f64>,
    pub c: Vec<f64>,
}

impl Dynamics for Diagonal {
    fn acceleration(&self, f: &[f64], u: &[f64], v_half: &[f64], h: f64, a: &mut [f64]) {
        for i in 0..a.len() {
            // m a = f - k u - c (v_half + h a)
            a[i] = (f[i] - self.k[i] * u[i] - self.c[i] * v_half[i]) / (self.m[i] + self.c[i] * h);
        }
    }

    fn implicit_midpoint(&self, f: &[f64], dt: f64, u: &mut [f64], v: &mut [f64]) {
        for i in 0..u.len() {
            let (m, k, c) = (self.m[i], self.k[i], self.c[i]);
            // With s = v^n + v^{n+1}: s (m + Δt² k/4 + Δt c/2) = 2 m v^n + Δt (f - k u^n).
            let s =
                (2.0 * m * v[i] + dt * (f[i] - k * u[i])) / (m + dt * dt * k / 4.0 + dt * c / 2.0);
            u[i] += 0.5 * dt * s;
            v[i] = s - v[i];
        }
    }
}

/// The structure's state through the coupling sequence of one scheme.
#[derive(Debug, Clone)]
pub struct Staggered {
    pub scheme: Scheme,
    pub u: Vec<f64>,
    pub v: Vec<f64>,
    pub a: Vec<f64>,
    /// The kinematics to publish after `start` (C0) or `predict`.
    pub up: Vec<f64>,
    pub vp: Vec<f64>,
    /// C0: v^{n+1/2}, v^{n-1/2}, u^{n+1} (between PREDICT and CORRECT), F^{n+1/2}.
    v_half: Vec<f64>,
    v_half_prev: Vec<f64>,
    u_next: Vec<f64>,
    f_half: Vec<f64>,
    /// A6: â^n, and the scratch load.
    a_hat: Vec<f64>,
    scratch: Vec<f64>,
}

impl Staggered {
    /// The state at t^0.
    pub fn new(scheme: Scheme, u0: &[f64], v0: &[f64]) -> Staggered {
        let z = vec![0.0; u0.len()];
        Staggered {
            scheme,
            u: u0.to_vec(),
            v: v0.to_vec(),
            a: z.clone(),
            up: u0.to_vec(),
            vp: v0.to_vec(),
            v_half: z.clone(),
            v_half_prev: z.clone(),
            u_next: z.clone(),
            f_half: z.clone(),
            a_hat: z.clone(),
            scratch: z,
        }
    }

    /// START with the load F^0: a^0 = M^{-1}(F^0 - f_int(u^0, v^0)). Returns whether `up`/`vp`
    /// hold kinematics to publish (C0: the prediction for t^{1/2}).
    pub fn start(&mut self, dynamics: &impl Dynamics, f0: &[f64], dt: f64) -> bool {
        dynamics.acceleration(f0, &self.u, &self.v, 0.0, &mut self.a);
        self.a_hat.copy_from_slice(&self.a);
        match self.scheme {
            Scheme::C0 => {
                kick(&self.v, &self.a, -0.5 * dt, &mut self.v_half_prev);
                c0_start_prediction(&self.u, &self.v, &self.a, dt, &mut self.up, &mut self.vp);
                true
            }
            Scheme::Css | Scheme::A6 => false,
        }
    }

    /// Whether PREDICT of `step` first consumes a load (C0, step 0: F^{1/2}).
    pub fn predict_reads_load(&self, step: u64) -> bool {
        self.scheme == Scheme::C0 && step == 0
    }

    /// PREDICT of a step of length `dt`: fills `up`/`vp` with the kinematics the fluid's next
    /// advance needs. `load` is F^{1/2} when `predict_reads_load` says so.
    pub fn predict(&mut self, dt: f64, load: Option<&[f64]>) {
        match self.scheme {
            Scheme::Css => {
                self.up.copy_from_slice(&self.u);
                self.vp.copy_from_slice(&self.v);
            }
            Scheme::C0 => {
                if let Some(f) = load {
                    self.f_half.copy_from_slice(f);
                }
                kick(&self.v, &self.a, 0.5 * dt, &mut self.v_half);
                drift(&self.u, &self.v_half, dt, &mut self.u_next);
                c0_prediction(
                    &self.u_next,
                    &self.v_half,
                    &self.v_half_prev,
                    dt,
                    &mut self.up,
                    &mut self.vp,
                );
            }
            Scheme::A6 => {
                a6_prediction(&self.u, &self.v, &self.a_hat, dt, &mut self.up, &mut self.vp)
            }
        }
    }

    /// CORRECT of a step of length `dt` with the load the fluid just returned (CSS: F^{n+1},
    /// C0: F^{n+3/2}, A6: F^{n+1/2}); the state moves to t^{n+1}.
    pub fn correct(&mut self, dynamics: &impl Dynamics, load: &[f64], dt: f64) {
        match self.scheme {
            Scheme::Css => {
                kick(&self.v, &self.a, 0.5 * dt, &mut self.v_half);
                drift(&self.u, &self.v_half, dt, &mut self.u_next);
                self.u.copy_from_slice(&self.u_next);
                dynamics.acceleration(load, &self.u, &self.v_half, 0.5 * dt, &mut self.a);
                kick(&self.v_half, &self.a, 0.5 * dt, &mut self.v);
            }
            Scheme::C0 => {
                c0_load_average(&self.f_half, load, &mut self.scratch);
                self.u.copy_from_slice(&self.u_next);
                dynamics.acceleration(&self.scratch, &self.u, &self.v_half, 0.5 * dt, &mut self.a);
                kick(&self.v_half, &self.a, 0.5 * dt, &mut self.v);
                self.v_half_prev.copy_from_slice(&self.v_half);
                self.f_half.copy_from_slice(load);
            }
            Scheme::A6 => {
                self.scratch.copy_from_slice(&self.v);
                dynamics.implicit_midpoint(load, dt, &mut self.u, &mut self.v);
                a6_acceleration_estimate(&self.v, &self.scratch, dt, &mut self.a_hat);
                self.a.copy_from_slice(&self.a_hat);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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

    /// Runs the coupling sequence (start-up, then PREDICT / fluid / CORRECT) and returns u(T).
    fn run(scheme: Scheme, n: usize) -> f64 {
        let dt = T / n as f64;
        let d = Diagonal { m: vec![M], k: vec![K], c: vec![0.0] };
        let mut s = Staggered::new(scheme, &[U0], &[0.0]);
        let f0 = fluid(s.u[0], s.v[0]); // fluid Init
        let mut pending = None;
        if s.start(&d, &[f0], dt) {
            pending = Some(fluid(s.up[0], s.vp[0])); // C0: fluid's start-up half step
        }
        for step in 0..n {
            let load = if s.predict_reads_load(step as u64) { pending.take() } else { None };
            s.predict(dt, load.as_ref().map(std::slice::from_ref));
            let f = fluid(s.up[0], s.vp[0]);
            s.correct(&d, &[f], dt);
        }
        s.u[0]
    }

    fn observed_order(scheme: Scheme) -> f64 {
        let e: Vec<f64> =
            [100, 200, 400].iter().map(|&n| (run(scheme, n) - exact(T)).abs()).collect();
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
        let d = Diagonal { m: vec![m], k: vec![k], c: vec![c] };
        let exact = |t: f64| {
            let g = c / (2.0 * m);
            let wd = (k / m - g * g).sqrt();
            (-g * t).exp() * ((wd * t).cos() + g / wd * (wd * t).sin())
        };
        for scheme in [Scheme::Css, Scheme::A6] {
            let err = |n: usize| {
                let dt = 3.0 / n as f64;
                let mut s = Staggered::new(scheme, &[1.0], &[0.0]);
                s.start(&d, &[0.0], dt);
                for _ in 0..n {
                    s.predict(dt, None);
                    s.correct(&d, &[0.0], dt);
                }
                (s.u[0] - exact(3.0)).abs()
            };
            let p = (err(200) / err(400)).log2();
            assert!((1.9..2.1).contains(&p), "{scheme:?}: order {p}");
        }
    }
}
