//! `fake-participant`: a participant that misbehaves on purpose, for the launcher's tests.
//!
//! `fake-participant --role fluid|structure [MODE] run <case> --couple <id> --out <dir>
//! [--set k=v]...`, the case hash computed from the case like a real participant. Modes:
//! - `--protocol-version N` / `--nodes N`: publishes one crafted `Hello` and answers nothing;
//! - `--fail-init MESSAGE`: joins through the real endpoint and answers `Init` with
//!   `Failed { message }`, then serves the rest of the sequence as a no-op;
//! - `--fail MESSAGE --fail-on init|start|predict|advance|correct|checkpoint|finish
//!   [--fail-step K]`: the same, failing the first such command of step K (default 0;
//!   `advance` is the fluid's phase-NONE advance);
//! - `--serve`: joins and answers every command as a no-op (the peer of a scripted failure).
//!
//! Serving, it publishes and reads no surface data: pair it with another fake participant.
//!
//! It exits on SIGTERM/SIGINT or when the launcher is gone, like any participant.

use clap::Parser;
use interface_protocol::case::Case;
use interface_protocol::endpoint::{ControlPort, FluidEndpoint, StructureEndpoint, Timeouts};
use interface_protocol::handshake::HelloInfo;
use interface_protocol::liveness::{Watch, POLL_SLICE};
use interface_protocol::messages::{Command, Hello, Role, PROTOCOL_VERSION};
use interface_protocol::participant::{failure_code, serve, Failure, Handler, Progress};
use interface_protocol::services;
use std::path::PathBuf;

#[derive(Debug, Parser)]
struct Args {
    #[arg(long)]
    role: String,
    #[arg(long, default_value_t = PROTOCOL_VERSION)]
    protocol_version: u32,
    #[arg(long, default_value_t = 1)]
    nodes: u64,
    #[arg(long)]
    fail_init: Option<String>,
    #[arg(long)]
    fail: Option<String>,
    #[arg(long, default_value = "init")]
    fail_on: String,
    #[arg(long, default_value_t = 0)]
    fail_step: u64,
    #[arg(long)]
    serve: bool,
    /// `run`, as every participant is started.
    verb: String,
    case: PathBuf,
    #[arg(long)]
    couple: String,
    #[arg(long)]
    out: PathBuf,
    #[arg(long = "set")]
    overrides: Vec<String>,
}

fn main() -> anyhow::Result<()> {
    let args = Args::parse();
    anyhow::ensure!(args.verb == "run", "expected `run`, got `{}`", args.verb);
    let role = match args.role.as_str() {
        "fluid" => Role::Fluid,
        "structure" => Role::Structure,
        r => anyhow::bail!("--role: expected fluid or structure, got {r}"),
    };
    let case = Case::load(&args.case, &args.overrides)?;
    let info = HelloInfo {
        n_surface_nodes: args.nodes,
        n_surface_elements: 0,
        case_hash: case.hash(),
        capabilities: 0,
    };
    let fail = match (args.fail_init, args.fail) {
        (Some(message), _) => Some((When::parse("init", 0)?, message)),
        (None, Some(message)) => Some((When::parse(&args.fail_on, args.fail_step)?, message)),
        (None, None) => None,
    };
    if fail.is_none() && !args.serve {
        return crafted_hello(role, &args.couple, info, args.protocol_version);
    }
    scripted(role, &args.couple, info, &case, Scripted { fail, steps: 0 })
}

/// The command a scripted participant fails: its kind, the advance's phase, the step.
#[derive(Debug, Clone, Copy, PartialEq)]
struct When {
    kind: u32,
    phase: Option<u32>,
    step: u64,
}

impl When {
    fn parse(on: &str, step: u64) -> anyhow::Result<When> {
        use interface_protocol::messages::{command_kind as k, scheme_phase as p};
        let (kind, phase) = match on {
            "init" => (k::INIT, None),
            "start" => (k::ADVANCE, Some(p::START)),
            "predict" => (k::ADVANCE, Some(p::PREDICT)),
            "advance" => (k::ADVANCE, Some(p::NONE)),
            "correct" => (k::ADVANCE, Some(p::CORRECT)),
            "checkpoint" => (k::CHECKPOINT, None),
            "finish" => (k::FINISH, None),
            other => anyhow::bail!(
                "--fail-on: expected init, start, predict, advance, correct, checkpoint or \
                 finish, got `{other}`"
            ),
        };
        Ok(When { kind, phase, step })
    }
}

