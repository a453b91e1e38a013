//! The command line every participant accepts, so the launcher can start any of them the same
//! way (DESIGN §1): `<solver> run CASE [--couple RUN_ID] [--out DIR] [--set KEY=VALUE]... [--quiet]
//! [--force] [--restart DIR]`.
//! A solver flattens `RunArgs` into its own `run` subcommand and adds what only it has, and
//! offers `<solver> check CASE [--set KEY=VALUE]...` ([`CheckArgs`]): everything `run` does before
//! its first step (mesh, sets, EOS, states, probes), then exit 0, or an error naming the file,
//! line or field and exit non-zero. `fsi check` calls each participant's `check`.

use crate::case::{Case, CaseError};
use std::path::PathBuf;

/// Arguments of `run`, common to every participant.
#[derive(clap::Args, Debug, Clone)]
pub struct RunArgs {
    /// The case file.
    pub case: PathBuf,
    /// Join the coupled run RUN_ID started by `fsi`; without it the solver runs alone.
    #[arg(long, value_name = "RUN_ID")]
    pub couple: Option<String>,
    /// Output folder (default: `[output] dir` relative to the case file, else a fresh folder
    /// under runs/).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Override a case key, e.g. --set coupling.dt=1e-4 (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// No progress bar or summary.
    #[arg(long)]
    pub quiet: bool,
    /// Reuse an output folder that holds a previous run, removing that run's files first.
    /// Without it a non-empty output folder is refused (never overwritten silently).
    #[arg(long)]
    pub force: bool,
    /// Continue from a checkpoint: a run folder (its newest complete checkpoint of this
    /// participant) or one checkpoint folder `<run>/checkpoints/<tag>` (that one; what `fsi run
    /// --restart` passes each participant, the newest checkpoint both wrote). See
    /// `io::checkpoint::restart_point`.
    #[arg(long, value_name = "DIR")]
    pub restart: Option<PathBuf>,
}

/// Arguments of `check`, common to every participant.
#[derive(clap::Args, Debug, Clone)]
pub struct CheckArgs {
    /// The case file.
    pub case: PathBuf,
    /// Override a case key, as for `run` (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
}

impl CheckArgs {
    /// Reads the case with the `--set` overrides applied.
    pub fn load_case(&self) -> Result<Case, CaseError> {
        Case::load(&self.case, &self.set)
    }
}

impl RunArgs {
    /// Reads the case with the `--set` overrides applied.
    pub fn load_case(&self) -> Result<Case, CaseError> {
        Case::load(&self.case, &self.set)
    }

    /// The output folder: `--out`, else `[output] dir` relative to the case file, else `default`.
    pub fn out_dir(&self, case: &Case, default: impl FnOnce() -> PathBuf) -> PathBuf {
        self.out
            .clone()
            .or_else(|| case.output.dir.as_ref().map(|d| case.dir().join(d)))
            .unwrap_or_else(default)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        run: RunArgs,
    }

    #[test]
    fn parses_the_launcher_command_line() {
        let cli = Cli::try_parse_from([
            "x", "c.toml", "--couple", "r1", "--out", "o", "--set", "a.b=1", "--set", "c=2",
        ])
        .unwrap();
        assert_eq!(cli.run.couple.as_deref(), Some("r1"));
        assert_eq!(cli.run.out, Some(PathBuf::from("o")));
        assert_eq!(cli.run.set, ["a.b=1", "c=2"]);
        assert!(!cli.run.quiet);
        assert!(!cli.run.force);
        assert_eq!(cli.run.restart, None);
        let forced = Cli::try_parse_from(["x", "c.toml", "--force"]).unwrap();
        assert!(forced.run.force);
    }

    #[test]
    fn output_dir_prefers_the_flag_then_the_case() {
        let text = "[output]\ndir = \"out\"\n";
        let case = Case::parse(text, std::path::Path::new("cases/k/case.toml"), &[]).unwrap();
        let mut args = Cli::try_parse_from(["x", "cases/k/case.toml"]).unwrap().run;
        assert_eq!(args.out_dir(&case, || "d".into()), PathBuf::from("cases/k/out"));
        args.out = Some("o".into());
        assert_eq!(args.out_dir(&case, || "d".into()), PathBuf::from("o"));
    }
}
