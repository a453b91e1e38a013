//! The explicit second-order TVD Runge-Kutta scheme (Shu & Osher 1988, Heun form):
//! `W¹ = Wⁿ - Δt/|C| R(Wⁿ)`, `Wⁿ⁺¹ = ½ Wⁿ + ½ (W¹ - Δt/|C| R(W¹))`.

use super::cfl::{stable_time_step, TimeStepping};
use crate::semidiscretization::{FluidError, Semidiscretization};
use crate::state::{State, Workspace};
use rayon::prelude::*;

/// Advances `state` by one RK2 step no longer than `dt_max`; returns the (global) step taken
/// (for local stepping, the smallest node step).
pub fn rk2_step(
    semi: &Semidiscretization,
    state: &mut State,
    ws: &mut Workspace,
    stepping: TimeStepping,
    dt_max: f64,
) -> Result<f64, FluidError> {
    let dt_min = stable_time_step(semi, &state.cons, ws)?;
    let dt_global = (stepping.cfl() * dt_min).min(dt_max);
    let local = matches!(stepping, TimeStepping::Local { .. });
    let cfl = stepping.cfl();
    if local {
        ws.dt_node.par_iter_mut().for_each(|dt| *dt = (cfl * *dt).min(dt_max));
    }
    let volumes = &semi.mesh.volumes;
    let dt_of = |dt_node: &[f64], i: usize| if local { dt_node[i] } else { dt_global };

    // Stage 1.
    semi.residual_from_primitives(ws)?;
    let mut stage = std::mem::take(&mut ws.stage);
    {
        let (res, dtn) = (&ws.residual, &ws.dt_node);
        stage.par_iter_mut().enumerate().with_min_len(1024).for_each(|(i, w1)| {
            let a = dt_of(dtn, i) / volumes[i];
            for k in 0..5 {
                w1[k] = state.cons[i][k] - a * res[i][k];
            }
        });
    }
    // Stage 2.
    let r = semi.residual(&stage, ws);
    if let Err(e) = r {
        ws.stage = stage;
        return Err(e);
    }
    {
        let (res, dtn) = (&ws.residual, &ws.dt_node);
        state.cons.par_iter_mut().enumerate().with_min_len(1024).for_each(|(i, w)| {
            let a = dt_of(dtn, i) / volumes[i];
            for k in 0..5 {
                w[k] = 0.5 * w[k] + 0.5 * (stage[i][k] - a * res[i][k]);
            }
        });
    }
    ws.stage = stage;
    Ok(dt_global)
}
