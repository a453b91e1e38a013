//! `rigid-structure`: a rigid body on springs and dampers (1 to 6 DOF, optional prescribed
//! motion) that speaks the coupling protocol; the alternative structure participant of DESIGN §1.
//! Depends on `interface-protocol` only (no hdf5).
//!
//! - `rigid-structure run CASE [--couple RUN_ID] [--out DIR] [--set key=value]... [--force]`:
//!   coupled, it answers the launcher's commands in the launcher's folder; alone, it integrates
//!   with zero fluid load into a fresh folder (a non-empty one only with `--force`).
//! - `rigid-structure check CASE [--set key=value]...`: everything `run` does before the first
//!   step, then a one-line summary; creates no file.

mod finite;
mod model;
mod setup;
mod solver;

use clap::{Parser, Subcommand};
use interface_protocol::case::Case;
use interface_protocol::cli::{CheckArgs, RunArgs};
use interface_protocol::endpoint::{StructureEndpoint, Timeouts};
use interface_protocol::handshake::HelloInfo;
use interface_protocol::io::outdir::{OutputDir, Policy};
use interface_protocol::messages::capability;
use interface_protocol::participant::serve;
use setup::Setup;
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
    /// Check a case as `run` would before its first step, then exit.
    Check(CheckArgs),
}

fn main() -> ExitCode {
    let result = match Cli::parse().command {
        Cmd::Run(args) => run(&args),
        Cmd::Check(args) => check(&args).map(|summary| println!("rigid-structure: {summary}")),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("rigid-structure: {message}");
            ExitCode::FAILURE
        }
    }
}

/// The case and its setup: what `run` and `check` share.
fn prepare(
    case: Result<Case, interface_protocol::case::CaseError>,
) -> Result<(Case, Setup), String> {
    let case = case.map_err(|e| e.to_string())?;
    let setup = Setup::new(&case)?;
    Ok((case, setup))
}

fn check(args: &CheckArgs) -> Result<String, String> {
    let (case, setup) = prepare(args.load_case())?;
    if let Some(w) = setup.unstable_step_warning() {
        eprintln!("rigid-structure: warning: {w}");
    }
    Ok(setup.summary(&case))
}

fn run(args: &RunArgs) -> Result<(), String> {
    let (case, setup) = prepare(args.load_case())?;
    let dir =
        args.out_dir(&case, || PathBuf::from("runs").join(format!("{}-rigid", case.case.name)));
    // Coupled, the launcher made the folder; alone, the folder rule of every binary.
    let policy =
        if args.couple.is_some() { Policy::Existing } else { Policy::from_force(args.force) };
    let out = OutputDir::create(dir, policy).map_err(|e| e.to_string())?;
    let (dt, n_steps, t_end) = (setup.dt, setup.n_steps, setup.t_end);
    let n_elements = setup.body.elements.len() as u64;
    let mut solver = match (&args.restart, &args.couple) {
        (Some(dir), Some(_)) => solver::RigidSolver::resumed(setup, out, dir)?,
        (Some(_), None) => {
            return Err("--restart continues a coupled run (`fsi run --restart`); a rigid \
                        structure alone runs from its start"
                .into())
        }
        (None, _) => solver::RigidSolver::new(setup, out)?,
    };
    let Some(run_id) = args.couple.as_deref() else {
        return solver.run_alone(dt, n_steps, t_end).map_err(|f| f.message);
    };
    let info = HelloInfo {
        n_surface_nodes: solver.n_nodes() as u64,
        n_surface_elements: n_elements,
        case_hash: case.hash(),
        capabilities: capability::RESTART | capability::INTERFACE_WORK,
    };
    let mut endpoint =
        StructureEndpoint::open(run_id, info, Timeouts::from_secs(case.coupling.timeout_s))
            .map_err(|e| format!("cannot join run {run_id}: {e}"))?;
    let result = serve(&mut endpoint, &mut solver);
    // Ports and node go before the process does, whatever happened.
    drop(endpoint);
    result.map_err(|e| format!("run {run_id} stopped: {e}"))
}
