//! `fsi`: starts the two solvers of a case, supervises them and sequences the coupling scheme.

use clap::{Parser, Subcommand};
use coupler_scripts::run::{run, RunOptions};
use coupler_scripts::{check, plot};
use std::path::PathBuf;
use std::process::ExitCode;

/// Fluid-structure interaction launcher (FIVER).
#[derive(Debug, Parser)]
#[command(name = "fsi", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Cmd,
}

#[derive(Debug, Subcommand)]
enum Cmd {
    /// Runs a coupled case: starts both participants and drives the coupling scheme.
    Run {
        /// The case file (TOML).
        case: PathBuf,
        /// Output folder (default: the case's output.dir, relative to the case file, else
        /// runs/<case>-<timestamp>).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Overrides a case key, e.g. --set coupling.dt=1e-4 (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        overrides: Vec<String>,
        /// No progress bar and no messages but errors.
        #[arg(long)]
        quiet: bool,
        /// Reuse a non-empty output folder, removing the previous run's files.
        #[arg(long)]
        force: bool,
        /// Run id naming the run's shared memory (default: generated; for scripts and tests).
        #[arg(long)]
        run_id: Option<String>,
        /// Continue the run in folder DIR from its newest checkpoint that both participants
        /// wrote completely; outputs go on in DIR (probe files keep their rows up to the
        /// checkpoint). The case and --set overrides must be the run's; coupling.t_end may grow.
        #[arg(long, value_name = "DIR", conflicts_with_all = ["out", "force"])]
        restart: Option<PathBuf>,
    },
    /// Validates a case without running it: the launcher's keys, then each participant's own
    /// `check` (mesh, sets, EOS, states, probes).
    Check {
        /// The case file (TOML).
        case: PathBuf,
        /// Overrides a case key, as for `run`.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        overrides: Vec<String>,
    },
    /// Benchmarks; prints JSON on stdout.
    Bench {
        #[command(subcommand)]
        what: BenchCmd,
    },
    /// Writes PNG plots of a run folder's probe files into DIR/plots.
    Plot {
        /// A run folder (holding probes.csv and/or structure_probes.csv).
        dir: PathBuf,
        /// A history to draw beside a probe column: COLUMN=FILE, the file a CSV of time and
        /// value (`#` lines are comments), e.g. tip.ux=cases/shock-panel/m2c-tip.csv.
        #[arg(long = "reference", value_name = "COLUMN=FILE")]
        references: Vec<String>,
    },
}

#[derive(Debug, Subcommand)]
enum BenchCmd {
    /// Round trip of kinematics out and loads back over shared memory (and a Unix socket for
    /// comparison) at 1e3 to 1e6 wet nodes.
    Ipc,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.command {
        Cmd::Run { case, out, overrides, quiet, force, run_id, restart } => {
            let opts =
                RunOptions { case_file: case, out, overrides, quiet, force, run_id, restart };
            match run(&opts) {
                Ok(s) => {
                    if !quiet {
                        eprintln!(
                            "fsi: completed {} steps in {:.2} s; outputs in {}",
                            s.steps,
                            s.wall.as_secs_f64(),
                            s.out_dir.display()
                        );
                    }
                    ExitCode::SUCCESS
                }
                Err(e) => {
                    eprintln!("fsi: error: {e}");
                    ExitCode::from(e.exit_code().clamp(1, 255) as u8)
                }
            }
        }
        Cmd::Check { case, overrides } => match check::check(&case, &overrides) {
            Ok(report) => {
                print!("{}", report.summary);
                for w in &report.warnings {
                    eprintln!("fsi: warning: {w}");
                }
                for e in &report.errors {
                    eprintln!("fsi: error: {e}");
                }
                if report.errors.is_empty() {
                    ExitCode::SUCCESS
                } else {
                    ExitCode::from(2)
                }
            }
            Err(e) => {
                eprintln!("fsi: error: {e}");
                ExitCode::from(2)
            }
        },
        Cmd::Bench { what: BenchCmd::Ipc } => {
            let run_id = coupler_scripts::run::new_run_id();
            let result =
                interface_protocol::bench::run(&run_id, &interface_protocol::bench::DEFAULT_SIZES)
                    .map_err(|e| e.to_string())
                    .and_then(|b| serde_json::to_string_pretty(&b).map_err(|e| e.to_string()));
            match result {
                Ok(json) => {
                    println!("{json}");
                    ExitCode::SUCCESS
                }
                Err(e) => {
                    eprintln!("fsi: error: bench ipc: {e}");
                    ExitCode::FAILURE
                }
            }
        }
        Cmd::Plot { dir, references } => match references
            .iter()
            .map(|r| plot::Reference::parse(r))
            .collect::<anyhow::Result<Vec<_>>>()
            .and_then(|r| plot::plot_dir(&dir, &r))
        {
            Ok(files) => {
                for f in files {
                    println!("{}", f.display());
                }
                ExitCode::SUCCESS
            }
            Err(e) => {
                eprintln!("fsi: error: {e}");
                ExitCode::FAILURE
            }
        },
    }
}
