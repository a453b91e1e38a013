//! `hello-stub`: a participant that publishes one crafted `Hello` and then answers nothing, for
//! the launcher's handshake tests (a protocol version or a node count the peers disagree on).
//!
//! `hello-stub --role fluid|structure [--protocol-version N] [--nodes N] run <case> --couple <id>
//! --out <dir> [--set k=v]...`: the case hash is computed from the case like a real participant.
//! It exits on SIGTERM/SIGINT or when the launcher is gone, like any participant.

use clap::Parser;
use interface_protocol::case::Case;
use interface_protocol::handshake::HelloInfo;
use interface_protocol::liveness::{Watch, POLL_SLICE};
use interface_protocol::messages::{Hello, Role, PROTOCOL_VERSION};
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
    let watch = Watch::from_env();
    let case = Case::load(&args.case, &args.overrides)?;
    let info = HelloInfo { n_surface_nodes: args.nodes, n_surface_elements: 0, case_hash: case.hash() };
    let hello = Hello { protocol_version: args.protocol_version, ..info.hello(role) };

    let run_id = &args.couple;
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
            eprintln!("hello-stub: stopping: {stop:?}");
            return Ok(());
        }
        std::thread::sleep(POLL_SLICE);
    }
}
