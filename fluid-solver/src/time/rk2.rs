//! The explicit second-order TVD Runge-Kutta scheme (Shu & Osher 1988, Heun form):
//! `W¹ = Wⁿ - Δt/|C| R(Wⁿ)`, `Wⁿ⁺¹ = ½ Wⁿ + ½ (W¹ - Δt/|C| R(W¹))`.

use super::cfl::{stable_time_step, TimeStepping};
use crate::embedded::step::{EmbeddedStep, Wall};
use crate::embedded::tracker::Tracker;
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
    let dt_min = stable_time_step(semi, &state.cons, ws)?;
    let dt_global = (stepping.cfl() * dt_min).min(dt_max);
    let local = matches!(stepping, TimeStepping::Local { .. });
    let cfl = stepping.cfl();
    let dt_node = std::mem::take(&mut ws.dt_node);
    // Δt_i / |C_i|.
    let ratio = |i: usize| {
        let dt = if local { (cfl * dt_node[i]).min(dt_max) } else { dt_global };
        dt / semi.mesh.volumes[i]
    };
    let result = stages(semi, state, ws, ratio, None);
    ws.dt_node = dt_node;
    result.map(|()| dt_global)
}

/// One RK2 step of exactly `dt` from `t_a = tracker.surface.t_a` to `t_b = t_a + dt` with the
/// embedded boundary of `tracker` (cut edges at `t_b`, thesis §4.4): the first stage sees the
/// wall velocity at `t_a`, the second at `t_b`; nodes that are not active keep their state.
/// `ws.prim` must hold the primitives of `state` (as [`stable_time_step`] leaves them).
pub fn rk2_step_embedded(
    semi: &Semidiscretization,
    state: &mut State,
    ws: &mut Workspace,
    dt: f64,
    step: &EmbeddedStep,
    tracker: &Tracker,
) -> Result<(), FluidError> {
    let ratio = |i: usize| if tracker.active[i] { dt / semi.mesh.volumes[i] } else { 0.0 };
    let (t_a, t_b) = (tracker.surface.t_a, tracker.surface.t_b);
    let walls = [Wall { step, tracker, t: t_a }, Wall { step, tracker, t: t_b }];
    stages(semi, state, ws, ratio, Some(walls))
}

/// The two stages with `ratio(i) = Δt_i / |C_i|` (zero freezes a node), each with its wall; the
/// new state is built in `ws.stage` and swapped in at the end.
fn stages(
    semi: &Semidiscretization,
    state: &mut State,
    ws: &mut Workspace,
    ratio: impl Fn(usize) -> f64 + Sync,
    walls: Option<[Wall<'_>; 2]>,
) -> Result<(), FluidError> {
    let mut stage = std::mem::take(&mut ws.stage);
    let cons = &state.cons;
    // Stage 1: W¹ = Wⁿ - Δt/|C| R(Wⁿ), into `stage`.
    let mut result = semi.residual_and_update_with(
        ws,
        &mut stage,
        |i, r, w1| {
            let a = ratio(i);
            for k in 0..5 {
                w1[k] = cons[i][k] - a * r[k];
            }
        },
        walls.map(|w| w[0]),
    );
    // Stage 2: Wⁿ⁺¹ = ½ Wⁿ + ½ (W¹ - Δt/|C| R(W¹)), in place of W¹ in `stage`.
    if result.is_ok() {
        result = semi.primitives(&stage, ws).and_then(|()| {
            semi.residual_and_update_with(
                ws,
                &mut stage,
                |i, r, w| {
                    let a = ratio(i);
                    for k in 0..5 {
                        w[k] = 0.5 * cons[i][k] + 0.5 * (w[k] - a * r[k]);
                    }
                },
                walls.map(|w| w[1]),
            )
        });
    }
    if result.is_ok() {
        std::mem::swap(&mut state.cons, &mut stage);
    }
    ws.stage = stage;
    result
}
