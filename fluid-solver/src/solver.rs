//! The run loop (DESIGN §7): [`FluidRun`] marches a case with RK2 in CFL steps, writing probes,
//! lines, the field time series and checkpoints. [`run`] drives it alone to its end time and
//! writes `run.json`; [`crate::couple`] drives it from the coupling commands. Restarts from a
//! checkpoint; checks after every step (alone and coupled) that the state is valid and finite,
//! and stops at the first step that breaks either, naming node, field, time and values and
//! keeping the last good checkpoint.
//!
//! Requested output times (the `times` of the lines) are landed on exactly: the step that would
//! pass the next one is shortened to end on it, as is the step that would pass the target time,
//! and the CFL step resumes after it.
//!
//! A restarted run is bitwise identical to an uninterrupted one: the state is the conserved
//! array, the node materials and the level set plus `(step, t)` (and, with an embedded surface,
//! the part of [`embedded::checkpoint`] beside it), and the time step and the reinitialisations
//! depend only on them, on the target time and on the output times after `t`.

use crate::embedded::advance::{EmbeddedRun, LevelSetStep};
use crate::embedded::output::SurfaceSeries;
use crate::embedded::{self};
use crate::levelset::{LevelSet, LevelSetWorkspace};
use crate::output;
use crate::probes::{sampled_state, Line, Placed};
use crate::run_report::{surface_report, write_report};
use crate::semidiscretization::Semidiscretization;
use crate::setup::{self, Problem};
use crate::state::{State, Workspace};
use crate::time::{reached, rk2_step, FixedSteps, TimeStepping};
use anyhow::Context;
use interface_protocol::case::Case;
use interface_protocol::io::checkpoint;
use interface_protocol::io::finite::{check_finite, Entity};
use interface_protocol::io::outdir::{OutputDir, Policy};
use interface_protocol::io::probes::{write_line_sample, ProbeWriter};
use interface_protocol::io::progress::Progress;
use interface_protocol::io::report::{bucket, Timers};
use interface_protocol::io::xdmf::TimeSeriesWriter;
use std::path::{Path, PathBuf};
use std::time::Instant;

mod checkpoint_part;
use checkpoint_part::read_fluid_part;
pub use checkpoint_part::{read_checkpoint, CHECKPOINT_PART};

/// Command-line options of `fluid-solver run`.
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    pub out: PathBuf,
    pub quiet: bool,
    /// A previous run's output folder to continue from (its newest complete checkpoint).
    pub restart: Option<PathBuf>,
    /// Overwrite a previous run's files in `out`.
    pub force: bool,
}

/// How a run ended.
#[derive(Debug, Clone, PartialEq)]
pub struct RunSummary {
    pub steps: u64,
    pub time: f64,
    pub nodes: usize,
}

pub use crate::setup::Mode;

/// Where an advance ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reached {
    /// Fluid (CFL) steps taken since the start of the run.
    pub step: u64,
    /// Time reached.
    pub t: f64,
}

/// One fluid run: the state and every open output, advanced by [`FluidRun::advance_to`] in
/// CFL-limited RK2 steps. The stand-alone loop ([`run`]) and the coupled participant share it.
pub struct FluidRun<'a> {
    case: &'a Case,
    case_text: &'a str,
    mode: Mode,
    wall: Instant,
    out: OutputDir,
    timers: Timers,
    semi: Semidiscretization,
    stepping: TimeStepping,
    t_end: f64,
    max_steps: Option<u64>,
    /// `fluid.time.substeps` (coupled only): equal steps per `advance_to`.
    substeps: Option<u64>,
    state: State,
    ws: Workspace,
    step: u64,
    t: f64,
    fields: TimeSeriesWriter,
    /// The embedded surface's own series, opened at its first output.
    surface_fields: Option<SurfaceSeries>,
    probe_nodes: Vec<usize>,
    probe_points: Vec<[f64; 3]>,
    probe_csv: ProbeWriter,
    lines: Vec<Line>,
    last_fields_step: u64,
    bar: Option<Progress>,
    /// `Err` once a step failed: the run stops there and reports it.
    status: Result<(), String>,
    /// The embedded surface of `[fluid.embedded]` (fluid-alone runs).
    embedded: Option<EmbeddedRun>,
    /// The moving interface of `[fluid.level_set]`.
    level_set: Option<(LevelSet, LevelSetWorkspace)>,
    /// Node states clipped to the cavitation cut-off (level-set runs), in `run.json`.
    cavitation_clips: u64,
}

