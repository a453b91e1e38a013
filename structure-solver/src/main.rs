//! `structure-solver`: runs a case alone or as a coupled participant, checks a case without
//! running it, or benches the kernels.

use clap::{Parser, Subcommand};
use interface_protocol::cli::{CheckArgs, RunArgs};

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
    },
    /// Does everything `run` does before the first step (mesh and its checks, sets, parts,
    /// BCs, loads, probes, the stable step; coupled cases: the wet surface), prints a summary
    /// and exits; nothing is written.
    Check {
        #[command(flatten)]
        args: CheckArgs,
    },
    /// Prints the explicit BT4 and implicit Newmark speeds as JSON.
    Bench {
        /// Small sizes (a smoke test, not a measurement).
        #[arg(long)]
        quick: bool,
        /// Elements of the explicit BT4 plate (about; a square grid).
        #[arg(long, default_value_t = 100_000)]
        elements: usize,
        /// Thread counts of the explicit bench.
        #[arg(long, value_delimiter = ',', default_value = "1,2")]
        threads: Vec<usize>,
    },
}

/// Warnings of this solver and of the shared crate (a damaged checkpoint skipped) on stderr.
fn log_warnings() {
    use tracing_subscriber::filter::{LevelFilter, Targets};
    use tracing_subscriber::prelude::*;
    let targets = Targets::new()
        .with_target("structure_solver", LevelFilter::WARN)
        .with_target("interface_protocol", LevelFilter::WARN);
    let layer = tracing_subscriber::fmt::layer()
        .with_writer(std::io::stderr)
        .without_time()
        .with_target(false);
    tracing_subscriber::registry().with(layer.with_filter(targets)).init();
}

fn main() {
    let cli = Cli::parse();
    log_warnings();
    let result = match cli.command {
        Command::Run {
            args: RunArgs { case, out, set, quiet, couple: Some(run_id), restart, .. },
        } => structure_solver::couple::run(&case, &run_id, out, &set, quiet, restart.as_deref()),
        Command::Run { args: RunArgs { case, out, set, quiet, force, couple: None, restart } } => {
            structure_solver::run::run(&structure_solver::run::RunOptions {
                case,
                out,
                set,
                quiet,
                force,
                restart,
            })
            .map(|_| ())
        }
        Command::Check { args } => args
            .load_case()
            .map_err(anyhow::Error::from)
            .and_then(|case| structure_solver::check::check(&case))
            .map(|summary| print!("{summary}")),
        Command::Bench { quick, elements, threads } => {
            structure_solver::bench::run(quick, elements, &threads).and_then(|r| {
                println!("{}", serde_json::to_string_pretty(&r)?);
                Ok(())
            })
        }
    };
    if let Err(e) = result {
        eprintln!("structure-solver: {e:#}");
        std::process::exit(1);
    }
}
