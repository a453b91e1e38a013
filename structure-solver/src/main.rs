//! `structure-solver`: runs a case alone or as a coupled participant, or benches the kernels.

use clap::{Parser, Subcommand};

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
    /// Runs a case alone.
    Run {
        /// The case file.
        case: std::path::PathBuf,
        /// Output folder; default `runs/<case>-<timestamp>`.
        #[arg(long)]
        out: Option<std::path::PathBuf>,
        /// Overrides `key=value` applied to the case.
        #[arg(long = "set")]
        set: Vec<String>,
        /// No summary line.
        #[arg(long)]
        quiet: bool,
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
        Command::Run { case, out, set, quiet } => {
            structure_solver::run::run(&structure_solver::run::RunOptions { case, out, set, quiet })
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
