//! `fsi run`: one coupled run from start to `run.json` (DESIGN §1, §3, §7).
//!
//! The launcher opens the run's services, starts both participants, waits for and checks their
//! `Hello`s, then sends the scheme's commands one by one. Every wait is cut into slices of
//! [`SLICE`]; between slices it polls both children and its own termination signals, so a dead
//! participant, a silent one, Ctrl-C, SIGTERM or SIGHUP ends the run within about a second, with
//! both children gone, the run's shared memory removed and `run.json` saying why.
//!
//! The run id is claimed first ([`shm::RunLock`]): a second launcher given the same id is refused
//! before it touches anything of the live run.

use crate::scheme::{scheme_name, Progress, SchemeError, SchemeSettings, Sequencer};
use crate::supervise::{Death, LaunchArgs, Participant, Participants, SpawnError};
use interface_protocol::case::Case;
use interface_protocol::endpoint::{LauncherLink, ProtocolError, Timeouts};
use interface_protocol::io::outdir::{default_run_dir, OutputDir, Policy};
use interface_protocol::io::progress::Progress as Bar;
use interface_protocol::io::report::{self, case_echo, RunReport};
use interface_protocol::liveness;
use interface_protocol::messages::{capability, Command, Hello, Reply, Role};
use interface_protocol::shm;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

/// Longest wait between two checks of the children and of signals.
pub const SLICE: Duration = Duration::from_millis(20);

/// After a failure, how long to look for a child death that explains it.
const DEATH_GRACE: Duration = Duration::from_millis(300);

/// What `fsi run` was asked to do.
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    pub case_file: PathBuf,
    pub out: Option<PathBuf>,
    pub overrides: Vec<String>,
    pub quiet: bool,
    pub force: bool,
    /// Run id (services and shared-memory files); generated when `None`.
    pub run_id: Option<String>,
    /// Continue the run in this folder from its newest common checkpoint ([`crate::restart`]);
    /// the folder is the output folder.
    pub restart: Option<PathBuf>,
}

