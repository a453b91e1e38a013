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

/// The scheme's own state through the coupling sequence (the structure's state is the
/// [`Dynamics`]'): the one implementation of CSS, C0 and A6 every structure participant uses.
///
/// **Subcycling.** With central differences (CSS, C0) the structure takes `m` equal substeps
/// `h = Δt/m` inside a coupling step, `m` fixed by the case or the least with `h` within the
/// stable step ([`Staggered::set_stable_step`]); `m = 1` is the plain scheme, bitwise.
/// - CSS (at CORRECT, F^{n+1} known): substep `k` ends with the load
///   `(1 - k/m) F^n + (k/m) F^{n+1}`.
/// - C0: u^{n+1} is needed at PREDICT, before F^{n+3/2} exists, so the first `m - 1` substeps
///   and the drift of the last run at PREDICT with the load extrapolated linearly through the
///   last two samples, `F(t) = F^{n+1/2} + (t - t^{n+1/2}) (F^{n+1/2} - F^{n-1/2}) / (t^{n+1/2} -
///   t^{n-1/2})` (step 0: through F^0 and F^{1/2}), an O(Δt²) error in the load. CORRECT
///   completes the last substep with C0's `F^{n+1} = (F^{n+1/2} + F^{n+3/2})/2`. The predictor's
///   `v^{n+1/2}` is the velocity at the step's midpoint: the middle substep's half-step velocity
///   (`m` odd) or the velocity after substep `m/2` (`m` even).
/// - A6 integrates with the implicit midpoint rule, unconditionally stable: one step.
///
/// **Energy ledger.** [`Staggered::interface_work`] is the work of the loads the structure
/// applied along its own displacement since t = 0 ([`Ledger`]), the structure's half of the
/// interface energy balance (PROTOCOL.md §3, `interface_work`).
#[derive(Debug, Clone)]
pub struct Staggered {
    pub scheme: Scheme,
    /// The kinematics to publish after `start` (C0) or `predict`.
    pub up: Vec<f64>,
    pub vp: Vec<f64>,
    /// C0: v^{n-1/2} and F^{n+1/2} (at `t_half`); A6: â^n.
    v_half_prev: Vec<f64>,
    f_half: Vec<f64>,
    t_half: f64,
    a_hat: Vec<f64>,
    /// The load sample before: CSS F^n; C0 F^{n-1/2} (at `t_prev`; F^0 at step 0).
    f_prev: Vec<f64>,
    t_prev: f64,
    /// C0: the velocity at the step's midpoint, from PREDICT.
    v_mid: Vec<f64>,
    /// Displacements and loads in passing; v^n before an A6 step.
    scratch: Vec<f64>,
    /// t^n.
    t: f64,
    /// The structure's stable step, and the substeps of the step under way (C0).
    stable_step: f64,
    fixed_substeps: Option<u32>,
    substeps: usize,
    ledger: Ledger,
}

/// The work of the applied load on the structure's displacement, step by step: a central-
/// difference substep from u^k to u^{k+1}, whose loads are F^k (the previous substep's, F^0 at
/// START) and F^{k+1}, adds `(F^k + F^{k+1})/2 · (u^{k+1} - u^k)` (the trapezoidal rule, with
/// which the scheme's discrete energy balances); an implicit midpoint step with F held adds
/// `F · (u^{n+1} - u^n)`.
#[derive(Debug, Clone)]
struct Ledger {
    /// The load of the last completed substep.
    f_applied: Vec<f64>,
    /// The displacement at the start of the substep under way, and at its end.
    u_before: Vec<f64>,
    u_after: Vec<f64>,
    work: f64,
}

impl Ledger {
    fn new(n: usize) -> Ledger {
        Ledger { f_applied: vec![0.0; n], u_before: vec![0.0; n], u_after: vec![0.0; n], work: 0.0 }
    }

    /// A substep begins from the current configuration.
    fn begin<D: Dynamics>(&mut self, d: &D) {
        d.displacement(&mut self.u_before);
    }

    /// The substep that [`Ledger::begin`] opened ended with the load `f`; `held`: the load was
    /// held over it (implicit midpoint) rather than applied at its end.
    fn end<D: Dynamics>(&mut self, d: &D, f: &[f64], held: bool) {
        d.displacement(&mut self.u_after);
        let (before, after, applied) = (&self.u_before, &self.u_after, &self.f_applied);
        self.work += (0..f.len())
            .map(|i| {
                let load = if held { f[i] } else { 0.5 * (applied[i] + f[i]) };
                load * (after[i] - before[i])
            })
            .sum::<f64>();
        self.f_applied.copy_from_slice(f);
    }
}

impl Staggered {
    /// The scheme's state for `n` generalized coordinates, before START.
    pub fn new(scheme: Scheme, n: usize) -> Staggered {
        let z = vec![0.0; n];
        Staggered {
            scheme,
            up: z.clone(),
            vp: z.clone(),
            v_half_prev: z.clone(),
            f_half: z.clone(),
            t_half: 0.0,
            a_hat: z.clone(),
            f_prev: z.clone(),
            t_prev: 0.0,
            v_mid: z.clone(),
            scratch: z,
            t: 0.0,
            stable_step: f64::INFINITY,
            fixed_substeps: None,
            substeps: 1,
            ledger: Ledger::new(n),
        }
    }

