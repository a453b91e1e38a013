//! `fsi check CASE`: validate a case without running it, and say what a run would do.
//!
//! The launcher checks what it reads itself (the TOML, the coupling scheme), then asks each
//! participant: `<command...> check CASE [--set K=V]...`, both at once, within
//! `coupling.timeout_s`. A participant's check does everything its `run` does before the first
//! step and exits 0, or prints its error on stderr and exits non-zero (PROTOCOL.md §7). One that
//! answers with a usage error (clap's exit code 2) offers no `check`: a warning, not a pass.

use crate::scheme::{scheme_name, SchemeSettings, Sequencer};
use crate::supervise::{case_commands, describe_exit, participant_command, signal_group};
use interface_protocol::case::Case;
use interface_protocol::messages::Role;
use std::fmt::Write;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Child, ExitStatus, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// What `fsi check` found.
#[derive(Debug, Default)]
pub struct CheckReport {
    /// The case's summary (stdout).
    pub summary: String,
    /// Sections nobody validated (stderr, `fsi: warning:`).
    pub warnings: Vec<String>,
    /// Participants that refused the case, or could not be asked (stderr, `fsi: error:`).
    pub errors: Vec<String>,
}

/// A participant's answer to `check`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Verdict {
    /// It accepted the case; what it printed on stderr (its warnings), trimmed.
    Passed { warnings: String },
    /// It answered `check` with a usage error: its section was not validated.
    NoCheck { first_line: String },
    /// Its error, verbatim (stderr), or what went wrong asking it.
    Refused(String),
}

/// The case's summary and every participant's verdict; `Err` when the case itself is invalid
/// (file:line:column, field, what was expected).
pub fn check(case_file: &Path, overrides: &[String]) -> anyhow::Result<CheckReport> {
    let case = Case::load(case_file, overrides)?;
    let s = SchemeSettings::of_case(&case);
    let seq = Sequencer::new(s).map_err(|e| anyhow::anyhow!("{}: {e}", case_file.display()))?;
    let (fluid, structure) = case_commands(&case);
    let timeout = Duration::from_secs_f64(case.coupling.timeout_s);
    let asked = ask_participants(
        [(Role::Fluid, fluid.as_slice()), (Role::Structure, structure.as_slice())],
        case_file,
        overrides,
        timeout,
    );

    let mut report = CheckReport::default();
    let mut lines = Vec::new();
    let file_name = case_file.display().to_string();
    for (role, cmd, outcome) in asked {
        let program = cmd.first().cloned().unwrap_or_default();
        // Where the case names this participant, for errors about the command itself.
        let command_key = format!("{}.command", role.name());
        let line = match outcome {
            Err(e) => {
                report.errors.push(case.field_error(&command_key, e.clone()).to_string());
                format!("(not checked: {e})")
            }
            Ok((path, verdict)) => {
                let at = path.display();
                match verdict {
                    Verdict::Passed { warnings } => {
                        if !warnings.is_empty() {
                            report.warnings.push(prefixed(role, &program, &warnings));
                        }
                        format!("({at}): check passed")
                    }
                    Verdict::NoCheck { first_line } => {
                        let warning = format!(
                            "the {} participant `{program}` offers no `check` command: its section \
                             was not validated (it answered: {first_line})",
                            role.name()
                        );
                        report.warnings.push(case.field_error(&command_key, warning).to_string());
                        format!("({at}): offers no `check` command, not validated")
                    }
                    Verdict::Refused(text) => {
                        report.errors.push(prefixed(role, &program, &text));
                        if !text.contains(&file_name) {
                            // An answer that does not name the case may not come from a `check`.
                            let context = format!(
                                "the {} participant's check failed without naming the case file; \
                                 is `{program}` a participant that offers `check`?",
                                role.name()
                            );
                            report.errors.push(case.field_error(&command_key, context).to_string());
                        }
                        format!("({at}): refused the case")
                    }
                }
            }
        };
        lines.push(format!("  {:<10} {} {line}", role.name(), cmd.join(" ")));
    }

    let w = &mut report.summary;
    let verdict = if report.errors.is_empty() { "ok" } else { "refused" };
    writeln!(w, "{}: {verdict}", case_file.display())?;
    writeln!(w, "  case       {}", case.case.name)?;
    if !case.case.description.is_empty() {
        writeln!(w, "  about      {}", case.case.description)?;
    }
    writeln!(
        w,
        "  coupling   {}, dt {:e} s, t_end {:e} s: {} steps (last {:e} s), timeout {} s",
        scheme_name(s.scheme),
        s.dt,
        s.t_end,
        s.n_steps,
        round12(seq.step_dt(s.n_steps.saturating_sub(1))),
        case.coupling.timeout_s
    )?;
    for l in lines {
        writeln!(w, "{l}")?;
    }
    let o = &case.output;
    writeln!(
        w,
        "  output     {}; fields every {}, probes every {}, checkpoints every {}",
        o.dir.as_deref().unwrap_or("runs/<case>-<timestamp>"),
        o.fields_every,
        o.probes_every,
        o.checkpoint_every
    )?;
    writeln!(w, "  case hash  {:016x}", case.hash())?;
    Ok(report)
}

/// Every line of a participant's error, prefixed by its role and program.
fn prefixed(role: Role, program: &str, text: &str) -> String {
    let lines: Vec<String> = text
        .lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| format!("{} participant {program}: {l}", role.name()))
        .collect();
    lines.join("\n")
}

/// A started `check` of one participant.
struct Asked {
    child: Child,
    stderr: mpsc::Receiver<String>,
    path: PathBuf,
    status: Option<ExitStatus>,
}

type Outcome = Result<(PathBuf, Verdict), String>;

