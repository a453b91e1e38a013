//! `structure-solver`: runs a case alone or as a coupled participant, or benches the kernels.

use clap::{Parser, Subcommand};
use interface_protocol::cli::RunArgs;

#[derive(Parser)]
#[command(
    name = "structure-solver",
    about = "Nonlinear finite-element structure solver of the FSI framework"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Runs a case alone, or coupled with `--couple RUN_ID`.
    Run {
        #[command(flatten)]
        args: RunArgs,
        /// Resume a run alone from the newest checkpoint in this run folder.
        #[arg(long)]
        restart: Option<std::path::PathBuf>,
    },
    /// Prints the explicit BT4 and implicit Newmark speeds as JSON.
    Bench {
        /// Small sizes (a smoke test, not a measurement).
        #[arg(long)]
        quick: bool,
    },
}

fn main() {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Run { args: RunArgs { couple: Some(_), .. }, restart: Some(_) } => {
            Err(anyhow::anyhow!(
                "--restart applies to runs alone; the launcher drives a coupled run from its start"
            ))
        }
        Command::Run { args: RunArgs { case, out, set, quiet, couple: Some(run_id) }, .. } => {
            structure_solver::couple::run(&case, &run_id, out, &set, quiet)
        }
        Command::Run { args: RunArgs { case, out, set, quiet, couple: None }, restart } => {
            structure_solver::run::run(&structure_solver::run::RunOptions {
                case,
                out,
                set,
                quiet,
                restart,
            })
            .map(|_| ())
        }
        Command::Bench { quick } => structure_solver::bench::run(quick).and_then(|r| {
            println!("{}", serde_json::to_string_pretty(&r)?);
            Ok(())
        }),
    };
    if let Err(e) = result {
        eprintln!("structure-solver: {e:#}");
        std::process::exit(1);
    }
}
