//! `fake-participant`: a participant that misbehaves on purpose, for the launcher's tests.
//!
//! `fake-participant --role fluid|structure [MODE] run <case> --couple <id> --out <dir>
//! [--set k=v]...`, the case hash computed from the case like a real participant. Modes:
//! - `--protocol-version N` / `--nodes N`: publishes one crafted `Hello` and answers nothing;
//! - `--fail-init MESSAGE`: joins through the real endpoint and answers `Init` with
//!   `Failed { message }`, then serves the rest of the sequence as a no-op.
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
    let info =
        HelloInfo { n_surface_nodes: args.nodes, n_surface_elements: 0, case_hash: case.hash() };
    match &args.fail_init {
        Some(message) => fail_init(role, &args.couple, info, &case, message),
        None => crafted_hello(role, &args.couple, info, args.protocol_version),
    }
}

/// Answers `Init` with `Failed`, everything else with `Done`.
struct FailInit(String);

impl<E> Handler<E> for FailInit {
    fn init(&mut self, _: &mut E) -> Result<f64, Failure> {
        Err(Failure::new(failure_code::SOLVER, self.0.clone()))
    }
    fn advance(&mut self, _: &mut E, c: &Command) -> Result<Progress, Failure> {
        Ok(Progress { step: c.step, t: c.t_to, dt_stable: f64::INFINITY })
    }
    fn checkpoint(&mut self, _: &mut E, _: &str) -> Result<(), Failure> {
        Ok(())
    }
    fn finish(&mut self, _: &mut E) -> Result<(), Failure> {
        Ok(())
    }
}

fn fail_init(
    role: Role,
    run_id: &str,
    info: HelloInfo,
    case: &Case,
    message: &str,
) -> anyhow::Result<()> {
    let timeouts = Timeouts::from_secs(case.coupling.timeout_s);
    let mut handler = FailInit(message.to_string());
    fn go<E: ControlPort>(mut ep: E, h: &mut FailInit) -> anyhow::Result<()> {
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