/// Runs every participant's `check` at once; each must end within `timeout` or is killed.
fn ask_participants<'a, const N: usize>(
    participants: [(Role, &'a [String]); N],
    case_file: &Path,
    overrides: &[String],
    timeout: Duration,
) -> Vec<(Role, &'a [String], Outcome)> {
    let deadline = Instant::now() + timeout;
    let mut started: Vec<(Role, &[String], Result<Asked, String>)> = participants
        .into_iter()
        .map(|(role, cmd)| (role, cmd, start_check(role, cmd, case_file, overrides)))
        .collect();
    loop {
        let mut running = false;
        for (_, _, a) in started.iter_mut() {
            if let Ok(a) = a {
                if a.status.is_none() {
                    a.status = a.child.try_wait().ok().flatten();
                    running |= a.status.is_none();
                }
            }
        }
        if !running || Instant::now() >= deadline {
            break;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    started
        .into_iter()
        .map(|(role, cmd, a)| {
            let outcome = a.map(|a| finish_check(a, timeout));
            (role, cmd, outcome)
        })
        .collect()
}

/// Starts `<command...> check CASE [--set K=V]...` with its stderr read on a thread.
fn start_check(
    role: Role,
    command: &[String],
    case_file: &Path,
    overrides: &[String],
) -> Result<Asked, String> {
    let (_, path, mut cmd) = participant_command(role, command).map_err(|e| e.to_string())?;
    cmd.arg("check").arg(case_file);
    for o in overrides {
        cmd.arg("--set").arg(o);
    }
    cmd.stdin(Stdio::null()).stdout(Stdio::null()).stderr(Stdio::piped());
    let mut child = cmd.spawn().map_err(|e| {
        format!("cannot start the {} participant `{}`: {e}", role.name(), path.display())
    })?;
    let mut pipe = child.stderr.take().expect("stderr is piped");
    let (tx, stderr) = mpsc::channel();
    std::thread::spawn(move || {
        let mut bytes = Vec::new();
        let _ = pipe.read_to_end(&mut bytes);
        let _ = tx.send(String::from_utf8_lossy(&bytes).into_owned());
    });
    Ok(Asked { child, stderr, path, status: None })
}

/// Kills a check still running at its deadline and turns its exit into a verdict.
fn finish_check(mut a: Asked, timeout: Duration) -> (PathBuf, Verdict) {
    let status = match a.status {
        Some(s) => Ok(s),
        None => {
            signal_group(a.child.id(), libc::SIGKILL);
            let _ = a.child.wait();
            Err(format!(
                "its check did not end within {} s (coupling.timeout_s) and was killed",
                timeout.as_secs_f64()
            ))
        }
    };
    // A grandchild that outlives the check may hold the pipe open: do not wait for it forever.
    let stderr = a.stderr.recv_timeout(Duration::from_secs(1)).unwrap_or_default();
    let verdict = match status {
        Ok(s) => verdict(s, &stderr),
        Err(e) => {
            Verdict::Refused(if stderr.trim().is_empty() { e } else { format!("{stderr}\n{e}") })
        }
    };
    (a.path, verdict)
}

/// A participant's exit and stderr as a verdict: 0 passes; a usage error (exit code 2 with a
/// `Usage:` line, as clap prints for an unknown subcommand) means it offers no `check`.
pub fn verdict(status: ExitStatus, stderr: &str) -> Verdict {
    if status.success() {
        return Verdict::Passed { warnings: stderr.trim().to_string() };
    }
    if status.code() == Some(2) && stderr.contains("Usage:") {
        let first_line = stderr.lines().find(|l| !l.trim().is_empty()).unwrap_or_default();
        return Verdict::NoCheck { first_line: first_line.trim().to_string() };
    }
    let text = stderr.trim();
    Verdict::Refused(if text.is_empty() {
        format!("its check {} and printed no error", describe_exit(status))
    } else {
        text.to_string()
    })
}

/// `v` to 12 significant digits, so a last step of 1e-3 does not print as 1.0000000000000009e-3.
fn round12(v: f64) -> f64 {
    format!("{v:.11e}").parse().unwrap_or(v)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::os::unix::process::ExitStatusExt;

    fn exit(code: i32) -> ExitStatus {
        ExitStatus::from_raw(code << 8)
    }

    #[test]
    fn exits_become_verdicts() {
        assert_eq!(
            verdict(exit(0), "a warning\n"),
            Verdict::Passed { warnings: "a warning".into() }
        );
        let clap = "error: unrecognized subcommand 'check'\n\nUsage: solver <COMMAND>\n";
        assert_eq!(
            verdict(exit(2), clap),
            Verdict::NoCheck { first_line: "error: unrecognized subcommand 'check'".into() }
        );
        let refused = "solver: error: case.toml:3:1: fluid.eos.gamma: expected > 1\n";
        assert_eq!(verdict(exit(2), refused), Verdict::Refused(refused.trim().into()));
        assert_eq!(verdict(exit(1), refused), Verdict::Refused(refused.trim().into()));
        let Verdict::Refused(e) = verdict(exit(3), "") else { panic!("a silent failure passed") };
        assert!(e.contains("exited with code 3"), "{e}");
        let Verdict::Refused(e) = verdict(ExitStatus::from_raw(libc::SIGSEGV), "") else {
            panic!("a crash passed")
        };
        assert!(e.contains("SIGSEGV"), "{e}");
    }

    #[test]
    fn every_line_of_an_error_names_the_participant() {
        let text = prefixed(Role::Structure, "my-solver", "first\n\n  second\n");
        assert_eq!(
            text,
            "structure participant my-solver: first\nstructure participant my-solver:   second"
        );
    }
}
