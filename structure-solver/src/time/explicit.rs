//! Explicit central differences (Belytschko, Liu & Moran, *Nonlinear Finite Elements*, Box 6.1):
//! `v^{n+1/2} = v^n + Δt/2 a^n`, `u^{n+1} = u^n + Δt v^{n+1/2}`,
//! `a^{n+1} = M⁻¹ (f_ext^{n+1} - f_int(u^{n+1}))`, `v^{n+1} = v^{n+1/2} + Δt/2 a^{n+1}`.
//!
//! A step is split in [`CentralDifference::advance_positions`] and
//! [`CentralDifference::complete`] so that a coupled run (C0) can publish the predicted wet
//! surface between them. Stable for `Δt <= 2/ω_max`; its discrete frequency obeys
//! `cos ΩΔt = 1 - (ωΔt)²/2`.
//!
//! The kicks use the model's inverse mass (`Model::apply_inverse_mass`: rigid masters solve
//! their 6x6 block) and the drift lets the model move dofs whose motion is not `Δt v`
//! (`Model::explicit_drift`: the free flow of rigid bodies, Euler's equations included);
//! dependent (rigid slave) velocities and accelerations follow their masters
//! (`Model::dependent_motion`) at every full step.

use super::{out_of_balance, prescribed_increment, Dynamics};
use crate::model::Model;

/// Central-difference integrator with its work arrays (no allocation per step).
#[derive(Debug, Clone)]
pub struct CentralDifference {
    pub state: Dynamics,
    /// Velocity at the last half step, `v^{n+1/2}` after `advance_positions`.
    pub v_half: Vec<f64>,
    fi: Vec<f64>,
    r: Vec<f64>,
    du: Vec<f64>,
    scratch: Vec<f64>,
}

impl CentralDifference {
    /// Starts at `t0` with velocity `v0`; `a^0` from the out-of-balance force (with `extra`).
    pub fn new(model: &mut dyn Model, t0: f64, v0: Vec<f64>, extra: Option<&[f64]>) -> Self {
        let n = model.n_dof();
        assert_eq!(v0.len(), n, "initial velocity has the wrong length");
        let mut cd = CentralDifference {
            state: Dynamics { t: t0, v: v0, a: vec![0.0; n] },
            v_half: vec![0.0; n],
            fi: vec![0.0; n],
            r: vec![0.0; n],
            du: vec![0.0; n],
            scratch: vec![0.0; n],
        };
        cd.update_acceleration(model, t0, extra);
        model.dependent_motion(&mut cd.state.v, &mut cd.state.a);
        cd
    }

    /// Resumes from a checkpointed state.
    pub fn resume(model: &dyn Model, state: Dynamics) -> Self {
        let n = model.n_dof();
        CentralDifference {
            state,
            v_half: vec![0.0; n],
            fi: vec![0.0; n],
            r: vec![0.0; n],
            du: vec![0.0; n],
            scratch: vec![0.0; n],
        }
    }

    /// Follows a change of `model`'s topology made after the last step, nodes appended
    /// whose velocity `state` holds already (`Dynamics::push_nodes`, `Dynamics::copy_nodes`):
    /// the work arrays grow to the model's dofs and the new dofs take the acceleration of the
    /// changed model at the current time (with `extra`); the others keep theirs.
    pub fn follow_topology(
        &mut self,
        model: &mut dyn Model,
        extra: Option<&[f64]>,
    ) -> Result<(), super::ResizeError> {
        let n = self.state.fits(model)?;
        let first = self.fi.len();
        for w in [&mut self.v_half, &mut self.fi, &mut self.r, &mut self.du, &mut self.scratch] {
            w.resize(n, 0.0);
        }
        let work = [&mut self.fi[..], &mut self.r[..], &mut self.scratch[..]];
        super::added_accelerations(model, (self.state.t, extra), first, work, &mut self.state.a);
        Ok(())
    }

    fn update_acceleration(&mut self, model: &mut dyn Model, t: f64, extra: Option<&[f64]>) {
        out_of_balance(model, t, extra, &mut self.fi, &mut self.r);
        model.apply_inverse_mass(&self.r, &mut self.state.a);
    }

    /// First half of a step: `v^{n+1/2}` and `u^{n+1}` (prescribed dofs follow their history).
    pub fn advance_positions(&mut self, model: &mut dyn Model, dt: f64) {
        let t = self.state.t;
        prescribed_increment(model, t, dt, &mut self.scratch, &mut self.du);
        let constrained = model.constrained();
        for i in 0..self.du.len() {
            if constrained[i] {
                self.v_half[i] = self.du[i] / dt;
            } else {
                self.v_half[i] = self.state.v[i] + 0.5 * dt * self.state.a[i];
                self.du[i] = dt * self.v_half[i];
            }
        }
        model.explicit_drift(dt, &mut self.v_half, &mut self.du);
        model.apply_increment(&self.du);
    }

    /// Second half: `a^{n+1}` from the forces at `u^{n+1}` (with `extra`), `v^{n+1}`; commits.
    pub fn complete(&mut self, model: &mut dyn Model, dt: f64, extra: Option<&[f64]>) {
        let t1 = self.state.t + dt;
        self.update_acceleration(model, t1, extra);
        for ((v, vh), a) in self.state.v.iter_mut().zip(&self.v_half).zip(&self.state.a) {
            *v = vh + 0.5 * dt * a;
        }
        model.dependent_motion(&mut self.state.v, &mut self.state.a);
        model.commit();
        self.state.t = t1;
    }

    /// One full step.
    pub fn step(&mut self, model: &mut dyn Model, dt: f64, extra: Option<&[f64]>) {
        self.advance_positions(model, dt);
        self.complete(model, dt, extra);
    }

    /// Internal force at the last completed step.
    pub fn internal_force(&self) -> &[f64] {
        &self.fi
    }
}
