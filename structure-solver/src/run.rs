//! `structure-solver run CASE`: a structure alone, from the `[structure]` section of a case
//! (DESIGN §7; the schema is documented in `interface_protocol::case::structure`): mesh and
//! sets, materials and parts, boundary conditions, loads with time curves, initial velocity,
//! and the analysis: central differences, Newmark, the implicit midpoint rule, or statics
//! (load steps or displacement control). Probes go to `structure_probes.csv` (static runs: the
//! time column holds the load factor), fields to `structure.xdmf`, the final cell fields to
//! `structure_cells.csv`.
//!
//! Every structure is one `assembly::FeModel`; BT4 shells are its explicit-only part. Central
//! differences scale the shells' rotary inertia (`RotaryInertia::Scaled`), implicit and static
//! runs keep the physical one. What happens before the first step is [`crate::prepare`]'s,
//! shared with `check`.

use std::path::{Path, PathBuf};
use std::time::{Instant, SystemTime};

use anyhow::{anyhow, bail, Context};
use interface_protocol::case::{Case, CurveName, CurveSpec, Integrator, StructureSection};
use interface_protocol::io::checkpoint::{self, Checkpoint};
use interface_protocol::io::outdir::{default_run_dir, OutputDir, Policy};
use interface_protocol::io::probes::ProbeWriter;
use interface_protocol::io::progress::Progress;
use interface_protocol::io::report::{bucket, case_echo, versions, RunReport, Timers};

use crate::assembly::FeModel;
use crate::build::{field_error, node_set, section, Structure};
use crate::mesh::Mesh;
use crate::model::Model;
use crate::output::{gather_nodal, write_cell_table, FieldOutput};
use crate::prepare::{prepare_alone, unstable_note, Alone};
use crate::restart::{load_dynamics, restore_state, save_dynamics, save_state, PART};
use crate::state_check::check_state;
use crate::statics::{
    arc_length, displacement_control, load_steps, ArcLengthSettings, Converged, NewtonSettings,
};
use crate::time::{CentralDifference, Dynamics, Implicit, ImplicitScheme};

/// Options of `run`.
#[derive(Debug, Clone)]
pub struct RunOptions {
    pub case: PathBuf,
    pub out: Option<PathBuf>,
    pub set: Vec<String>,
    pub quiet: bool,
    /// Reuse an output folder that holds a previous run (`--force`).
    pub force: bool,
    /// Resume from the newest checkpoint in this run folder.
    pub restart: Option<PathBuf>,
}

/// What a run did.
#[derive(Debug, Clone)]
pub struct RunSummary {
    pub steps: u64,
    pub t: f64,
    pub dt: f64,
    pub out: PathBuf,
}

/// What a run alone writes per step: probe rows every `probes_every` steps, the field series
/// every `fields_every` steps (0: first and last only), both at the end; the first non-finite
/// value stops the run.
struct AloneOutput {
    probe_nodes: Vec<usize>,
    probes: ProbeWriter,
    probes_every: u64,
    fields: FieldOutput,
    fields_every: u64,
    disp: Vec<[f64; 3]>,
    vel: Vec<[f64; 3]>,
    bar: Progress,
}

impl AloneOutput {
    /// Writes step `step` at `t` (`last`: the final state); `cells` gives the model for cell
    /// fields (dynamic runs).
    fn write(
        &mut self,
        model: &dyn Model,
        cells: Option<&FeModel>,
        v: &[f64],
        (step, t, dt): (u64, f64, f64),
        last: bool,
    ) -> anyhow::Result<()> {
        let probe = step % self.probes_every == 0 || last;
        let field = step == 0 || last || (self.fields_every > 0 && step % self.fields_every == 0);
        self.bar.update(step, t, dt);
        if !(probe || field) {
            return Ok(());
        }
        gather_nodal(t, model, v, &mut self.disp, &mut self.vel)?;
        if probe {
            let mut row = Vec::with_capacity(6 * self.probe_nodes.len());
            for &p in &self.probe_nodes {
                row.extend_from_slice(&self.disp[p]);
                row.extend_from_slice(&self.vel[p]);
            }
            self.probes.write_row(t, &row)?;
        }
        if field {
            self.fields.gather(t, model, cells, v)?;
            self.fields.write(t)?;
        }
        Ok(())
    }
}

/// Where a restart resumes: step, time step and integrator state (the model is restored).
struct Resume {
    step: u64,
    dt: f64,
    dynamics: Dynamics,
}

