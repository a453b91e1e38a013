//! `fluid-solver`: runs a case alone (`run`) or as the fluid of a coupled run (`run --couple`),
//! checks a case without running it (`check`), or measures its speed (`bench`).

use clap::{Parser, Subcommand};
use fluid_solver::{bench, bench_bubble, bench_embedded, check, couple, solver};
use interface_protocol::cli::{CheckArgs, RunArgs};
use interface_protocol::io::outdir;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::SystemTime;

#[derive(Parser)]
#[command(
    name = "fluid-solver",
    version,
    about = "Compressible Euler solver of FIVER (vertex-centred FV)"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a case's fluid: alone, or coupled with --couple RUN_ID (started by `fsi run`).
    Run {
        #[command(flatten)]
        args: RunArgs,
    },
    /// Set a case up as `run` would (mesh, boundaries, EOS, states, probes, lines, time step),
    /// print a summary and exit without running or writing anything.
    Check {
        #[command(flatten)]
        args: CheckArgs,
    },
    /// Measure node-steps per second per core of RK2 + MUSCL + Roe on a tet box (one and two
    /// materials) and of the level-set case `cases/underwater-bubble` (key `level_set`); prints
    /// JSON.
    Bench {
        /// Approximate number of nodes.
        #[arg(long, default_value_t = 200_000)]
        nodes: usize,
        /// RK2 steps per measurement.
        #[arg(long, default_value_t = 10)]
        steps: usize,
        /// Thread counts to measure, comma-separated.
        #[arg(long, value_delimiter = ',', default_value = "1,2")]
        threads: Vec<usize>,
        /// Also write the edge-loop arrays to this file for the C reference loop
        /// (fluid-solver/bench/run-c-reference.sh).
        #[arg(long, value_name = "FILE")]
        dump_edges: Option<PathBuf>,
        /// Also measure the embedded boundary (tracking, wall fluxes, memory): key `embedded`.
        #[arg(long)]
        embedded: bool,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Run { args } => run(&args),
        Command::Check { args } => args.load_case().map_err(anyhow::Error::from).and_then(|case| {
            let checked = check::check(&case)?;
            print!("{}", checked.summary);
            for w in &checked.warnings {
                eprintln!("fluid-solver: warning: {w}");
            }
            Ok(())
        }),
        Command::Bench { nodes, steps, threads, dump_edges, embedded } => {
            bench::run(nodes, steps, &threads, dump_edges.as_deref()).and_then(|report| {
                let mut json = serde_json::to_value(&report)?;
                json["level_set"] =
                    serde_json::to_value(bench_bubble::run(nodes, steps, &threads)?)?;
                if embedded {
                    json["embedded"] =
                        serde_json::to_value(bench_embedded::run(nodes, steps, &report)?)?;
                }
                println!("{}", serde_json::to_string_pretty(&json)?);
                Ok(())
            })
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("fluid-solver: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn run(args: &RunArgs) -> anyhow::Result<()> {
    let case = args.load_case()?;
    let text = std::fs::read_to_string(&args.case)?;
    let out = args.out_dir(&case, || outdir::default_run_dir(&args.case, SystemTime::now()));
    let quiet = args.quiet;
    let restart = args.restart.clone();
    let opts = solver::RunOptions { out: out.clone(), quiet, restart, force: args.force };
    if let Some(run_id) = &args.couple {
        return couple::run(&case, &text, opts, run_id);
    }
    let summary = solver::run(&case, &text, &opts)?;
    if !quiet {
        eprintln!(
            "fluid-solver: {} steps to t = {:e} on {} nodes; outputs in {}",
            summary.steps,
            summary.time,
            summary.nodes,
            out.display()
        );
    }
    Ok(())
}
