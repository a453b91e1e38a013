//! `fluid-solver`: runs a case alone (`run`), or measures its speed (`bench`).

use clap::{Parser, Subcommand};
use fluid_solver::{bench, solver};
use interface_protocol::case::Case;
use interface_protocol::io::outdir;
use std::path::PathBuf;
use std::process::ExitCode;

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
    /// Run a case's fluid alone.
    Run {
        /// The case file.
        case: PathBuf,
        /// Output folder (default: `[output] dir`, else runs/<case>-<timestamp>).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Override a case key, e.g. --set fluid.time.t_end=0.1 (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// Continue from the newest checkpoint of this previous run folder.
        #[arg(long)]
        restart: Option<PathBuf>,
        /// No progress bar or messages.
        #[arg(long)]
        quiet: bool,
        /// Overwrite the previous run's files in the output folder.
        #[arg(long)]
        force: bool,
        /// Run as the fluid participant of a coupled run.
        #[arg(long, value_name = "RUN_ID")]
        couple: Option<String>,
    },
    /// Measure node-steps per second per core of RK2 + MUSCL + Roe on a tet box; prints JSON.
    Bench {
        /// Approximate number of nodes.
        #[arg(long, default_value_t = 200_000)]
        nodes: usize,
        /// RK2 steps per measurement.
        #[arg(long, default_value_t = 10)]
        steps: usize,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Run { case, out, set, restart, quiet, force, couple } => {
            if couple.is_some() {
                Err(anyhow::anyhow!(
                    "coupling not available: this build of fluid-solver runs cases alone (drop --couple)"
                ))
            } else {
                run(case, out, set, restart, quiet, force)
            }
        }
        Command::Bench { nodes, steps } => bench::run(nodes, steps).map(|report| {
            println!("{}", serde_json::to_string_pretty(&report).expect("JSON"));
        }),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("fluid-solver: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn run(
    case_file: PathBuf,
    out: Option<PathBuf>,
    set: Vec<String>,
    restart: Option<PathBuf>,
    quiet: bool,
    force: bool,
) -> anyhow::Result<()> {
    let case = Case::load(&case_file, &set)?;
    let text = std::fs::read_to_string(&case_file)?;
    let out = out
        .or_else(|| case.output.dir.as_ref().map(PathBuf::from))
        .unwrap_or_else(|| outdir::default_run_dir(&case_file, std::time::SystemTime::now()));
    let opts = solver::RunOptions { out: out.clone(), quiet, restart, force };
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
