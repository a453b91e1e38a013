//! Time integration of a [`Model`](crate::model::Model) (DESIGN §6): explicit central
//! differences with a critical step estimated from the model, and implicit Newmark (average
//! acceleration) and implicit midpoint with Newton and a sparse direct solve.
//!
//! The integrators own velocities and accelerations per dof; the model owns the configuration
//! (rotations composed, material and hourglass state), so a checkpoint of a run is the model's
//! state plus [`Dynamics`].
//!
//! Loads received over the coupling interface enter every step as an extra nodal force vector
//! (`extra`) that the model reduces with its own external forces (`Model::external_force_with`).

pub mod critical;
pub mod explicit;
pub mod implicit;

pub use critical::{critical_dt, CriticalDt, StableStep};
pub use explicit::CentralDifference;

pub use implicit::{Implicit, ImplicitError, ImplicitScheme, NewtonParams, StepInfo};

use crate::model::Model;

/// Time, velocity and acceleration per dof: the integrator's part of a checkpoint.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Dynamics {
    pub t: f64,
    pub v: Vec<f64>,
    pub a: Vec<f64>,
}

/// The integrator's dofs cannot follow a change of its model's topology.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ResizeError {
    #[error("{what}: {got} values, expected 6 per added node ({expected})")]
    Length { what: &'static str, got: usize, expected: usize },
    #[error("node {node} to copy the motion of is past the {n} nodes of the integrator")]
    Source { node: usize, n: usize },
    #[error("the model has {model} dofs, the integrator's state {state}: add the new nodes' motion first")]
    Dofs { model: usize, state: usize },
}

impl Dynamics {
    /// Appends nodes with velocities `v` and accelerations `a`, 6 per node.
    pub fn push_nodes(&mut self, v: &[f64], a: &[f64]) -> Result<(), ResizeError> {
        if !v.len().is_multiple_of(6) {
            return Err(ResizeError::Length {
                what: "velocity",
                got: v.len(),
                expected: v.len().div_ceil(6) * 6,
            });
        }
        if a.len() != v.len() {
            return Err(ResizeError::Length {
                what: "acceleration",
                got: a.len(),
                expected: v.len(),
            });
        }
        self.v.extend_from_slice(v);
        self.a.extend_from_slice(a);
        Ok(())
    }

    /// Appends nodes that start with the velocity and acceleration of the nodes `sources`
    /// (phantom nodes start with the motion of the nodes they copy; the integrators'
    /// `follow_topology` then gives them the acceleration of the changed model).
    pub fn copy_nodes(&mut self, sources: &[usize]) -> Result<(), ResizeError> {
        let n = self.v.len() / 6;
        if let Some(&node) = sources.iter().find(|&&s| s >= n) {
            return Err(ResizeError::Source { node, n });
        }
        for &s in sources {
            self.v.extend_from_within(6 * s..6 * s + 6);
            self.a.extend_from_within(6 * s..6 * s + 6);
        }
        Ok(())
    }

    /// The state fits `model` after its topology changed; returns its dofs.
    fn fits(&self, model: &dyn Model) -> Result<usize, ResizeError> {
        let n = model.n_dof();
        if self.v.len() != n || self.a.len() != n {
            return Err(ResizeError::Dofs { model: n, state: self.v.len() });
        }
        Ok(n)
    }
}

/// Accelerations `M⁻¹ (f_ext(t) + extra - f_int)` of the changed model at its committed
/// configuration written into `a` for the dofs from `first` on (the nodes a topology change
/// added; the others keep theirs, so a change that does not touch them leaves their motion
/// as it was). The trial state the evaluation leaves is dropped.
fn added_accelerations(
    model: &mut dyn Model,
    (t, extra): (f64, Option<&[f64]>),
    first: usize,
    work: [&mut [f64]; 3],
    a: &mut [f64],
) {
    let [fi, r, all] = work;
    out_of_balance(model, t, extra, fi, r);
    model.apply_inverse_mass(r, all);
    a[first..].copy_from_slice(&all[first..]);
    model.revert();
}

/// Prescribed increments of the constrained dofs over `[t, t + dt]` written into `du`.
fn prescribed_increment(model: &dyn Model, t: f64, dt: f64, scratch: &mut [f64], du: &mut [f64]) {
    scratch.fill(0.0);
    model.prescribed(t, scratch);
    du.fill(0.0);
    model.prescribed(t + dt, du);
    for ((d, s), &c) in du.iter_mut().zip(scratch.iter()).zip(model.constrained()) {
        *d = if c { *d - s } else { 0.0 };
    }
}

/// `f_ext(t) + extra - f_int` at the model's current configuration, written into `r`;
/// `f_int` is left in `fi`.
fn out_of_balance(
    model: &mut dyn Model,
    t: f64,
    extra: Option<&[f64]>,
    fi: &mut [f64],
    r: &mut [f64],
) {
    fi.fill(0.0);
    model.internal_force(fi);
    r.fill(0.0);
    model.external_force_with(t, extra, r);
    for (r, f) in r.iter_mut().zip(fi.iter()) {
        *r -= f;
    }
}

/// Kinetic energy `½ vᵀ M v` with the model's mass (`Model::mass_product`: rigid bodies'
/// full blocks).
pub fn kinetic_energy(model: &dyn Model, v: &[f64]) -> f64 {
    let mut mv = vec![0.0; v.len()];
    model.mass_product(v, &mut mv);
    0.5 * mv.iter().zip(v).map(|(p, v)| p * v).sum::<f64>()
}