/// Restores `model` from the newest complete checkpoint of run folder `from`.
fn read_checkpoint(from: &Path, model: &mut FeModel) -> anyhow::Result<Resume> {
    let dir = from.join("checkpoints");
    let found = checkpoint::latest(&dir, &[PART])?.ok_or_else(|| {
        anyhow!("--restart {}: no complete checkpoint in {}", from.display(), dir.display())
    })?;
    let ck = Checkpoint::read(&dir, &found.tag, PART)?;
    eprintln!(
        "structure-solver: restarting from checkpoint {} (step {}, t = {:e}) in {}",
        found.tag,
        found.step,
        found.time,
        dir.display()
    );
    restore_state(model, &ck)?;
    let dt = ck
        .f64("dt")?
        .first()
        .copied()
        .ok_or_else(|| anyhow!("checkpoint {}: empty `dt`", found.tag))?;
    Ok(Resume { step: ck.step, dt, dynamics: load_dynamics(&ck, model.n_dof())? })
}

/// Writes `checkpoints/<checkpoint::tag_for_step(step)>/structure.ckpt`: model state, velocities, accelerations, `dt`.
fn write_checkpoint(
    dir: &OutputDir,
    model: &FeModel,
    d: &Dynamics,
    step: u64,
    dt: f64,
) -> anyhow::Result<()> {
    let mut ck = Checkpoint::new(step, d.t);
    save_state(model, &mut ck)?;
    save_dynamics(&mut ck, d)?;
    ck.put("dt", vec![dt])?;
    ck.write(&dir.checkpoints()?, &checkpoint::tag_for_step(step), PART)?;
    Ok(())
}

/// Where a run has got to: steps completed and the time (load factor) of the last good state.
#[derive(Debug, Clone, Copy)]
struct Reached {
    steps: u64,
    t: f64,
}

/// The folders `a` and `b` are one (both exist and resolve to the same path).
/// Runs a case alone. The output folder follows the one rule of every binary: a folder that
/// holds a run is refused unless `--force`; a restart from the same folder under `--force`
/// continues that run in place (its checkpoints stay, [`Policy::alone`]). Every step is checked finite before anything is written;
/// `run.json` records how the run ended, failed runs included.
pub fn run(opts: &RunOptions) -> anyhow::Result<RunSummary> {
    let case = Case::load(&opts.case, &opts.set)?;
    let file = case.source.path.clone();
    let s = section(&case)?;
    let alone = prepare_alone(&case)?;
    let statics = alone.integrator == Integrator::Static;
    if statics && opts.restart.is_some() {
        bail!("--restart applies to dynamic runs; a static run starts from its unloaded state");
    }
    let Alone { structure, integrator, t_end, stable, probe_nodes, .. } = alone;
    let Structure { mesh, mut model, v0, cells, .. } = structure;
    let n = mesh.nodes.len();

    let out = opts.out.clone().unwrap_or_else(|| default_run_dir(&opts.case, SystemTime::now()));
    // Read the checkpoint before the output folder is made: it may be the same folder.
    let resume = match &opts.restart {
        Some(from) => Some(read_checkpoint(from, &mut model)?),
        None => None,
    };
    let policy = Policy::alone(opts.force, opts.restart.as_deref(), &out);
    let dir = OutputDir::create(&out, policy)?;
    let names: Vec<&str> = s.probes.iter().map(|p| p.name.as_str()).collect();
    let started = Instant::now();
    // Static steps see the model through `dyn Model` only: nodal fields.
    let field_cells = if statics { None } else { Some(cells.clone()) };
    let mut output = AloneOutput {
        probe_nodes,
        probes: ProbeWriter::structure(dir.path(), &names)?,
        probes_every: s.output_every.unwrap_or(1).max(1),
        fields: FieldOutput::create(dir.path(), &mesh, field_cells)?,
        fields_every: case.output.fields_every,
        disp: vec![[0.0; 3]; n],
        vel: vec![[0.0; 3]; n],
        bar: Progress::new(t_end, opts.quiet),
    };
    let mut timers = Timers::new();
    let start = resume
        .as_ref()
        .map_or(Reached { steps: 0, t: 0.0 }, |r| Reached { steps: r.step, t: r.dynamics.t });
    let mut reached = start;
    let dt = resume.as_ref().map_or(alone.dt, |r| r.dt);
    let result = match integrator {
        Integrator::Static => {
            run_static(s, &case, &mesh, &mut model, t_end, &mut output, &mut timers).map(|done| {
                reached = Reached { steps: done.len() as u64, t: done.last().map_or(0.0, |c| c.t) };
            })
        }
        _ => {
            let mut run = Dynamic {
                mesh: &mesh,
                dir: &dir,
                checkpoint_every: case.output.checkpoint_every,
                t_end,
                dt,
                stable,
                output: &mut output,
                timers: &mut timers,
                reached: &mut reached,
            };
            run.integrate(&mut model, integrator, v0, resume)
        }
    };
    output.probes.flush()?;
    output.fields.finish()?;
    output.bar.finish();
    if result.is_ok() {
        write_cell_table(&dir.path().join("structure_cells.csv"), &mesh, &model, &cells)?;
    }
    let report = RunReport {
        case_file: file.display().to_string(),
        case: std::fs::read_to_string(&file)
            .ok()
            .and_then(|text| case_echo(&text).ok())
            .unwrap_or_default(),
        versions: {
            let mut v = versions();
            v.insert("structure-solver".into(), env!("CARGO_PKG_VERSION").into());
            v
        },
        status: match &result {
            Ok(()) => "completed".into(),
            Err(e) => format!("{e:#}"),
        },
        steps: reached.steps,
        final_time: reached.t,
        counts: [("nodes", n as u64), ("cells", mesh.cells.len() as u64)]
            .into_iter()
            .map(|(k, v)| (k.to_string(), v))
            .collect(),
        wall_seconds: started.elapsed().as_secs_f64(),
        timings: [("structure".to_string(), timers.seconds())].into_iter().collect(),
    };
    report.write(&dir.run_json())?;
    result?;
    let steps = reached.steps;
    let dt = if statics { t_end / steps.max(1) as f64 } else { dt };
    if !opts.quiet {
        let what = if statics { "load steps to load factor" } else { "steps to t =" };
        eprintln!(
            "structure-solver: {steps} {what} {t_end} (step {dt:.3e}); outputs in {}",
            out.display()
        );
    }
    Ok(RunSummary { steps, t: t_end, dt, out })
}

