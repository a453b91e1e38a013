//! [`Staggered`]: the scheme's state through the coupling sequence, with its energy ledger.

use super::{
    a6_acceleration_estimate, a6_prediction, c0_load_average, c0_prediction, c0_start_prediction,
    kick, load_between, load_line, Dynamics,
};
use crate::case::Scheme;

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
