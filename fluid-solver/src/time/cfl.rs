//! CFL time steps: `Δt_i = 2 CFL |C_i| / Σ (|u·ν| + c|ν|)` per node (see
//! [`Semidiscretization::node_time_steps`]); the global step is the smallest.

use crate::semidiscretization::{FluidError, Semidiscretization};
use crate::state::Workspace;
use rayon::prelude::*;

/// How the time step is chosen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TimeStepping {
    /// One step for all nodes: `CFL · min_i Δt_i` (time accurate).
    Global { cfl: f64 },
    /// Each node its own `CFL · Δt_i` (steady states only: not time accurate).
    Local { cfl: f64 },
}

impl TimeStepping {
    pub fn cfl(&self) -> f64 {
        match *self {
            TimeStepping::Global { cfl } | TimeStepping::Local { cfl } => cfl,
        }
    }
}

/// Fills `ws.prim` and `ws.dt_node` (for CFL 1) from `cons`; returns `min_i Δt_i`.
pub fn stable_time_step(
    semi: &Semidiscretization,
    cons: &[[f64; 5]],
    ws: &mut Workspace,
) -> Result<f64, FluidError> {
    semi.primitives(cons, ws)?;
    semi.node_time_steps(ws);
    Ok(ws.dt_node.par_iter().copied().reduce(|| f64::INFINITY, f64::min))
}