/// A dynamic run alone: central differences or an implicit scheme stepping to `t_end`, each
/// step checked finite (naming step, time, node and dof, and an unstable step) before its
/// outputs and checkpoint.
struct Dynamic<'a> {
    mesh: &'a Mesh,
    dir: &'a OutputDir,
    checkpoint_every: u64,
    t_end: f64,
    dt: f64,
    stable: Option<f64>,
    output: &'a mut AloneOutput,
    timers: &'a mut Timers,
    reached: &'a mut Reached,
}

impl Dynamic<'_> {
    fn integrate(
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
                let step = dt.min(t_end - cd.state.t);
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
                if self.checkpoint_every > 0 && self.reached.steps % self.checkpoint_every == 0 {
                    im.forget_factor(); // a restart from this checkpoint starts afresh too
                }
            }
        }
        Ok(())
    }

    /// The state at `t` after the next step, checked finite.
    fn finite(
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

    /// Whether `t` is the end of the run.
    fn ended(&self, t: f64) -> bool {
        t >= self.t_end * (1.0 - 1e-12)
    }

    /// Counts the step and writes its outputs and checkpoint.
    fn after_step(&mut self, model: &FeModel, d: &Dynamics, step: f64) -> anyhow::Result<()> {
        *self.reached = Reached { steps: self.reached.steps + 1, t: d.t };
        let steps = self.reached.steps;
        let t0 = Instant::now();
        let last = self.ended(d.t);
        self.output
            .write(model, Some(model), &d.v, (steps, d.t, step), last)
            .with_context(|| format!("step {steps} of {:.3e} s", self.dt))?;
        if self.checkpoint_every > 0 && steps % self.checkpoint_every == 0 {
            write_checkpoint(self.dir, model, d, steps, self.dt)?;
        }
        self.timers.add_since(bucket::OUTPUT, t0);
        Ok(())
    }
}

