//! `rigid-structure`: a rigid body on springs and dampers (1 to 6 DOF, optional prescribed
//! motion) that speaks the coupling protocol; the alternative structure participant of DESIGN §1.
//! Depends on `interface-protocol` only.
//!
//! `rigid-structure run CASE [--couple RUN_ID] [--out DIR] [--set key=value]...`: coupled, it
//! answers the launcher's commands; alone, it integrates with zero fluid load.

mod model;
mod probes;
mod solver;

use clap::{Parser, Subcommand};
use interface_protocol::case::Case;
use interface_protocol::endpoint::{StructureEndpoint, Timeouts};
use interface_protocol::handshake::HelloInfo;
use interface_protocol::participant::serve;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "rigid-structure",
    version,
    about = "Rigid-body structure participant of the FSI protocol"
)]
struct Cli {
    #[command(subcommand)]
    command: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Run a case: coupled with --couple RUN_ID, alone (zero fluid load) otherwise.
    Run {
        case: PathBuf,
        /// Join the coupled run RUN_ID started by the launcher.
        #[arg(long)]
        couple: Option<String>,
        /// Output folder (default: the case's output.dir, else runs/<case>-rigid).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Override a case value, e.g. --set coupling.dt=1e-4.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
    },
}

fn main() -> ExitCode {
    let Cmd::Run { case, couple, out, set } = Cli::parse().command;
    match run(&case, couple.as_deref(), out, &set) {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("rigid-structure: {message}");
            ExitCode::FAILURE
        }
    }
}

fn run(
    case_path: &std::path::Path,
    couple: Option<&str>,
    out: Option<PathBuf>,
    set: &[String],
) -> Result<(), String> {
    let case = Case::load(case_path, set).map_err(|e| e.to_string())?;
    let out = out
        .or_else(|| case.output.dir.as_ref().map(|d| case.dir().join(d)))
        .unwrap_or_else(|| PathBuf::from("runs").join(format!("{}-rigid", case.case.name)));
    let mut solver = solver::RigidSolver::new(&case, out)?;
    let Some(run_id) = couple else {
        let c = &case.coupling;
        return solver.run_alone(c.dt, c.n_steps(), c.t_end).map_err(|f| f.message);
    };
    let info = HelloInfo {
        n_surface_nodes: solver.n_nodes() as u64,
        n_surface_elements: solver.body.elements.len() as u64,
        case_hash: case.hash(),
    };
    let mut endpoint =
        StructureEndpoint::open(run_id, info, Timeouts::from_secs(case.coupling.timeout_s))
            .map_err(|e| format!("cannot join run {run_id}: {e}"))?;
    let result = serve(&mut endpoint, &mut solver);
    // Ports and node go before the process does, whatever happened.
    drop(endpoint);
    result.map_err(|e| format!("run {run_id} stopped: {e}"))
}
