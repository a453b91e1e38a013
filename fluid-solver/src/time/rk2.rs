//! The explicit second-order TVD Runge-Kutta scheme (Shu & Osher 1988, Heun form):
//! `W¹ = Wⁿ - Δt/|C| R(Wⁿ)`, `Wⁿ⁺¹ = ½ Wⁿ + ½ (W¹ - Δt/|C| R(W¹))`.

use super::cfl::{stable_time_step, TimeStepping};
use crate::semidiscretization::{FluidError, Semidiscretization};
use crate::state::{State, Workspace};

/// Advances `state` by one RK2 step no longer than `dt_max`; returns the (global) step taken
/// (for local stepping, the smallest node step). Each stage's update is applied inside the
/// residual's edge pass ([`Semidiscretization::residual_and_update`]); the new state is built in
/// `ws.stage` and swapped in at the end, so on error `state` is unchanged.
pub fn rk2_step(
    semi: &Semidiscretization,
    state: &mut State,
    ws: &mut Workspace,
    stepping: TimeStepping,
    dt_max: f64,
) -> Result<f64, FluidError> {
    debug_assert!(state.material == semi.material(), "state and operator material layouts differ");
    let dt_min = stable_time_step(semi, &state.cons, ws)?;
    let dt_global = (stepping.cfl() * dt_min).min(dt_max);
    let local = matches!(stepping, TimeStepping::Local { .. });
    let cfl = stepping.cfl();
    let volumes = &semi.mesh.volumes;
    let mut stage = std::mem::take(&mut ws.stage);
    let dt_node = std::mem::take(&mut ws.dt_node);
    // Δt_i / |C_i|.
    let ratio = |i: usize| {
        let dt = if local { (cfl * dt_node[i]).min(dt_max) } else { dt_global };
        dt / volumes[i]
    };
    let cons = &state.cons;
    // Stage 1: W¹ = Wⁿ - Δt/|C| R(Wⁿ), into `stage`.
    let mut result = semi.residual_and_update(ws, &mut stage, |i, r, w1| {
        let a = ratio(i);
        for k in 0..5 {
            w1[k] = cons[i][k] - a * r[k];
        }
    });
    // Stage 2: Wⁿ⁺¹ = ½ Wⁿ + ½ (W¹ - Δt/|C| R(W¹)), in place of W¹ in `stage`.
    if result.is_ok() {
        result = semi.primitives(&stage, ws).and_then(|()| {
            semi.residual_and_update(ws, &mut stage, |i, r, w| {
                let a = ratio(i);
                for k in 0..5 {
                    w[k] = 0.5 * cons[i][k] + 0.5 * (w[k] - a * r[k]);
                }
            })
        });
    }
    if result.is_ok() {
        std::mem::swap(&mut state.cons, &mut stage);
    }
    ws.stage = stage;
    ws.dt_node = dt_node;
    result.map(|()| dt_global)
}