/// Why a run stopped early.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    #[error("{0}")]
    Case(#[from] interface_protocol::case::CaseError),
    #[error("{0}")]
    Scheme(#[from] SchemeError),
    #[error("{0}")]
    Setup(String),
    #[error("{0}")]
    Spawn(#[from] SpawnError),
    #[error("{death} before the run finished{}", waiting.as_deref().map(|w| format!(", while waiting for {w}")).unwrap_or_default())]
    Died { death: Death, waiting: Option<String> },
    #[error("{who} did not {what} within {timeout_s} s (coupling.timeout_s){note}")]
    Silent { who: String, what: String, timeout_s: f64, note: String },
    #[error("{0}")]
    Protocol(#[from] ProtocolError),
    #[error("stopped by {}", crate::supervise::signal_name(*.0))]
    Interrupted(i32),
    #[error("after Finish: {0}")]
    BadExit(String),
}

impl RunError {
    /// Process exit code: 128 + signal when interrupted, 1 otherwise.
    pub fn exit_code(&self) -> i32 {
        match self {
            RunError::Interrupted(sig) => 128 + sig,
            _ => 1,
        }
    }
}

/// Per-participant totals of the `Done` replies, and the `(t, interface_work)` of the last two
/// from a participant that announces [`capability::INTERFACE_WORK`] (`None` otherwise).
#[derive(Debug, Clone, Copy, Default)]
struct SolverTime {
    work_s: f64,
    wait_s: f64,
    interface_work: Option<[(f64, f64); 2]>,
}

impl SolverTime {
    /// The participant's interface work at `t`, linear through its last two samples: the
    /// staggered schemes leave the fluid half a step from the structure (C0 ahead, A6 behind),
    /// and the line through the last two brings both to one time within O(Δt²).
    fn interface_work_at(&self, t: f64) -> Option<f64> {
        let [(ta, wa), (tb, wb)] = self.interface_work?;
        Some(if tb > ta { wb + (t - tb) / (tb - ta) * (wb - wa) } else { wb })
    }
}

/// What `run.json` holds beyond the common report.
#[derive(Debug, Serialize)]
struct LauncherReport<'a> {
    #[serde(flatten)]
    report: &'a RunReport,
    run_id: &'a str,
    scheme: String,
    dt: f64,
    t_end: f64,
    overrides: &'a [String],
    coupling_overhead: Overhead,
    #[serde(skip_serializing_if = "Option::is_none")]
    interface_energy: Option<InterfaceEnergy>,
}

/// The energy ledger of the interface (PROTOCOL.md §3, `interface_work`): the work the fluid's
/// loads did along the surface motion it was given, the work the structure's applied loads did
/// along its own displacement, both from t = 0 to the last reply, and their difference, the
/// energy the staggered scheme created at the interface (zero for an exact coupling).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
struct InterfaceEnergy {
    fluid_work: f64,
    structure_work: f64,
    /// `fluid_work - structure_work` (J).
    error: f64,
    /// `error / max(|fluid_work|, |structure_work|)` (0 when both are 0).
    relative: f64,
}

impl InterfaceEnergy {
    /// The ledger at the run's end time `t` when both participants keep it.
    fn of(solver: &BTreeMap<&'static str, SolverTime>, t: f64) -> Option<InterfaceEnergy> {
        let work = |role: Role| solver.get(role.name()).and_then(|s| s.interface_work_at(t));
        let (fluid_work, structure_work) = (work(Role::Fluid)?, work(Role::Structure)?);
        let error = fluid_work - structure_work;
        let scale = fluid_work.abs().max(structure_work.abs());
        let relative = if scale > 0.0 { error / scale } else { 0.0 };
        Some(InterfaceEnergy { fluid_work, structure_work, error, relative })
    }
}

/// The launcher's cost: the stepping wall time (from the end of start-up to the exits) that
/// neither participant reports as work. The staggered schemes run the two solvers one after the
/// other, so that wall time is their work plus this overhead (sequencing, IPC latency, wake-ups).
#[derive(Debug, Serialize)]
struct Overhead {
    /// Wall seconds after start-up (processes started, `Hello` exchanged).
    stepping_seconds: f64,
    /// Of those, the seconds in neither participant's reported work.
    seconds: f64,
    /// `seconds / stepping_seconds` (0 for a run that never stepped).
    fraction: f64,
}

impl Overhead {
    fn of(stepping: f64, solver: &BTreeMap<&'static str, SolverTime>) -> Overhead {
        let work: f64 = solver.values().map(|t| t.work_s).sum();
        let seconds = (stepping - work).max(0.0);
        let fraction = if stepping > 0.0 { seconds / stepping } else { 0.0 };
        Overhead { stepping_seconds: stepping, seconds, fraction }
    }
}

/// A fresh run id: `r<pid>-<nanoseconds>` in hex (unique per process and instant).
pub fn new_run_id() -> String {
    let nanos = SystemTime::now().duration_since(UNIX_EPOCH).map(|d| d.as_nanos()).unwrap_or(0);
    format!("r{:x}-{:x}", std::process::id(), nanos as u64)
}

/// Result of a completed run.
#[derive(Debug)]
pub struct RunSummary {
    pub out_dir: PathBuf,
    pub steps: u64,
    pub wall: Duration,
}

/// The live state of one run.
struct Session<'a> {
    link: Option<LauncherLink>,
    children: Participants,
    timeout: Duration,
    timeout_s: f64,
    ipc_wait: Duration,
    /// From the start of `fsi` to both `Hello`s checked.
    startup: Duration,
    solver: BTreeMap<&'static str, SolverTime>,
    bar: &'a mut Bar,
    /// `<out>/checkpoints`, where the launcher writes its part of each checkpoint.
    checkpoints: PathBuf,
    /// A restart: both participants must announce the capability.
    restart: bool,
}

/// Runs a case; `run.json` is written in the output folder whether the run completes or not.
pub fn run(opts: &RunOptions) -> Result<RunSummary, RunError> {
    let start = Instant::now();
    liveness::install_signal_handlers();
    let case = Case::load(&opts.case_file, &opts.overrides)?;
    let settings = SchemeSettings::of_case(&case);
    let resume = match &opts.restart {
        Some(dir) => {
            Some(crate::restart::common_checkpoint(dir, &settings).map_err(RunError::Setup)?)
        }
        None => None,
    };
    let mut seq = match &resume {
        Some(found) => Sequencer::resume(settings, found.step)?,
        None => Sequencer::new(settings)?,
    };
    let (fluid_cmd, structure_cmd) = crate::supervise::case_commands(&case);

    let run_id = opts.run_id.clone().unwrap_or_else(new_run_id);
    interface_protocol::services::validate_run_id(&run_id)?;
    // Before anything is created or removed: a live run with this id stays untouched.
    let _claim = shm::RunLock::acquire(&run_id)?;
    let dir = match (&opts.restart, &opts.out, &case.output.dir) {
        (Some(d), _, _) | (None, Some(d), _) => d.clone(),
        // Relative to the case file, as the participants read it.
        (None, None, Some(d)) => case.dir().join(d),
        (None, None, None) => default_run_dir(&opts.case_file, SystemTime::now()),
    };
    // A restart continues the run in its own folder: the explicit request to write there.
    let policy = if resume.is_some() { Policy::Existing } else { Policy::from_force(opts.force) };
    let out = OutputDir::create(&dir, policy).map_err(|e| RunError::Setup(e.to_string()))?;
    let out_dir = std::fs::canonicalize(out.path()).unwrap_or_else(|_| out.path().to_path_buf());
    let case_file =
        std::fs::canonicalize(&opts.case_file).unwrap_or_else(|_| opts.case_file.clone());

    let mut bar = Bar::new(settings.t_end, opts.quiet);
    let from = match &resume {
        Some(f) => format!(", continued from {} at t = {:e}", f.tag, f.time),
        None => String::new(),
    };
    bar.println(&format!(
        "fsi: run {run_id}: {} ({}, dt {:e}, {} steps{from}) -> {}",
        case.case.name,
        scheme_name(settings.scheme),
        settings.dt,
        settings.n_steps,
        out_dir.display()
    ));
    let mut session = Session {
        link: None,
        children: Participants::default(),
        timeout: Duration::from_secs_f64(case.coupling.timeout_s),
        timeout_s: case.coupling.timeout_s,
        ipc_wait: Duration::ZERO,
        startup: Duration::ZERO,
        solver: BTreeMap::new(),
        bar: &mut bar,
        checkpoints: out_dir.join("checkpoints"),
        restart: resume.is_some(),
    };
    let args = LaunchArgs {
        case_file: &case_file,
        run_id: &run_id,
        out_dir: &out_dir,
        overrides: &opts.overrides,
        restart: resume.as_ref().map(|f| f.dir.as_path()),
    };
    let mut steps = resume.as_ref().map_or(0, |f| f.step);
    let result = session
        .start(&run_id, &args, &structure_cmd, &fluid_cmd, case.hash())
        .and_then(|()| {
            session.startup = start.elapsed();
            session.drive(&mut seq, &mut steps)
        })
        .and_then(|()| session.wait_exits());
    let result = match result {
        Err(e) => Err(session.explain(e)),
        ok => ok,
    };
    session.children.stop_all();
    let cleaned = match session.link.take() {
        Some(link) => link.remove_resources(),
        None => shm::cleanup_run(&run_id),
    };
    let launcher = [("startup", session.startup), ("ipc_wait", session.ipc_wait)];
    let solver = session.solver.clone();
    let startup = session.startup;
    drop(session);
    let wall = start.elapsed();
    let overhead = Overhead::of(wall.saturating_sub(startup).as_secs_f64(), &solver);
    let status = match (&result, &cleaned) {
        (Err(e @ RunError::Interrupted(_)), _) => format!("interrupted: {e}"),
        (Err(e), _) => format!("failed: {e}"),
        (Ok(()), Err(e)) => format!("completed, but the run's shared memory was not removed: {e}"),
        (Ok(()), Ok(_)) => "completed".to_string(),
    };
    let final_time = if steps == 0 { 0.0 } else { seq.time(steps) };
    let reported = write_report(
        &out,
        &case,
        opts,
        &run_id,
        &status,
        (steps, final_time),
        Measured {
            wall,
            launcher,
            solver: &solver,
            coupling_overhead: overhead,
            interface_energy: InterfaceEnergy::of(&solver, final_time),
        },
    );
    bar.finish();
    result?;
    cleaned?;
    reported
        .map_err(|e| RunError::Setup(format!("cannot write {}: {e}", out.run_json().display())))?;
    Ok(RunSummary { out_dir, steps, wall })
}

impl Session<'_> {
    /// Opens the link, starts both children, waits for and checks their `Hello`s.
    fn start(
        &mut self,
        run_id: &str,
        args: &LaunchArgs,
        structure_cmd: &[String],
        fluid_cmd: &[String],
        case_hash: u64,
    ) -> Result<(), RunError> {
        self.link = Some(LauncherLink::open(run_id, Timeouts::from_secs(self.timeout_s))?);
        self.children.push(Participant::spawn(Role::Structure, structure_cmd, args)?);
        self.children.push(Participant::spawn(Role::Fluid, fluid_cmd, args)?);
        let deadline = Instant::now() + self.timeout;
        let structure = self.hello(Role::Structure, deadline)?;
        let fluid = self.hello(Role::Fluid, deadline)?;
        LauncherLink::check(&fluid, &structure, case_hash)?;
        for (role, hello) in [(Role::Fluid, &fluid), (Role::Structure, &structure)] {
            let keeps = hello.capabilities & capability::INTERFACE_WORK != 0;
            self.solver.entry(role.name()).or_default().interface_work =
                keeps.then_some([(0.0, 0.0); 2]);
        }
        if self.restart {
            let label = |role| self.children.get(role).map_or(role.name().into(), |p| p.label());
            let labels = [label(Role::Fluid), label(Role::Structure)];
            crate::restart::check_capable(&fluid, &structure, labels).map_err(RunError::Setup)?;
        }
        Ok(())
    }

    fn hello(&mut self, role: Role, deadline: Instant) -> Result<Hello, RunError> {
        let what = "send its Hello (is it a coupling participant?)".to_string();
        self.in_slices(role, deadline, what, |link, until| link.wait_hello(role, until))
    }

    /// Sends the scheme's commands until both participants acknowledged `Finish`.
    fn drive(&mut self, seq: &mut Sequencer, steps: &mut u64) -> Result<(), RunError> {
        while let Some((role, cmd)) = seq.next_command() {
            let reply = self.command(role, &cmd)?;
            let progress = match seq.accept(role, &reply) {
                Err(e @ SchemeError::Failed { .. }) => {
                    self.finish_after_failure(role, cmd.kind);
                    return Err(e.into());
                }
                other => other?,
            };
            self.account(role, &reply);
            use interface_protocol::messages::command_kind::{CHECKPOINT, FINISH};
            if cmd.kind == FINISH {
                self.children.release(role);
            }
            // The fluid answers a checkpoint after the structure: the launcher's part completes it.
            if cmd.kind == CHECKPOINT && role == Role::Fluid {
                let at = (cmd.step, cmd.t_from);
                crate::restart::write_part(&self.checkpoints, &cmd.tag_str(), at, seq.settings())
                    .map_err(|e| RunError::Setup(e.to_string()))?;
            }
            match progress {
                Progress::StepDone { step, t } => {
                    *steps = step + 1;
                    self.bar.update(step + 1, t, seq.step_dt(step));
                }
                Progress::Finished | Progress::Continue => {}
            }
        }
        Ok(())
    }

    /// Sends one command and waits for its reply (deadline `coupling.timeout_s`).
    fn command(&mut self, role: Role, cmd: &Command) -> Result<Reply, RunError> {
        self.check_alive()?;
        let link = self.link.as_mut().expect("the link is open while commands are sent");
        link.send(role, cmd)?;
        let deadline = Instant::now() + self.timeout;
        let what = format!("answer {}", cmd.describe());
        let waited = Instant::now();
        let reply =
            self.in_slices(role, deadline, what, |link, until| link.wait_reply(role, until));
        self.ipc_wait += waited.elapsed();
        reply
    }

    /// After `failed` answered `Failed` to a command of `kind`: `Finish` to the other participant
    /// (unless it finished already), then to the failed one (unless `Finish` is what failed), so
    /// that both flush their outputs and exit; best effort. The failed one may also just exit.
    fn finish_after_failure(&mut self, failed: Role, kind: u32) {
        use interface_protocol::messages::command_kind::FINISH;
        self.children.release(failed);
        let other = if failed == Role::Fluid { Role::Structure } else { Role::Fluid };
        if !self.children.is_released(other) && self.command(other, &Command::finish()).is_ok() {
            self.children.release(other);
        }
        if kind != FINISH {
            let _ = self.command(failed, &Command::finish());
        }
        self.children.wait_all(Instant::now() + Duration::from_secs(1));
    }

    /// Adds a `Done` reply's timings to the participant's totals.
    fn account(&mut self, role: Role, reply: &Reply) {
        let t = self.solver.entry(role.name()).or_default();
        t.work_s += reply.work_s.max(0.0);
        t.wait_s += reply.wait_s.max(0.0);
        if let Some([older, last]) = &mut t.interface_work {
            if reply.t > last.0 {
                *older = *last;
            }
            *last = (reply.t, reply.interface_work);
        }
    }

    /// After `Finish`: every child exits, with code 0, within `coupling.timeout_s`.
    fn wait_exits(&mut self) -> Result<(), RunError> {
        let deadline = Instant::now() + self.timeout;
        loop {
            self.check_signal()?;
            let running = self.children.wait_all(Instant::now() + SLICE);
            if running.is_empty() {
                break;
            }
            if Instant::now() >= deadline {
                let who: Vec<String> = running.iter().map(|p| p.label()).collect();
                return Err(RunError::Silent {
                    who: who.join(" and "),
                    what: "exit after Finish".into(),
                    timeout_s: self.timeout_s,
                    note: String::new(),
                });
            }
        }
        let bad: Vec<String> = self
            .children
            .exits()
            .into_iter()
            .filter(|(_, _, s)| !s.success())
            .map(|(_, label, s)| format!("{label} {}", crate::supervise::describe_exit(s)))
            .collect();
        if bad.is_empty() {
            Ok(())
        } else {
            Err(RunError::BadExit(bad.join("; ")))
        }
    }

    fn check_signal(&self) -> Result<(), RunError> {
        match liveness::termination_signal() {
            Some(sig) => Err(RunError::Interrupted(sig)),
            None => Ok(()),
        }
    }

    fn check_alive(&mut self) -> Result<(), RunError> {
        self.check_signal()?;
        match self.children.first_dead() {
            Some(death) => Err(RunError::Died { death, waiting: None }),
            None => Ok(()),
        }
    }

    /// Calls `wait` with deadlines of at most `SLICE` until it yields or `deadline` passes,
    /// checking signals and both children between slices. `role` is who is awaited.
    fn in_slices<T>(
        &mut self,
        role: Role,
        deadline: Instant,
        what: String,
        mut wait: impl FnMut(&mut LauncherLink, Instant) -> Result<T, ProtocolError>,
    ) -> Result<T, RunError> {
        let who = self.children.get(role).map_or_else(
            || role.name().to_string(),
            |p| format!("the {} participant {}", role.name(), p.label()),
        );
        loop {
            // Read first, then look for deaths: a participant may answer and exit at once (after
            // `Finish`), and its answer must not be lost to its exit.
            let now = Instant::now();
            let link = self.link.as_mut().expect("the link is open while waiting");
            match wait(link, (now + SLICE).min(deadline)) {
                Ok(v) => return Ok(v),
                Err(ProtocolError::Timeout { .. }) => {}
                Err(ProtocolError::Terminated { signal }) => {
                    return Err(RunError::Interrupted(signal))
                }
                Err(e) => return Err(e.into()),
            }
            // A death ends the wait; so does the exit of an awaited participant that was
            // released (it failed) and will not answer.
            let death = match self.check_alive() {
                Err(RunError::Died { death, .. }) => Some(death),
                other => {
                    other?;
                    self.children.exited(role)
                }
            };
            if let Some(death) = death {
                if death.role == role {
                    // Its answer, sent just before it exited, may have arrived since the read.
                    let link = self.link.as_mut().expect("the link is open while waiting");
                    if let Ok(v) = wait(link, Instant::now()) {
                        return Ok(v);
                    }
                }
                let waiting = (death.role != role).then(|| format!("{who} to {what}"));
                return Err(RunError::Died { death, waiting });
            }
            if Instant::now() >= deadline {
                let note =
                    self.children.get(role).and_then(|p| p.stopped_note()).unwrap_or_default();
                return Err(RunError::Silent { who, what, timeout_s: self.timeout_s, note });
            }
        }
    }

    /// A wire error (a command that cannot be delivered, a reply that cannot come) right after a
    /// child died is explained by the death: report that. The launcher's own verdicts stand.
    fn explain(&mut self, e: RunError) -> RunError {
        if !matches!(e, RunError::Protocol(_)) {
            return e;
        }
        let until = Instant::now() + DEATH_GRACE;
        loop {
            if let Some(d) = self.children.first_dead() {
                return RunError::Died { death: d, waiting: None };
            }
            if Instant::now() >= until {
                return e;
            }
            std::thread::sleep(Duration::from_millis(5));
        }
    }
}

