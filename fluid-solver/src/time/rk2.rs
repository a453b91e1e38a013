//! The explicit second-order TVD Runge-Kutta scheme (Shu & Osher 1988, Heun form):
//! `W¹ = Wⁿ - Δt/|C| R(Wⁿ)`, `Wⁿ⁺¹ = ½ Wⁿ + ½ (W¹ - Δt/|C| R(W¹))`.

use super::cfl::{stable_time_step, TimeStepping};
use crate::embedded::step::{EmbeddedStep, Wall};
use crate::embedded::tracker::Tracker;
use crate::levelset::{advect, LevelSet, LevelSetWorkspace};
use crate::reconstruct::gradient::LsqGradient;
use crate::semidiscretization::{FluidError, Semidiscretization};
use crate::state::{State, Workspace};
use std::sync::atomic::{AtomicU64, Ordering};

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
    let steps = NodeSteps::new(semi, &state.cons, ws, stepping, dt_max)?;
    let ratio = |i| steps.ratio(semi, i);
    let result = stages(semi, &mut state.cons, ws, ratio, None, |_, _| {}, |_, _| {});
    steps.finish(ws, result)
}

/// The CFL steps of one explicit step: the global step no longer than `dt_max` and, for
/// local stepping, each node's own (held out of `ws.dt_node` while the stages run).
struct NodeSteps {
    dt_global: f64,
    local: bool,
    cfl: f64,
    dt_max: f64,
    dt_node: Vec<f64>,
}

impl NodeSteps {
    fn new(
        semi: &Semidiscretization,
        cons: &[[f64; 5]],
        ws: &mut Workspace,
        stepping: TimeStepping,
        dt_max: f64,
    ) -> Result<NodeSteps, FluidError> {
        let dt_min = stable_time_step(semi, cons, ws)?;
        Ok(NodeSteps {
            dt_global: (stepping.cfl() * dt_min).min(dt_max),
            local: matches!(stepping, TimeStepping::Local { .. }),
            cfl: stepping.cfl(),
            dt_max,
            dt_node: std::mem::take(&mut ws.dt_node),
        })
    }

    /// `Δt_i / |C_i|`.
    #[inline]
    fn ratio(&self, semi: &Semidiscretization, i: usize) -> f64 {
        let dt =
            if self.local { (self.cfl * self.dt_node[i]).min(self.dt_max) } else { self.dt_global };
        dt / semi.mesh.volumes[i]
    }

    /// Gives `ws.dt_node` back; the global step taken when the stages succeeded.
    fn finish(self, ws: &mut Workspace, result: Result<(), FluidError>) -> Result<f64, FluidError> {
        ws.dt_node = self.dt_node;
        result.map(|()| self.dt_global)
    }
}

/// [`rk2_step`] of the flow and the level set together (thesis Eq. 3.8 with 3.10-3.13): each
/// stage advances `φ` with the velocities of that stage's flow state by the same update
/// ([`advect`]), `φ¹ = φⁿ - Δt/|C| R^φ(φⁿ, Wⁿ)`, `φⁿ⁺¹ = ½ φⁿ + ½ (φ¹ - Δt/|C| R^φ(φ¹, W¹))`, on the
/// material layout of `semi` (the caller updates the materials afterwards). After each stage's
/// update a node below its material's cavitation cut-off is clipped ([`crate::eos::Eos::cut_off`]
/// with `ls.p_cut`); the clips of the step are added to `clips`. On error `state` is unchanged.
#[allow(clippy::too_many_arguments)]
pub fn rk2_step_level_set(
    semi: &Semidiscretization,
    ls: &LevelSet,
    state: &mut State,
    ws: &mut Workspace,
    lws: &mut LevelSetWorkspace,
    stepping: TimeStepping,
    dt_max: f64,
    clips: &mut u64,
) -> Result<f64, FluidError> {
    let steps = NodeSteps::new(semi, &state.cons, ws, stepping, dt_max)?;
    let advection = PhiAdvection { gradient: &ls.gradient, open: &ls.open, through: None };
    let ratio = |i: usize| steps.ratio(semi, i);
    let clipped = AtomicU64::new(0);
    let cut_off = |i: usize, q: &mut [f64; 5]| {
        let m = semi.material()[i] as usize;
        if semi.eos[m].cut_off(q, ls.p_cut[m]) {
            clipped.fetch_add(1, Ordering::Relaxed);
        }
    };
    let result =
        stages_with_phi(semi, state, ws, ratio, None, cut_off, (advection, lws), |_, _| {});
    if result.is_ok() {
        *clips += clipped.into_inner();
    }
    steps.finish(ws, result)
}

/// How `φ` is advected in a step ([`advect::residual_and_update`]): the operator of `∇φ`, the
/// nodes on open boundaries, and the edges that carry its flux (`None`: all).
#[derive(Clone, Copy)]
pub struct PhiAdvection<'a> {
    pub gradient: &'a LsqGradient,
    pub open: &'a [bool],
    pub through: Option<&'a [bool]>,
}

