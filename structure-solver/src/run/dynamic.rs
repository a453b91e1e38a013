//! The time loop of a dynamic run alone.

use std::time::Instant;

use anyhow::{anyhow, bail, Context};
use interface_protocol::case::Integrator;
use interface_protocol::io::outdir::OutputDir;
use interface_protocol::io::report::{bucket, Timers};
use interface_protocol::resources::MAX_STEPS;

use super::alone_output::AloneOutput;
use super::checkpoint::{write_checkpoint, Resume};
use super::Reached;
use crate::assembly::FeModel;
use crate::mesh::Mesh;
use crate::model::Model;
use crate::prepare::unstable_note;
use crate::state_check::check_state;
use crate::time::{CentralDifference, Dynamics, Implicit, ImplicitScheme, StableStep};

/// A dynamic run alone: central differences or an implicit scheme stepping to `t_end`, each
/// step checked finite (naming step, time, node and dof, and an unstable step) before its
/// outputs and checkpoint.
pub(super) struct Dynamic<'a> {
    pub(super) mesh: &'a Mesh,
    pub(super) dir: &'a OutputDir,
    pub(super) checkpoint_every: u64,
    pub(super) t_end: f64,
    pub(super) dt: f64,
    pub(super) stable: Option<f64>,
    /// Central differences: the step recomputed every step (`dt` and `stable` then follow it).
    pub(super) adaptive: Option<StableStep>,
    pub(super) output: &'a mut AloneOutput,
    pub(super) timers: &'a mut Timers,
    pub(super) reached: &'a mut Reached,
}

impl Dynamic<'_> {
    pub(super) fn integrate(
        &mut self,
        model: &mut FeModel,
        integrator: Integrator,
        v0: Vec<f64>,
        resume: Option<Resume>,
    ) -> anyhow::Result<()> {
        let (t_end, dt) = (self.t_end, self.dt);
        let mut disp = vec![[0.0; 3]; model.n_nodes()];
        if integrator == Integrator::CentralDifference {
            let mut cd = match resume {
                Some(r) => CentralDifference::resume(model, r.dynamics),
                None => CentralDifference::new(model, 0.0, v0, None),
            };
            // a restart at `t_end` has nothing to step: its state is the last
            let (at, last) = ((self.reached.steps, cd.state.t, dt), self.ended(cd.state.t));
            self.output.write(model, Some(model), &cd.state.v, at, last)?;
            while !self.ended(cd.state.t) {
                if let Some(rule) = self.adaptive {
                    self.adapt(rule.at(model), rule.safety)?;
                }
                let step = self.dt.min(t_end - cd.state.t);
                self.timers.time(bucket::STRUCTURE, || cd.step(model, step, None));
                let state = (&cd.state.v[..], &cd.state.a[..], Some(cd.internal_force()));
                self.finite(model, &mut disp, state, cd.state.t)?;
                self.after_step(model, &cd.state, step)?;
            }
        } else {
            let scheme = if integrator == Integrator::Newmark {
                ImplicitScheme::Newmark
            } else {
                ImplicitScheme::Midpoint
            };
            let mut im = match resume {
                Some(r) => Implicit::resume(model, scheme, r.dynamics),
                None => Implicit::new(model, scheme, 0.0, v0, None),
            };
            // a restart at `t_end` has nothing to step: its state is the last
            let (at, last) = ((self.reached.steps, im.state.t, dt), self.ended(im.state.t));
            self.output.write(model, Some(model), &im.state.v, at, last)?;
            while !self.ended(im.state.t) {
                let step = dt.min(t_end - im.state.t);
                let n = self.reached.steps + 1;
                self.timers
                    .time(bucket::STRUCTURE, || im.step(model, step, None))
                    .with_context(|| format!("step {n} (t = {:e})", im.state.t + step))?;
                self.finite(model, &mut disp, (&im.state.v, &im.state.a, None), im.state.t)?;
                self.after_step(model, &im.state, step)?;
                if self.checkpoint_every > 0
                    && self.reached.steps.is_multiple_of(self.checkpoint_every)
                {
                    im.forget_factor(); // a restart from this checkpoint starts afresh too
                }
            }
        }
        Ok(())
    }

    /// The state at `t` after the next step, checked finite.
    pub(super) fn finite(
        &self,
        model: &FeModel,
        disp: &mut [[f64; 3]],
        state: (&[f64], &[f64], Option<&[f64]>),
        t: f64,
    ) -> anyhow::Result<()> {
        let id = |i: usize| self.mesh.node_id(i);
        check_state(model, disp, state, &id).map_err(|e| {
            let note = unstable_note(self.stable, self.dt);
            anyhow!(
                "step {} (t = {t:e}): {e}: the structure diverged{note}",
                self.reached.steps + 1
            )
        })
    }

    /// Takes the stable step `dt` of the current configuration (`safety` x the stable one),
    /// refusing one that is no longer a positive number or a run past `MAX_STEPS` steps.
    fn adapt(&mut self, dt: f64, safety: f64) -> anyhow::Result<()> {
        let n = self.reached.steps + 1;
        if !(dt.is_finite() && dt > 0.0) {
            bail!(
                "step {n}: the stable step at the current configuration is {dt:e} s: an element \
                 has collapsed"
            );
        }
        if n > MAX_STEPS {
            bail!("step {n}: more than {MAX_STEPS} steps; the stable step has fallen to {dt:e} s");
        }
        self.dt = dt;
        self.stable = Some(dt / safety);
        Ok(())
    }

    /// Whether `t` is the end of the run.
    pub(super) fn ended(&self, t: f64) -> bool {
        t >= self.t_end * (1.0 - 1e-12)
    }

    /// Counts the step and writes its outputs and checkpoint.
    pub(super) fn after_step(
        &mut self,
        model: &FeModel,
        d: &Dynamics,
        step: f64,
    ) -> anyhow::Result<()> {
        *self.reached = Reached { steps: self.reached.steps + 1, t: d.t };
        let steps = self.reached.steps;
        let t0 = Instant::now();
        let last = self.ended(d.t);
        self.output
            .write(model, Some(model), &d.v, (steps, d.t, step), last)
            .with_context(|| format!("step {steps} of {:.3e} s", self.dt))?;
        if self.checkpoint_every > 0 && steps.is_multiple_of(self.checkpoint_every) {
            write_checkpoint(self.dir, model, d, steps, self.dt)?;
        }
        self.timers.add_since(bucket::OUTPUT, t0);
        Ok(())
    }
}