    /// The work of the applied loads on the structure's displacement from t = 0 ([`Ledger`]).
    pub fn interface_work(&self) -> f64 {
        self.ledger.work
    }

    /// A fixed number of central-difference substeps per coupling step (`None`: the least that
    /// keeps each within the stable step).
    pub fn with_substeps(mut self, substeps: Option<u32>) -> Staggered {
        self.fixed_substeps = substeps;
        self
    }

    /// The structure's stable step for the steps to come (infinite: no limit).
    pub fn set_stable_step(&mut self, stable_step: f64) {
        self.stable_step = stable_step;
    }

    /// The substeps of central differences in a coupling step of length `dt` (A6: 1).
    pub fn substeps(&self, dt: f64) -> usize {
        if self.scheme == Scheme::A6 {
            return 1;
        }
        match self.fixed_substeps {
            Some(m) => m.max(1) as usize,
            None if self.stable_step.is_finite() && self.stable_step > 0.0 => {
                (dt / self.stable_step * (1.0 - 1e-12)).ceil().max(1.0) as usize
            }
            None => 1,
        }
    }

    /// The scheme's history a checkpoint must keep, named: C0's `F^{n+1/2}` and `v^{n-1/2}`,
    /// A6's `â^n`, the load sample before (CSS F^n, C0 F^{n-1/2}), the times `[t^n,
    /// t_prev, t_half]` of the samples, and the ledger's last applied load and work.
    /// [`Staggered::restore`] reads it back.
    pub fn history(&self) -> [(&'static str, Vec<f64>); 7] {
        [
            ("f_half", self.f_half.clone()),
            ("v_half_prev", self.v_half_prev.clone()),
            ("a_hat", self.a_hat.clone()),
            ("f_prev", self.f_prev.clone()),
            ("times", vec![self.t, self.t_prev, self.t_half]),
            ("f_applied", self.ledger.f_applied.clone()),
            ("work", vec![self.ledger.work]),
        ]
    }

    /// Restores the [`Staggered::history`] that `get` returns by name, after CORRECT of the
    /// step the checkpoint closed: the sequence continues with PREDICT bitwise as if never
    /// stopped. An error names the missing or mis-sized entry.
    pub fn restore(&mut self, mut get: impl FnMut(&str) -> Option<Vec<f64>>) -> Result<(), String> {
        let n = self.f_half.len();
        let mut take = |name: &str, len: usize| match get(name) {
            Some(v) if v.len() == len => Ok(v),
            Some(v) => {
                Err(format!("coupling history `{name}` holds {} values, expected {len}", v.len()))
            }
            None => Err(format!("coupling history `{name}` is missing")),
        };
        self.f_half = take("f_half", n)?;
        self.v_half_prev = take("v_half_prev", n)?;
        self.a_hat = take("a_hat", n)?;
        self.f_prev = take("f_prev", n)?;
        let times = take("times", 3)?;
        (self.t, self.t_prev, self.t_half) = (times[0], times[1], times[2]);
        self.ledger.f_applied = take("f_applied", n)?;
        self.ledger.work = take("work", 1)?[0];
        Ok(())
    }

    /// START with the load F^0 (a^0 = M^{-1}(F^0 - f_int(u^0, v^0))). Returns whether `up`/`vp`
    /// hold kinematics to publish (C0: the prediction for t^{1/2}).
    pub fn start<D: Dynamics>(&mut self, d: &mut D, f0: &[f64], dt: f64) -> Result<bool, D::Error> {
        d.start(f0)?;
        self.a_hat.copy_from_slice(d.acceleration());
        self.f_prev.copy_from_slice(f0);
        self.ledger.f_applied.copy_from_slice(f0);
        self.t_prev = self.t;
        Ok(match self.scheme {
            Scheme::C0 => {
                kick(d.velocity(), d.acceleration(), -0.5 * dt, &mut self.v_half_prev);
                d.displacement(&mut self.scratch);
                let (v, a) = (d.velocity(), d.acceleration());
                c0_start_prediction(&self.scratch, v, a, dt, &mut self.up, &mut self.vp);
                true
            }
            Scheme::Css | Scheme::A6 => false,
        })
    }

    /// Whether PREDICT of `step` first consumes a load (C0, step 0: F^{1/2}).
    pub fn predict_reads_load(&self, step: u64) -> bool {
        self.scheme == Scheme::C0 && step == 0
    }

    /// The time PREDICT of the step `[t_from, t_from + dt]` publishes kinematics for (CSS: the
    /// held state t^n; C0: t^{n+3/2}; A6: t^{n+1/2}).
    pub fn predicted_time(&self, t_from: f64, dt: f64) -> f64 {
        match self.scheme {
            Scheme::Css => t_from,
            Scheme::C0 => t_from + 1.5 * dt,
            Scheme::A6 => t_from + 0.5 * dt,
        }
    }

    /// PREDICT of a step of length `dt`: fills `up`/`vp` with the kinematics the fluid's next
    /// advance needs (C0 first drifts the structure to u^{n+1}, substeps included). `load` is
    /// F^{1/2} when `predict_reads_load` says so.
    pub fn predict<D: Dynamics>(
        &mut self,
        d: &mut D,
        dt: f64,
        load: Option<&[f64]>,
    ) -> Result<(), D::Error> {
        match self.scheme {
            Scheme::Css => {
                d.displacement(&mut self.up);
                self.vp.copy_from_slice(d.velocity());
            }
            Scheme::C0 => {
                if let Some(f) = load {
                    self.f_half.copy_from_slice(f);
                    self.t_half = self.t + 0.5 * dt;
                }
                self.c0_drift(d, dt)?;
                d.displacement(&mut self.scratch);
                let (vh, vh_prev) = (&self.v_mid, &self.v_half_prev);
                c0_prediction(&self.scratch, vh, vh_prev, dt, &mut self.up, &mut self.vp);
            }
            Scheme::A6 => {
                d.displacement(&mut self.scratch);
                let v = d.velocity();
                a6_prediction(&self.scratch, v, &self.a_hat, dt, &mut self.up, &mut self.vp)
            }
        }
        Ok(())
    }

    /// C0 at PREDICT: the substeps to u^{n+1} but the last one's second half, with the
    /// extrapolated load (type docs); keeps the midpoint velocity in `v_mid`.
    fn c0_drift<D: Dynamics>(&mut self, d: &mut D, dt: f64) -> Result<(), D::Error> {
        let m = self.substeps(dt);
        self.substeps = m;
        let h = dt / m as f64;
        for k in 1..=m {
            self.ledger.begin(d);
            d.advance_positions(h);
            if 2 * k - 1 == m {
                self.v_mid.copy_from_slice(d.half_velocity());
            }
            if k == m {
                break;
            }
            let tk = self.t + k as f64 * h;
            load_line(self.t_prev, &self.f_prev, self.t_half, &self.f_half, tk, &mut self.scratch);
            d.complete(&self.scratch, h)?;
            self.ledger.end(d, &self.scratch, false);
            if 2 * k == m {
                self.v_mid.copy_from_slice(d.velocity());
            }
        }
        Ok(())
    }

    /// CORRECT of a step of length `dt` with the load the fluid just returned (CSS: F^{n+1},
    /// C0: F^{n+3/2}, A6: F^{n+1/2}); the structure moves to t^{n+1}.
    pub fn correct<D: Dynamics>(
        &mut self,
        d: &mut D,
        load: &[f64],
        dt: f64,
    ) -> Result<(), D::Error> {
        match self.scheme {
            Scheme::Css => {
                let m = self.substeps(dt);
                let h = dt / m as f64;
                for k in 1..=m {
                    self.ledger.begin(d);
                    d.advance_positions(h);
                    load_between(&self.f_prev, load, k as f64 / m as f64, &mut self.scratch);
                    d.complete(&self.scratch, h)?;
                    self.ledger.end(d, &self.scratch, false);
                }
                self.f_prev.copy_from_slice(load);
            }
            Scheme::C0 => {
                c0_load_average(&self.f_half, load, &mut self.scratch);
                d.complete(&self.scratch, dt / self.substeps as f64)?;
                self.ledger.end(d, &self.scratch, false);
                self.v_half_prev.copy_from_slice(&self.v_mid);
                self.f_prev.copy_from_slice(&self.f_half);
                self.t_prev = self.t_half;
                self.f_half.copy_from_slice(load);
                self.t_half = self.t + 1.5 * dt;
            }
            Scheme::A6 => {
                self.scratch.copy_from_slice(d.velocity());
                self.ledger.begin(d);
                d.implicit_midpoint(load, dt)?;
                self.ledger.end(d, load, true);
                a6_acceleration_estimate(d.velocity(), &self.scratch, dt, &mut self.a_hat);
            }
        }
        self.t += dt;
        Ok(())
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
                    .restore(|name| {
                        history.iter().find(|(k, _)| *k == name).map(|(_, v)| v.clone())
                    })
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
                    s.predict(&mut d, dt, (s.predict_reads_load(step)).then_some(&[f][..]))
                        .unwrap();
                    s.correct(&mut d, &[f], dt).unwrap();
                }
                let (w, u, v) = (s.interface_work(), d.u[0], d.v[0]);
                assert!(
                    (w - f * u).abs() < 1e-13 * w,
                    "{scheme:?}/{substeps}: {w} vs F u {}",
                    f * u
                );
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
        assert!(
            plain.is_nan() || plain > 1e10,
            "central differences stable without substeps: {plain}"
        );
        // Free vibration from u = 1 at rest: central differences keep |u| <= 1, and 200 steps of
        // a period near 4 coupling steps come within a few percent of the peak.
        let peak = run(true);
        assert!((0.95..=1.0 + 1e-12).contains(&peak), "peak {peak}");
    }
}