/// A static run: `steps` equal load increments to the load factor `t_end`, displacement
/// control of one dof to `control.value`, or arc-length path following to the load factor
/// `t_end` in at most `steps` steps (the last two scale the loads with the load factor λ).
/// Each converged step writes a probe row at its load factor.
fn run_static(
    s: &StructureSection,
    case: &Case,
    mesh: &Mesh,
    model: &mut FeModel,
    t_end: f64,
    output: &mut AloneOutput,
    timers: &mut Timers,
) -> anyhow::Result<Vec<Converged>> {
    let steps = s.steps.unwrap_or(10);
    let defaults = NewtonSettings::default();
    let newton = s.newton.unwrap_or_default();
    let settings = NewtonSettings {
        tol: newton.tol.unwrap_or(defaults.tol),
        max_iter: newton.max_iter.unwrap_or(defaults.max_iter),
        max_cuts: newton.max_cuts.unwrap_or(defaults.max_cuts),
    };
    let zero = vec![0.0; model.n_dof()];
    output.write(&*model, None, &zero, (0, 0.0, 0.0), false)?;
    let mut k = 0u64;
    let mut failure = None;
    // `reached`: the arc length passed `t_end`; load steps and control end after `steps`.
    let mut on_step = |m: &mut dyn Model, c: Converged, reached: bool| {
        k += 1;
        let last = reached || k == steps as u64;
        if failure.is_none() {
            if let Err(e) = output.write(&*m, None, &zero, (k, c.t, c.t), last) {
                failure = Some(e);
            }
        }
    };
    let done = match (&s.control, &s.arc_length) {
        (None, Some(a)) => {
            linear_loads(s, case, "arc-length path following")?;
            let arc = ArcLengthSettings {
                newton: settings,
                initial: a.initial,
                min: a.min(),
                max: a.max(),
                desired_iterations: a.desired_iterations.unwrap_or(4),
                max_steps: steps,
                start: 0.0,
            };
            let mut reached = false;
            let done = timers.time(bucket::STRUCTURE, || {
                arc_length(model, &arc, |m, c| {
                    reached = c.t >= t_end;
                    on_step(m, c, reached);
                    !reached
                })
            })?;
            if !reached {
                return Err(field_error(
                    case,
                    "structure.steps",
                    format!(
                        "the arc length took {steps} steps to the load factor {:.4}, short of \
                         t_end = {t_end}; allow more steps or a longer arc",
                        done.last().map_or(0.0, |c| c.t)
                    ),
                ));
            }
            Ok(done)
        }
        (None, None) => {
            let targets: Vec<f64> = (1..=steps).map(|i| t_end * i as f64 / steps as f64).collect();
            timers.time(bucket::STRUCTURE, || {
                load_steps(model, &targets, &settings, |m, c| on_step(m, c, false))
            })
        }
        (Some(c), _) => {
            let node = match (&c.point, &c.set) {
                (Some(p), _) => mesh.nearest_node(*p),
                (None, Some(name)) => {
                    let nodes = node_set(mesh, name, "structure.control.set", case)?;
                    if nodes.len() != 1 {
                        return Err(field_error(
                            case,
                            "structure.control.set",
                            format!("expected a set of one node, \"{name}\" holds {}", nodes.len()),
                        ));
                    }
                    nodes[0]
                }
                (None, None) => unreachable!("validated: a point or a set"),
            };
            linear_loads(s, case, "displacement control")?;
            let targets: Vec<f64> =
                (1..=steps).map(|i| c.value * i as f64 / steps as f64).collect();
            let dof = 6 * node + c.dof.index();
            timers.time(bucket::STRUCTURE, || {
                displacement_control(model, dof, &targets, &settings, |m, c| on_step(m, c, false))
            })
        }
    };
    if let Some(e) = failure {
        return Err(e);
    }
    done.map_err(|e| anyhow!("{}: static solve: {e}", case.source.path.display()))
}

/// Path following scales the loads with the load factor: their curves must be linear and the
/// constrained dofs fixed.
fn linear_loads(s: &StructureSection, case: &Case, what: &str) -> anyhow::Result<()> {
    for (k, l) in s.loads.iter().enumerate() {
        if !matches!(l.curve, None | Some(CurveSpec::Named(CurveName::Linear))) {
            return Err(field_error(
                case,
                &format!("structure.loads[{k}].curve"),
                format!("{what} scales the loads with the load factor; use \"linear\""),
            ));
        }
    }
    if let Some(k) = s.bc.iter().position(|b| b.prescribed.is_some()) {
        return Err(field_error(
            case,
            &format!("structure.bc[{k}].prescribed"),
            format!("{what} holds the constrained dofs fixed; use `fixed`"),
        ));
    }
    Ok(())
}