/// Answers every command with `Done` (`Ready` for `Init`), but `Failed` at the scripted one.
struct Scripted {
    fail: Option<(When, String)>,
    /// Steps completed (a checkpoint after k steps is the checkpoint of step k).
    steps: u64,
}

impl Scripted {
    /// `step`: `None` for `Init` and `Finish`, which happen once whatever the step.
    fn answer(&self, kind: u32, phase: u32, step: Option<u64>) -> Result<(), Failure> {
        match &self.fail {
            Some((w, message))
                if w.kind == kind
                    && w.phase.is_none_or(|p| p == phase)
                    && step.is_none_or(|s| s == w.step) =>
            {
                Err(Failure::new(failure_code::SOLVER, message.clone()))
            }
            _ => Ok(()),
        }
    }
}

impl<E> Handler<E> for Scripted {
    fn init(&mut self, _: &mut E) -> Result<f64, Failure> {
        use interface_protocol::messages::command_kind::INIT;
        self.answer(INIT, 0, None).map(|()| f64::INFINITY)
    }
    fn advance(&mut self, _: &mut E, c: &Command) -> Result<Progress, Failure> {
        use interface_protocol::messages::scheme_phase::START;
        self.answer(c.kind, c.scheme_phase, Some(c.step))?;
        if c.scheme_phase != START {
            self.steps = c.step + 1;
        }
        Ok(Progress { step: c.step, t: c.t_to, dt_stable: f64::INFINITY, interface_work: 0.0 })
    }
    fn checkpoint(&mut self, _: &mut E, _: &str) -> Result<(), Failure> {
        use interface_protocol::messages::command_kind::CHECKPOINT;
        self.answer(CHECKPOINT, 0, Some(self.steps))
    }
    fn finish(&mut self, _: &mut E) -> Result<(), Failure> {
        use interface_protocol::messages::command_kind::FINISH;
        self.answer(FINISH, 0, None)
    }
}

fn scripted(
    role: Role,
    run_id: &str,
    info: HelloInfo,
    case: &Case,
    mut handler: Scripted,
) -> anyhow::Result<()> {
    let timeouts = Timeouts::from_secs(case.coupling.timeout_s);
    fn go<E: ControlPort>(mut ep: E, h: &mut Scripted) -> anyhow::Result<()> {
        serve(&mut ep, h).map_err(|e| anyhow::anyhow!("{e}"))
    }
    match role {
        Role::Fluid => go(FluidEndpoint::open(run_id, info, timeouts)?, &mut handler),
        Role::Structure => go(StructureEndpoint::open(run_id, info, timeouts)?, &mut handler),
    }
}

/// Publishes `info`'s `Hello` with `protocol_version`, then idles until stopped.
fn crafted_hello(
    role: Role,
    run_id: &str,
    info: HelloInfo,
    protocol_version: u32,
) -> anyhow::Result<()> {
    let watch = Watch::from_env();
    let hello = Hello { protocol_version, ..info.hello(role) };
    let node = services::node(run_id, role.name())?;
    // The settings of the hello service, as every participant opens it.
    let service = node
        .service_builder(&services::service_name(run_id, &services::hello(role))?)
        .publish_subscribe::<Hello>()
        .history_size(1)
        .subscriber_max_buffer_size(1)
        .enable_safe_overflow(true)
        .open_or_create()
        .map_err(|e| anyhow::anyhow!("cannot open the hello service: {e:?}"))?;
    let publisher = service
        .publisher_builder()
        .create()
        .map_err(|e| anyhow::anyhow!("cannot create the hello publisher: {e:?}"))?;
    publisher.send_copy(hello).map_err(|e| anyhow::anyhow!("cannot publish the hello: {e:?}"))?;
    loop {
        use iceoryx2::port::update_connections::UpdateConnections;
        // Delivers the history to a launcher that subscribes late.
        let _ = publisher.update_connections();
        if let Err(stop) = watch.check() {
            eprintln!("fake-participant: stopping: {stop:?}");
            return Ok(());
        }
        std::thread::sleep(POLL_SLICE);
    }
}
