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
use interface_protocol::cli::RunArgs;
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
    Run(RunArgs),
}

fn main() -> ExitCode {
    let Cmd::Run(args) = Cli::parse().command;
    match run(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("rigid-structure: {message}");
            ExitCode::FAILURE
        }
    }
}

fn run(args: &RunArgs) -> Result<(), String> {
    let case = args.load_case().map_err(|e| e.to_string())?;
    let out =
        args.out_dir(&case, || PathBuf::from("runs").join(format!("{}-rigid", case.case.name)));
    let mut solver = solver::RigidSolver::new(&case, out)?;
    let Some(run_id) = args.couple.as_deref() else {
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