impl<'a> FluidRun<'a> {
    /// Sets the case up, opens the outputs and writes the initial probes and fields.
    /// `case_text` is echoed into `run.json`.
    pub fn open(
        case: &'a Case,
        case_text: &'a str,
        opts: &RunOptions,
        mode: Mode,
    ) -> anyhow::Result<FluidRun<'a>> {
        let wall = Instant::now();
        let problem = setup::problem(case, mode)?;
        for w in &problem.warnings {
            eprintln!("fluid-solver: warning: {w}");
        }
        let Problem {
            mut semi,
            initial,
            stepping,
            t_end,
            max_steps,
            substeps,
            probes,
            placed,
            level_set,
            ..
        } = problem;
        let Placed { probe_nodes, probe_points, mut lines } = placed;
        // Read the checkpoint before the output folder is made: it may be the same folder. A
        // fluid-alone run with an embedded surface restarts from a checkpoint holding its state.
        let n_nodes = semi.mesh.n_nodes();
        let embedded_alone =
            mode == Mode::Alone && case.fluid.as_ref().and_then(|f| f.embedded.as_ref()).is_some();
        let (state, step, t, saved) = match &opts.restart {
            Some(dir) if embedded_alone => {
                let ck = embedded::checkpoint::latest(dir, CHECKPOINT_PART)?;
                let (state, step, t) = read_fluid_part(&ck.found, n_nodes)?;
                (state, step, t, Some(ck))
            }
            Some(dir) => {
                let (state, step, t) = read_checkpoint(dir, n_nodes)?;
                (state, step, t, None)
            }
            None => (initial, 0, 0.0, None),
        };
        if state.material != semi.material() {
            semi.set_materials(state.material.clone())
                .context("the checkpoint's node materials do not fit the case")?;
        }
        if let Some(ls) = &level_set {
            ls.check(&state).map_err(|e| {
                anyhow::anyhow!("the state does not fit the case's [fluid.level_set]: {e}")
            })?;
        }
        let level_set = level_set.map(|ls| (ls, LevelSetWorkspace::new(semi.mesh.n_nodes())));
        // Coupled, the surface comes from the structure ([`crate::couple`] embeds it at `Init`).
        // A restart sets the surface up at t = 0, as the run did, then restores its state.
        let prescribed = match mode {
            Mode::Alone => embedded::case::prescribed(case, &semi.mesh, 0.0)?,
            Mode::Coupled => None,
        };
        let restored = match (&saved, &prescribed) {
            (Some(ck), Some(p)) => Some(ck.check(p, &semi.mesh)?),
            _ => None,
        };
        let policy = match mode {
            Mode::Alone => Policy::alone(opts.force, opts.restart.as_deref(), &opts.out),
            Mode::Coupled => Policy::Existing,
        };
        let out = OutputDir::create(&opts.out, policy)?;
        if opts.restart.is_some() {
            // Written before the checkpoint was taken.
            for line in &mut lines {
                line.pending.retain(|&lt| !reached(t, lt));
            }
        }
        let mut ws = Workspace::new(semi.mesh.n_nodes());
        semi.primitives(&state.cons, &mut ws)?;
        let embedded = match prescribed {
            None => None,
            Some(p) => {
                let p_cut =
                    case.fluid.as_ref().and_then(|f| f.embedded.as_ref()).and_then(|e| e.p_cut);
                let mut e = EmbeddedRun::new(p, p_cut, out.path())?;
                match restored {
                    Some(r) => r.restore(&mut e, &semi.mesh)?,
                    None => {
                        // `p*` of the initial state for the first output; the clips of this
                        // pass are not the run's.
                        let clips = e.clips;
                        e.start_pressures(&semi, &ws.prim)?;
                        e.clips = clips;
                    }
                }
                Some(e)
            }
        };