/// The run's clocks and energy ledger as `run.json` reports them.
struct Measured<'a> {
    wall: Duration,
    /// The launcher's own buckets (start-up, IPC wait).
    launcher: [(&'static str, Duration); 2],
    solver: &'a BTreeMap<&'static str, SolverTime>,
    coupling_overhead: Overhead,
    interface_energy: Option<InterfaceEnergy>,
}

/// Writes `run.json`: the common report plus the launcher's view (run id, scheme, overrides).
fn write_report(
    out: &OutputDir,
    case: &Case,
    opts: &RunOptions,
    run_id: &str,
    status: &str,
    (steps, final_time): (u64, f64),
    Measured { wall, launcher, solver, coupling_overhead, interface_energy }: Measured,
) -> std::io::Result<()> {
    let text = std::fs::read_to_string(&opts.case_file).unwrap_or_default();
    let mut versions = report::versions();
    versions.insert("coupler-scripts".into(), env!("CARGO_PKG_VERSION").into());
    let mut timings = BTreeMap::new();
    for (role, t) in solver {
        timings.insert(
            role.to_string(),
            BTreeMap::from([("work".to_string(), t.work_s), ("ipc_wait".to_string(), t.wait_s)]),
        );
    }
    let mut own: BTreeMap<String, f64> =
        launcher.iter().map(|(name, d)| (name.to_string(), d.as_secs_f64())).collect();
    own.insert("total".to_string(), wall.as_secs_f64());
    timings.insert("launcher".to_string(), own);
    let report = RunReport {
        case_file: opts.case_file.display().to_string(),
        case: case_echo(&text).unwrap_or(serde_json::Value::Null),
        versions,
        status: status.to_string(),
        steps,
        final_time,
        counts: BTreeMap::from([("coupling_steps".to_string(), case.coupling.n_steps())]),
        wall_seconds: wall.as_secs_f64(),
        timings,
        surface: None,
    };
    let full = LauncherReport {
        coupling_overhead,
        interface_energy,
        report: &report,
        run_id,
        scheme: scheme_name(case.coupling.scheme).to_string(),
        dt: case.coupling.dt,
        t_end: case.coupling.t_end,
        overrides: &opts.overrides,
    };
    interface_protocol::io::atomic::write_atomic(&out.run_json(), |w| {
        serde_json::to_writer_pretty(&mut *w, &full).map_err(std::io::Error::other)?;
        std::io::Write::write_all(w, b"\n")
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_overhead_is_the_stepping_time_neither_solver_worked() {
        let solver = BTreeMap::from([
            ("fluid", SolverTime { work_s: 6.0, wait_s: 3.5, interface_work: None }),
            ("structure", SolverTime { work_s: 3.0, wait_s: 6.5, interface_work: None }),
        ]);
        let o = Overhead::of(10.0, &solver);
        assert_eq!((o.seconds, o.fraction), (1.0, 0.1));
        // Clock skew between the processes never makes it negative; no stepping, no fraction.
        assert_eq!(Overhead::of(8.0, &solver).seconds, 0.0);
        assert_eq!(Overhead::of(0.0, &BTreeMap::new()).fraction, 0.0);
    }

    #[test]
    fn the_interface_energy_needs_both_ledgers() {
        let with = |f: Option<[(f64, f64); 2]>, s: Option<[(f64, f64); 2]>| {
            let t = |w| SolverTime { work_s: 1.0, wait_s: 0.0, interface_work: w };
            InterfaceEnergy::of(&BTreeMap::from([("fluid", t(f)), ("structure", t(s))]), 1.0)
        };
        // The fluid half a step ahead (samples at 0.75 and 1.25) is read at 1.0 on its line.
        let e = with(Some([(0.75, 1.0), (1.25, 3.0)]), Some([(0.5, 0.0), (1.0, 1.5)])).unwrap();
        assert_eq!((e.fluid_work, e.structure_work), (2.0, 1.5));
        assert_eq!((e.error, e.relative), (0.5, 0.25));
        let at_rest = Some([(0.0, 0.0); 2]);
        assert_eq!(with(at_rest, at_rest).unwrap().relative, 0.0);
        assert!(with(at_rest, None).is_none() && with(None, at_rest).is_none());
    }

    #[test]
    fn generated_run_ids_are_valid_and_distinct() {
        let a = new_run_id();
        std::thread::sleep(Duration::from_millis(1));
        let b = new_run_id();
        assert_ne!(a, b);
        for id in [a, b] {
            interface_protocol::services::validate_run_id(&id).unwrap();
        }
    }

    #[test]
    fn a_death_says_what_the_launcher_was_waiting_for() {
        let death = Death {
            role: Role::Structure,
            label: "rigid-structure (structure, pid 7)".into(),
            how: "exited with code 1".into(),
        };
        let e = RunError::Died {
            death,
            waiting: Some("the fluid participant piston-fluid to answer Init".into()),
        };
        assert_eq!(
            e.to_string(),
            "the structure participant rigid-structure (structure, pid 7) exited with code 1 before \
             the run finished, while waiting for the fluid participant piston-fluid to answer Init"
        );
        assert_eq!(e.exit_code(), 1);
        assert_eq!(RunError::Interrupted(libc::SIGINT).exit_code(), 130);
    }

    #[test]
    fn bad_cases_fail_before_anything_is_created() {
        let dir = tempfile::tempdir().unwrap();
        let case = dir.path().join("case.toml");
        std::fs::write(&case, "[coupling]\ndt = 0\n").unwrap();
        let out = dir.path().join("out");
        let opts = RunOptions { case_file: case, out: Some(out.clone()), ..RunOptions::default() };
        let e = run(&opts).unwrap_err().to_string();
        assert!(e.contains("case.toml:2:") && e.contains("coupling.dt"), "{e}");
        assert!(!out.exists());
        let opts = RunOptions { run_id: Some("bad_id".into()), ..opts };
        std::fs::write(&opts.case_file, "[coupling]\ndt = 1e-3\n").unwrap();
        let e = run(&opts).unwrap_err().to_string();
        assert!(e.contains("invalid run id"), "{e}");
        assert!(!out.exists());
    }
}
