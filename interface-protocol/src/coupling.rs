//! The structure side of the staggered schemes CSS, C0 and A6 (DESIGN §4, thesis §3.2 after
//! Farhat, van der Zee and Geuzaine, CMAME 2006), as functions over slices of generalized
//! coordinates, and `Staggered`, the state that answers the structure's commands of the
//! coupling sequence (START, PREDICT, CORRECT). Solvers supply their dynamics through `Dynamics`.
//!
//! Notation: `u`, `v`, `a` displacement, velocity, acceleration; `f` the fluid load; `dt` the
//! coupling step of the step being taken (the last one is shortened).

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

/// The structure's equations of motion M a = f - f_int(u, v), stepped the ways the schemes need.
/// The implementor owns the state: u, v, a and whatever history its internal force depends on
/// (rotations, plastic strains), so a nonlinear finite-element model and a linear oscillator go
/// through the same sequence ([`Staggered`]).
pub trait Dynamics {
    type Error;
    /// The generalized displacement u of the current configuration, into `out`.
    fn displacement(&self, out: &mut [f64]);
    /// The velocity v^n.
    fn velocity(&self) -> &[f64];
    /// The acceleration a^n.
    fn acceleration(&self) -> &[f64];
    /// v^{n+1/2}, after [`Dynamics::advance_positions`].
    fn half_velocity(&self) -> &[f64];
    /// START: a^0 = M^{-1}(f0 - f_int(u^0, v^0)).
    fn start(&mut self, f0: &[f64]) -> Result<(), Self::Error>;
    /// Central differences, first half: v^{n+1/2} = v^n + Δt/2 a^n, u^{n+1} = u^n + Δt v^{n+1/2}.
    fn advance_positions(&mut self, dt: f64);
    /// Central differences, second half with the load `f` at t^{n+1}: a^{n+1} solves
    /// M a = f - f_int(u^{n+1}, v^{n+1/2} + Δt/2 a), v^{n+1} = v^{n+1/2} + Δt/2 a^{n+1}.
    fn complete(&mut self, f: &[f64], dt: f64) -> Result<(), Self::Error>;
    /// One implicit midpoint step with the load `f` held over the step: u^{n+1} = u^n + Δt/2
    /// (v^n + v^{n+1}), M (v^{n+1} - v^n) = Δt (f - f_int((u^n+u^{n+1})/2, (v^n+v^{n+1})/2)).
    fn implicit_midpoint(&mut self, f: &[f64], dt: f64) -> Result<(), Self::Error>;
}

/// Uncoupled linear oscillators m_i a_i + c_i v_i + k_i u_i = f_i (a rigid body in principal axes).
#[derive(Debug, Clone, PartialEq)]
pub struct Diagonal {
    pub m: Vec<f64>,
    pub k: Vec<f64>,
    pub c: Vec<f64>,
}

impl Diagonal {
    /// The `a` that solves m a = f - k u - c (v_half + h a).
    fn acceleration(&self, f: &[f64], u: &[f64], v_half: &[f64], h: f64, a: &mut [f64]) {
        for i in 0..a.len() {
            a[i] = (f[i] - self.k[i] * u[i] - self.c[i] * v_half[i]) / (self.m[i] + self.c[i] * h);
        }
    }
}

/// [`Diagonal`] oscillators with their state.
#[derive(Debug, Clone, PartialEq)]
pub struct Oscillators {
    pub params: Diagonal,
    pub u: Vec<f64>,
    pub v: Vec<f64>,
    pub a: Vec<f64>,
    pub v_half: Vec<f64>,
}

impl Oscillators {
    /// At rest in `u0`, `v0` (a^0 comes with START).
    pub fn new(params: Diagonal, u0: &[f64], v0: &[f64]) -> Oscillators {
        let z = vec![0.0; u0.len()];
        Oscillators { params, u: u0.to_vec(), v: v0.to_vec(), a: z.clone(), v_half: z }
    }
}

impl Dynamics for Oscillators {
    type Error = std::convert::Infallible;

    fn displacement(&self, out: &mut [f64]) {
        out.copy_from_slice(&self.u);
    }

    fn velocity(&self) -> &[f64] {
        &self.v
    }

    fn acceleration(&self) -> &[f64] {
        &self.a
    }

    fn half_velocity(&self) -> &[f64] {
        &self.v_half
    }

    fn start(&mut self, f0: &[f64]) -> Result<(), Self::Error> {
        self.params.acceleration(f0, &self.u, &self.v, 0.0, &mut self.a);
        Ok(())
    }

    fn advance_positions(&mut self, dt: f64) {
        kick(&self.v, &self.a, 0.5 * dt, &mut self.v_half);
        for (u, vh) in self.u.iter_mut().zip(&self.v_half) {
            *u += dt * vh;
        }
    }

    fn complete(&mut self, f: &[f64], dt: f64) -> Result<(), Self::Error> {
        self.params.acceleration(f, &self.u, &self.v_half, 0.5 * dt, &mut self.a);
        kick(&self.v_half, &self.a, 0.5 * dt, &mut self.v);
        Ok(())
    }

    fn implicit_midpoint(&mut self, f: &[f64], dt: f64) -> Result<(), Self::Error> {
        let Diagonal { m, k, c } = &self.params;
        for i in 0..self.u.len() {
            let (m, k, c) = (m[i], k[i], c[i]);
            let v0 = self.v[i];
            // With s = v^n + v^{n+1}: s (m + Δt² k/4 + Δt c/2) = 2 m v^n + Δt (f - k u^n).
            let s = (2.0 * m * v0 + dt * (f[i] - k * self.u[i]))
                / (m + dt * dt * k / 4.0 + dt * c / 2.0);
            self.u[i] += 0.5 * dt * s;
            self.v[i] = s - v0;
            self.a[i] = (self.v[i] - v0) / dt;
        }
        Ok(())
    }
}

/// Linear extrapolation (or interpolation) of a load through the samples `(ta, fa)`, `(tb, fb)`
/// to `t`: `out = fb + (t - tb)/(tb - ta) (fb - fa)`.
pub fn load_line(ta: f64, fa: &[f64], tb: f64, fb: &[f64], t: f64, out: &mut [f64]) {
    let s = (t - tb) / (tb - ta);
    for ((o, a), b) in out.iter_mut().zip(fa).zip(fb) {
        *o = b + s * (b - a);
    }
}

/// CSS substep load at the fraction `s` of the step: `out = (1 - s) F^n + s F^{n+1}` (exactly
/// `F^{n+1}` at `s = 1`).
pub fn load_between(f_from: &[f64], f_to: &[f64], s: f64, out: &mut [f64]) {
    for ((o, a), b) in out.iter_mut().zip(f_from).zip(f_to) {
        *o = (1.0 - s) * a + s * b;
    }
}

mod staggered;
pub use staggered::Staggered;

#[cfg(test)]
mod tests;