        let fields = output::create_writer(out.path(), &semi.mesh)?;
        let names: Vec<&str> = probes.iter().map(|p| p.name.as_str()).collect();
        // A coupled restart continues the run's probe file, which holds the row at `t` already.
        let resumed = mode == Mode::Coupled && opts.restart.is_some();
        let probe_csv = ProbeWriter::fluid_from(out.path(), &names, resumed.then_some(t))?;
        let bar = Progress::new(t_end, opts.quiet || mode == Mode::Coupled);
        let mut run = FluidRun {
            case,
            case_text,
            mode,
            wall,
            out,
            timers: Timers::new(),
            semi,
            stepping,
            t_end,
            max_steps,
            substeps,
            state,
            ws,
            step,
            t,
            fields,
            surface_fields: None,
            probe_nodes,
            probe_points,
            probe_csv,
            lines,
            last_fields_step: step,
            bar: Some(bar),
            status: Ok(()),
            embedded,
            level_set,
            cavitation_clips: 0,
        };
        run.write_field_step()?;
        if !resumed {
            run.write_probes()?;
        }
        // Lines asked for at the start time.
        run.write_due_lines()?;
        Ok(run)
    }

    /// `fluid.time.t_end` of the case (the end of a stand-alone run).
    pub fn t_end(&self) -> f64 {
        self.t_end
    }

    /// Where the run stands.
    pub fn reached(&self) -> Reached {
        Reached { step: self.step, t: self.t }
    }

    /// The mesh, EOS and scheme.
    pub fn semidiscretization(&self) -> &Semidiscretization {
        &self.semi
    }

    /// The state reached: conserved variables, node materials and level set.
    pub fn state(&self) -> &State {
        &self.state
    }

    /// The primitive states `[ρ, u, v, w, p]` of the last step that computed them (at least the
    /// start and every step with output).
    pub fn primitives(&self) -> &[[f64; 5]] {
        &self.ws.prim
    }

    /// The output folder.
    pub fn out_dir(&self) -> &Path {
        self.out.path()
    }

    /// Gives the run an embedded surface (a coupled run's, from the structure).
    pub fn embed(&mut self, surface: EmbeddedRun) {
        self.embedded = Some(surface);
    }

    /// The embedded surface, if any.
    pub fn embedded(&self) -> Option<&EmbeddedRun> {
        self.embedded.as_ref()
    }

    pub fn embedded_mut(&mut self) -> Option<&mut EmbeddedRun> {
        self.embedded.as_mut()
    }

    /// Writes the fields of the current state (`ws.prim`) and, with an embedded surface, the
    /// surface's step.
    fn write_field_step(&mut self) -> anyhow::Result<()> {
        let tracker = self.embedded.as_ref().map(|e| &e.tracker);
        let (semi, t) = (&self.semi, self.t);
        output::write_fields(&mut self.fields, semi, t, &self.ws.prim, &self.state.phi, tracker)?;
        if let Some(tracker) = tracker {
            let series = match &mut self.surface_fields {
                Some(s) => s,
                None => self
                    .surface_fields
                    .insert(SurfaceSeries::create(self.out.path(), &tracker.surface)?),
            };
            series.write(t, &semi.mesh, tracker)?;
        }
        self.last_fields_step = self.step;
        Ok(())
    }

    fn write_probes(&mut self) -> anyhow::Result<()> {
        let (prim, mesh) = (&self.ws.prim, &self.semi.mesh);
        let surface = self.embedded.as_ref().map(|e| &e.tracker);
        let row: Vec<f64> = self
            .probe_nodes
            .iter()
            .zip(&self.probe_points)
            .flat_map(|(&i, &x)| sampled_state(mesh, surface, prim, x, i))
            .collect();
        self.probe_csv.write_row(self.t, &row)?;
        Ok(())
    }

    /// The time the next step must not pass: `t_target` or the next line time before it.
    fn next_stop(&self, t_target: f64) -> f64 {
        self.lines.iter().filter_map(|l| l.pending.first().copied()).fold(t_target, f64::min)
    }

    /// Writes the lines whose next time is reached (from `ws.prim`), each once, in a file named
    /// for the time.
    fn write_due_lines(&mut self) -> anyhow::Result<()> {
        let t = self.t;
        for line in &mut self.lines {
            if line.due(t) {
                while line.due(t) {
                    line.pending.remove(0);
                }
                let name = format!("{}_t{t:.6e}", line.name);
                let surface = self.embedded.as_ref().map(|e| &e.tracker);
                let (mesh, prim) = (&self.semi.mesh, &self.ws.prim);
                let sample =
                    line.sample(mesh, surface, prim, &self.state.material, &self.state.phi);
                write_line_sample(&self.out.lines()?, &name, &sample)?;
            }
        }
        Ok(())
    }

    /// Advances to `t_target` in RK2 steps of the CFL step, shortened to land exactly on each
    /// line time on the way and on `t_target`, writing the outputs of every step; stops early
    /// after `fluid.time.max_steps` steps (stand-alone runs only). Coupled with
    /// `fluid.time.substeps = M`, in exactly `M` equal steps instead ([`FixedSteps`]; a step
    /// the stable step cuts short stops the run). Every step's state is checked
    /// valid and finite; a failed step keeps the last good state (alone, as a checkpoint) and
    /// returns the error naming the step, time, node, field and values; the run then only
    /// finishes.
    pub fn advance_to(&mut self, t_target: f64) -> anyhow::Result<Reached> {
        if let Err(e) = &self.status {
            anyhow::bail!("{e}");
        }
        let limit = match self.mode {
            Mode::Alone => self.max_steps,
            Mode::Coupled => None,
        };
        let every = &self.case.output;
        let fixed =
            self.substeps.map(|m| FixedSteps { substeps: m, t_from: self.t, t_to: t_target });
        let first = self.step;
        while !reached(self.t, t_target) && limit.is_none_or(|m| self.step < m) {
            let (step, t) = (self.step, self.t);
            let stop = match fixed {
                Some(f) => f.stop(step - first),
                None => self.next_stop(t_target),
            };
            let start = Instant::now();
            let result = match (&mut self.embedded, &mut self.level_set) {
                (None, Some((ls, lws))) => ls
                    .step(
                        &mut self.semi,
                        &mut self.state,
                        &mut self.ws,
                        lws,
                        self.stepping,
                        stop - t,
                        step + 1,
                    )
                    .map(|s| {
                        self.cavitation_clips += s.clips;
                        s.dt
                    })
                    .map_err(anyhow::Error::from),
                (None, None) => {
                    rk2_step(&self.semi, &mut self.state, &mut self.ws, self.stepping, stop - t)
                        .map_err(anyhow::Error::from)
                }
                (Some(e), ls) => {
                    let (tracking, loads) = (e.tracking_s, e.loads_s);
                    let cfl = self.stepping.cfl();
                    let ls = ls.as_mut().map(|(level_set, lws)| LevelSetStep {
                        level_set,
                        lws,
                        step_number: step + 1,
                    });
                    let (semi, state, ws) = (&mut self.semi, &mut self.state, &mut self.ws);
                    let r = e.step(semi, state, ws, cfl, t, stop, ls);
                    let d = |s: f64| std::time::Duration::from_secs_f64(s.max(0.0));
                    self.timers.add(bucket::TRACKING, d(e.tracking_s - tracking));
                    self.timers.add(bucket::LOADS, d(e.loads_s - loads));
                    r
                }
            };
            self.timers.add_since(bucket::RESIDUAL, start);
            let dt = match result {
                Ok(dt) => dt,
                Err(e) => {
                    // The state is unchanged by a failed step (an embedded step rolls itself
                    // back): keep it as the last good checkpoint (coupled, the launcher names and
                    // asks for checkpoints).
                    if self.mode == Mode::Alone {
                        self.write_checkpoint(&checkpoint::tag_for_step(step))?;
                    }
                    return self.fail(format!("stopped at step {}, t = {t:e}: {e}", step + 1));
                }
            };
            if let Some(Err(e)) = fixed.map(|f| f.check(t, stop, dt)) {
                // The state took the stable step: the run stops there.
                (self.t, self.step) = (t + dt, step + 1);
                return self.fail(format!("stopped at step {}: {e}", step + 1));
            }
            let cons = &self.state.cons[..];
            if let Err(e) = check_finite("conserved [ρ, ρu, ρv, ρw, E]", Entity::Node, t + dt, cons)
            {
                let node = e.index;
                return self.fail(format!(
                    "stopped at step {}: {e} (x = {:?}, conserved = {:?}); the last good checkpoint is kept",
                    step + 1,
                    self.semi.mesh.coords[node],
                    self.state.cons[node]
                ));
            }
            // A shortened step ends exactly on its stop, not at a rounded `t + dt`.
            self.t = if dt >= stop - t { stop } else { t + dt };
            self.step += 1;
            let (step, t) = (self.step, self.t);
            let start = Instant::now();
            let want_probes = step % every.probes_every == 0;
            let want_fields = every.fields_every > 0 && step % every.fields_every == 0;
            let want_lines = self.lines.iter().any(|l| l.due(t));
            if want_probes || want_fields || want_lines {
                self.semi.primitives(&self.state.cons, &mut self.ws)?;
            }
            if want_probes {
                self.write_probes()?;
            }
            if want_fields {
                self.write_field_step()?;
            }
            self.write_due_lines()?;
            if self.mode == Mode::Alone
                && every.checkpoint_every > 0
                && step % every.checkpoint_every == 0
            {
                self.write_checkpoint(&checkpoint::tag_for_step(step))?;
            }
            self.timers.add_since(bucket::OUTPUT, start);
            if let Some(bar) = &mut self.bar {
                bar.update(step, t, dt);
            }
        }
        Ok(self.reached())
    }

    fn fail(&mut self, message: String) -> anyhow::Result<Reached> {
        self.status = Err(message.clone());
        Err(anyhow::anyhow!(message))
    }

    /// Whether a step failed (the run can then only finish).
    pub fn failed(&self) -> bool {
        self.status.is_err()
    }

    /// Writes the final fields and lines (and, alone, the final checkpoint and `run.json`) and
    /// closes the files. Returns the failure of a failed run.
    pub fn finish(mut self) -> anyhow::Result<RunSummary> {
        if let Some(bar) = self.bar.take() {
            bar.finish();
        }
        if self.status.is_ok() {
            let start = Instant::now();
            self.semi.primitives(&self.state.cons, &mut self.ws)?;
            if self.last_fields_step != self.step {
                self.write_field_step()?;
            }
            for line in &self.lines {
                let surface = self.embedded.as_ref().map(|e| &e.tracker);
                let (mesh, prim) = (&self.semi.mesh, &self.ws.prim);
                let sample =
                    line.sample(mesh, surface, prim, &self.state.material, &self.state.phi);
                write_line_sample(&self.out.lines()?, &line.name, &sample)?;
            }
            self.timers.add_since(bucket::OUTPUT, start);
            if self.mode == Mode::Alone {
                self.write_checkpoint(&checkpoint::tag_for_step(self.step))?;
            }
        }
        self.probe_csv.flush()?;
        if let Some(e) = &mut self.embedded {
            e.flush()?;
        }
        self.fields.finish()?;
        if let Some(s) = self.surface_fields.take() {
            s.finish()?;
        }
        if self.mode == Mode::Alone {
            let surface =
                self.embedded.as_ref().map(|e| surface_report(e, &self.semi, &self.state));
            write_report(
                self.case,
                self.case_text,
                &self.out,
                &self.semi,
                &self.status,
                self.step,
                self.t,
                &self.timers,
                self.wall,
                self.cavitation_clips,
                surface,
            )?;
        }
        match self.status {
            Ok(()) => {
                Ok(RunSummary { steps: self.step, time: self.t, nodes: self.semi.mesh.n_nodes() })
            }
            Err(e) => Err(anyhow::anyhow!(e)),
        }
    }
}

/// Runs a case alone to `fluid.time.t_end` (or `max_steps`). `case_text` is echoed into
/// `run.json`.
pub fn run(case: &Case, case_text: &str, opts: &RunOptions) -> anyhow::Result<RunSummary> {
    let mut run = FluidRun::open(case, case_text, opts, Mode::Alone)?;
    let t_end = run.t_end();
    if let Err(e) = run.advance_to(t_end) {
        if !run.failed() {
            return Err(e);
        }
    }
    run.finish()
}