/// One RK2 step of exactly `dt` from `t_a = tracker.surface.t_a` to `t_b = t_a + dt` with the
/// embedded boundary of `tracker` (cut edges at `t_b`, thesis §4.4): the first stage sees the
/// wall velocity at `t_a`, the second at `t_b`; nodes that are not active keep their state.
/// With `level_set`, `φ` advances by the same stages as in [`rk2_step_level_set`], through the
/// edges of its [`PhiAdvection`] (never across the surface). `ws.prim` must hold the primitives
/// of `state` (as [`stable_time_step`] leaves them). On error `state` is unchanged.
///
/// Returns the mass that left through the domain's boundary in the step, as the two stages apply
/// it: `Δt/2 (B(Wⁿ) + B(W¹))`, `B` the mass component of the active nodes' boundary fluxes.
pub fn rk2_step_embedded(
    semi: &Semidiscretization,
    state: &mut State,
    ws: &mut Workspace,
    dt: f64,
    step: &EmbeddedStep,
    tracker: &Tracker,
    level_set: Option<(PhiAdvection<'_>, &mut LevelSetWorkspace)>,
) -> Result<f64, FluidError> {
    let active = &tracker.active;
    let ratio = |i: usize| if active[i] { dt / semi.mesh.volumes[i] } else { 0.0 };
    let (t_a, t_b) = (tracker.surface.t_a, tracker.surface.t_b);
    let walls = [Wall { step, tracker, t: t_a }, Wall { step, tracker, t: t_b }];
    let mut outflow = Ok(0.0);
    let mut count = |_: usize, ws: &mut Workspace| {
        if let Ok(total) = &mut outflow {
            match semi.boundary_mass_outflow(&ws.prim, |i| active[i]) {
                Ok(b) => *total += 0.5 * dt * b,
                Err(e) => outflow = Err(e),
            }
        }
    };
    let result = match level_set {
        Some(phi) => stages_with_phi(semi, state, ws, ratio, Some(walls), |_, _| {}, phi, count),
        None => stages(semi, &mut state.cons, ws, ratio, Some(walls), |_, _| {}, &mut count),
    };
    result.and(outflow)
}

/// The two stages of the flow (with `walls`, if any) and of `φ` by `advection` with the
/// velocities of each stage's flow state, each node's flow state through `floor` as in
/// [`stages`]; `φ^{n+1}` is built in `lws.stage` and swapped into `state.phi` with the flow, so
/// on error `state` is unchanged. `after` runs after each stage's flow pass, as in [`stages`].
#[allow(clippy::too_many_arguments)]
fn stages_with_phi(
    semi: &Semidiscretization,
    state: &mut State,
    ws: &mut Workspace,
    ratio: impl Fn(usize) -> f64 + Sync,
    walls: Option<[Wall<'_>; 2]>,
    floor: impl Fn(usize, &mut [f64; 5]) + Sync,
    (advection, lws): (PhiAdvection<'_>, &mut LevelSetWorkspace),
    mut after: impl FnMut(usize, &mut Workspace),
) -> Result<(), FluidError> {
    let mut phi_stage = std::mem::take(&mut lws.stage);
    let State { cons, phi, .. } = state;
    let phi_n = &phi[..];
    let limiter = semi.numerics.limiter;
    let mesh = &semi.mesh;
    let ratio = &ratio;
    // `ws.prim` holds the primitives of the stage's flow state when each stage's flow pass ends.
    let result = stages(semi, cons, ws, ratio, walls, floor, |stage, ws| {
        after(stage, ws);
        // The stage's φ (φⁿ, then φ¹) into the advection workspace.
        let source: &[f64] = if stage == 0 { phi_n } else { &phi_stage };
        for (s, p) in lws.phi.iter_mut().zip(source) {
            s[0] = *p;
        }
        advect::residual_and_update(
            mesh,
            advection.gradient,
            limiter,
            advection.open,
            advection.through,
            Some(semi),
            &ws.prim,
            lws,
            &mut phi_stage,
            |i, r, p| {
                *p = match stage {
                    0 => phi_n[i] - ratio(i) * r,
                    _ => 0.5 * phi_n[i] + 0.5 * (*p - ratio(i) * r),
                }
            },
        );
    });
    if result.is_ok() {
        std::mem::swap(phi, &mut phi_stage);
    }
    lws.stage = phi_stage;
    result
}

/// The two stages with `ratio(i) = Δt_i / |C_i|` (zero freezes a node), each with its wall; the
/// new state is built in `ws.stage` and swapped in at the end. Each node's new stage state
/// passes through `floor(i, &mut W_i)` as soon as it is updated. After each stage's pass,
/// `after(stage, ws)` runs with `ws.prim` still the primitives that pass read (of `Wⁿ`, then of
/// `W¹`).
fn stages(
    semi: &Semidiscretization,
    state_cons: &mut Vec<[f64; 5]>,
    ws: &mut Workspace,
    ratio: impl Fn(usize) -> f64 + Sync,
    walls: Option<[Wall<'_>; 2]>,
    floor: impl Fn(usize, &mut [f64; 5]) + Sync,
    mut after: impl FnMut(usize, &mut Workspace),
) -> Result<(), FluidError> {
    let mut stage = std::mem::take(&mut ws.stage);
    let cons = &state_cons[..];
    // Stage 1: W¹ = Wⁿ - Δt/|C| R(Wⁿ), into `stage`.
    let mut result = semi.residual_and_update_with(
        ws,
        &mut stage,
        |i, r, w1| {
            let a = ratio(i);
            for k in 0..5 {
                w1[k] = cons[i][k] - a * r[k];
            }
            floor(i, w1);
        },
        walls.map(|w| w[0]),
    );
    if result.is_ok() {
        after(0, ws);
    }
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
                    floor(i, w);
                },
                walls.map(|w| w[1]),
            )
        });
        if result.is_ok() {
            after(1, ws);
        }
    }
    if result.is_ok() {
        std::mem::swap(state_cons, &mut stage);
    }
    ws.stage = stage;
    result
}
