//! The two participant processes: started as children of `fsi`, watched in every wait slice, and
//! stopped together (DESIGN §3, liveness).
//!
//! Each child runs in its own process group (a terminal's Ctrl-C reaches `fsi` alone, which then
//! stops the children in order) and asks the kernel for SIGTERM when `fsi` dies
//! (`PR_SET_PDEATHSIG`). A child is stopped with SIGTERM (and SIGCONT, should it be stopped),
//! then SIGKILL after [`KILL_GRACE`].

use interface_protocol::case::Case;
use interface_protocol::liveness::LAUNCHER_PID_ENV;
use interface_protocol::messages::Role;
use std::os::unix::process::{CommandExt, ExitStatusExt};
use std::path::{Path, PathBuf};
use std::process::{Child, ExitStatus};
use std::time::{Duration, Instant};

/// How long a child may take to exit after SIGTERM before it gets SIGKILL.
pub const KILL_GRACE: Duration = Duration::from_secs(1);

/// Why a participant could not be started.
#[derive(Debug, thiserror::Error)]
pub enum SpawnError {
    #[error("[{section}] command is empty: expected e.g. command = [\"{default}\"]")]
    EmptyCommand { section: &'static str, default: &'static str },
    #[error("{role} participant `{program}` not found next to {exe_dir} or on PATH ([{role}] command in the case)")]
    NotFound { role: &'static str, program: String, exe_dir: String },
    #[error("cannot start the {role} participant `{program}`: {source}")]
    Spawn { role: &'static str, program: String, source: std::io::Error },
}

/// Where to look for a bare program name: the folder of the running `fsi`, then `PATH`.
/// A name with a `/` is taken as given (relative to the current folder).
/// The fluid's and the structure's commands of a case (`fluid-solver`, `structure-solver` when
/// a section does not name one).
pub fn case_commands(case: &Case) -> (Vec<String>, Vec<String>) {
    let fluid =
        case.fluid.as_ref().map(|f| f.command()).unwrap_or_else(|| vec!["fluid-solver".into()]);
    let structure = case
        .structure
        .as_ref()
        .map(|s| s.command())
        .unwrap_or_else(|| vec!["structure-solver".into()]);
    (fluid, structure)
}

pub fn resolve_program(name: &str, role: Role) -> Result<PathBuf, SpawnError> {
    if name.contains('/') {
        return Ok(PathBuf::from(name));
    }
    let exe_dir = std::env::current_exe().ok().and_then(|p| p.parent().map(Path::to_path_buf));
    let path_dirs = std::env::var_os("PATH").map(|p| std::env::split_paths(&p).collect::<Vec<_>>());
    let candidates = exe_dir.iter().cloned().chain(path_dirs.into_iter().flatten());
    for dir in candidates {
        let p = dir.join(name);
        if is_executable(&p) {
            return Ok(p);
        }
    }
    Err(SpawnError::NotFound {
        role: role.name(),
        program: name.to_string(),
        exe_dir: exe_dir.map_or_else(|| "fsi".into(), |d| d.display().to_string()),
    })
}

fn is_executable(p: &Path) -> bool {
    use std::os::unix::fs::PermissionsExt;
    std::fs::metadata(p).is_ok_and(|m| m.is_file() && m.permissions().mode() & 0o111 != 0)
}

/// What a participant is started with, after its own command words.
#[derive(Debug, Clone)]
pub struct LaunchArgs<'a> {
    pub case_file: &'a Path,
    pub run_id: &'a str,
    pub out_dir: &'a Path,
    pub overrides: &'a [String],
    /// A restart: the checkpoint folder each participant continues from (`--restart`).
    pub restart: Option<&'a Path>,
}

/// One running participant.
#[derive(Debug)]
pub struct Participant {
    pub role: Role,
    /// The program as the case names it, for messages.
    pub program: String,
    child: Child,
    exit: Option<ExitStatus>,
    /// The run no longer needs it (it answered `Finish`, or failed): its exit is not a death.
    released: bool,
}

/// The participant's program with its own command words, in its own process group and asking
/// for SIGTERM when `fsi` dies; the caller adds the verb and its arguments.
pub fn participant_command(
    role: Role,
    command: &[String],
) -> Result<(String, PathBuf, std::process::Command), SpawnError> {
    let (name, extra) = command.split_first().ok_or(SpawnError::EmptyCommand {
        section: role.name(),
        default: if role == Role::Fluid { "fluid-solver" } else { "structure-solver" },
    })?;
    let program = resolve_program(name, role)?;
    let mut cmd = std::process::Command::new(&program);
    cmd.args(extra);
    let launcher = std::process::id();
    cmd.process_group(0);
    // SAFETY: the closure runs in the forked child before exec and calls only `prctl` and
    // `getppid`, both async-signal-safe; it allocates nothing and touches no lock.
    unsafe {
        cmd.pre_exec(move || {
            if libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGTERM as libc::c_ulong, 0, 0, 0) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            // The launcher died between fork and prctl: the signal would never come.
            if libc::getppid() as u32 != launcher {
                return Err(std::io::Error::other("the launcher exited during start-up"));
            }
            Ok(())
        });
    }
    Ok((name.clone(), program, cmd))
}

/// Sends `signal` to the process group `pgid` (a child started by `participant_command`, and
/// anything it started). Call it only for a child not reaped yet, whose pid cannot be reused.
pub fn signal_group(pgid: u32, signal: libc::c_int) {
    // SAFETY: `killpg` only sends a signal; the group is the child's own (process_group(0)), and
    // the caller guarantees the child is not reaped yet.
    unsafe {
        libc::killpg(pgid as libc::pid_t, signal);
    }
}

impl Participant {
    /// Starts `command` (the case's `[<role>] command`) as
    /// `<command...> run <case> --couple <run_id> --out <dir> [--set k=v]... [--restart ckpt]`.
    pub fn spawn(role: Role, command: &[String], args: &LaunchArgs) -> Result<Self, SpawnError> {
        let (name, program, mut cmd) = participant_command(role, command)?;
        cmd.arg("run")
            .arg(args.case_file)
            .arg("--couple")
            .arg(args.run_id)
            .arg("--out")
            .arg(args.out_dir);
        for o in args.overrides {
            cmd.arg("--set").arg(o);
        }
        if let Some(dir) = args.restart {
            cmd.arg("--restart").arg(dir);
        }
        cmd.env(LAUNCHER_PID_ENV, std::process::id().to_string());
        let child = cmd.spawn().map_err(|source| SpawnError::Spawn {
            role: role.name(),
            program: program.display().to_string(),
            source,
        })?;
        Ok(Participant { role, program: name, child, exit: None, released: false })
    }

    pub fn pid(&self) -> u32 {
        self.child.id()
    }

    /// The exit status if the child has ended (non-blocking `waitpid`).
    pub fn poll(&mut self) -> Option<ExitStatus> {
        if self.exit.is_none() {
            self.exit = self.child.try_wait().ok().flatten();
        }
        self.exit
    }

    /// Sends `signal` to the child's process group (the child and anything it started).
    fn signal(&self, signal: libc::c_int) {
        if self.exit.is_none() {
            signal_group(self.child.id(), signal);
        }
    }

    /// "; its process is stopped (SIGSTOP or a debugger)" when the kernel says so, for the message
    /// about a participant that did not answer.
    pub fn stopped_note(&self) -> Option<String> {
        let stat = std::fs::read_to_string(format!("/proc/{}/stat", self.pid())).ok()?;
        // The state follows the parenthesised command name.
        let state = stat.rsplit(')').next()?.split_whitespace().next()?;
        matches!(state, "T" | "t")
            .then(|| "; its process is stopped (SIGSTOP or a debugger)".into())
    }

    /// "rigid-structure (structure, pid 123)".
    pub fn label(&self) -> String {
        format!("{} ({}, pid {})", self.program, self.role.name(), self.pid())
    }
}

/// "exited with code 3", "killed by SIGKILL (signal 9)".
pub fn describe_exit(status: ExitStatus) -> String {
    match (status.code(), status.signal()) {
        (Some(code), _) => format!("exited with code {code}"),
        (None, Some(sig)) => format!("killed by {} (signal {sig})", signal_name(sig)),
        _ => format!("ended ({status})"),
    }
}

/// The conventional name of a signal number.
pub fn signal_name(sig: i32) -> String {
    let name = match sig {
        libc::SIGHUP => "SIGHUP",
        libc::SIGINT => "SIGINT",
        libc::SIGQUIT => "SIGQUIT",
        libc::SIGILL => "SIGILL",
        libc::SIGABRT => "SIGABRT",
        libc::SIGBUS => "SIGBUS",
        libc::SIGFPE => "SIGFPE",
        libc::SIGKILL => "SIGKILL",
        libc::SIGSEGV => "SIGSEGV",
        libc::SIGPIPE => "SIGPIPE",
        libc::SIGALRM => "SIGALRM",
        libc::SIGTERM => "SIGTERM",
        _ => return format!("signal {sig}"),
    };
    name.to_string()
}

/// Both participants of a run.
#[derive(Debug, Default)]
pub struct Participants {
    list: Vec<Participant>,
}

/// A participant that ended before the run let it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Death {
    pub role: Role,
    pub label: String,
    pub how: String,
}

impl std::fmt::Display for Death {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "the {} participant {} {}", self.role.name(), self.label, self.how)
    }
}

impl Participants {
    pub fn push(&mut self, p: Participant) {
        self.list.push(p);
    }

    pub fn get(&self, role: Role) -> Option<&Participant> {
        self.list.iter().find(|p| p.role == role)
    }

    /// Whether the participant of `role` was released (it finished, or failed).
    pub fn is_released(&self, role: Role) -> bool {
        self.list.iter().any(|p| p.role == role && p.released)
    }

    /// Lets the participant of `role` exit from now on without that counting as a death.
    pub fn release(&mut self, role: Role) {
        self.list.iter_mut().filter(|p| p.role == role).for_each(|p| p.released = true);
    }

    /// The first participant found to have ended before it was released, if any (each call polls
    /// every child).
    pub fn first_dead(&mut self) -> Option<Death> {
        let mut dead = None;
        for p in &mut self.list {
            if let (Some(status), false) = (p.poll(), p.released) {
                dead.get_or_insert(Death {
                    role: p.role,
                    label: p.label(),
                    how: describe_exit(status),
                });
            }
        }
        dead
    }

    /// How the participant of `role` ended, if it did (released or not).
    pub fn exited(&mut self, role: Role) -> Option<Death> {
        let p = self.list.iter_mut().find(|p| p.role == role)?;
        let status = p.poll()?;
        Some(Death { role, label: p.label(), how: describe_exit(status) })
    }

    /// Waits until every child has exited, until `deadline`; returns the ones still running.
    pub fn wait_all(&mut self, deadline: Instant) -> Vec<&Participant> {
        loop {
            let running = self.list.iter_mut().map(|p| p.poll()).filter(Option::is_none).count();
            if running == 0 || Instant::now() >= deadline {
                break;
            }
            std::thread::sleep(Duration::from_millis(5));
        }
        self.list.iter().filter(|p| p.exit.is_none()).collect()
    }

    /// Exit statuses of the children that have ended.
    pub fn exits(&mut self) -> Vec<(Role, String, ExitStatus)> {
        self.list.iter_mut().filter_map(|p| p.poll().map(|s| (p.role, p.label(), s))).collect()
    }

    /// Stops every running child: SIGTERM (and SIGCONT), SIGKILL after `KILL_GRACE`, and reaps
    /// them. Returns within about `KILL_GRACE` plus the time the kernel takes to deliver SIGKILL.
    pub fn stop_all(&mut self) {
        for p in &mut self.list {
            if p.poll().is_none() {
                p.signal(libc::SIGTERM);
                p.signal(libc::SIGCONT);
            }
        }
        if !self.wait_all(Instant::now() + KILL_GRACE).is_empty() {
            for p in &mut self.list {
                if p.poll().is_none() {
                    p.signal(libc::SIGKILL);
                }
            }
            self.wait_all(Instant::now() + Duration::from_secs(1));
        }
    }
}

impl Drop for Participants {
    fn drop(&mut self) {
        self.stop_all();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args<'a>(dir: &'a Path, overrides: &'a [String]) -> LaunchArgs<'a> {
        LaunchArgs {
            case_file: Path::new("case.toml"),
            run_id: "t1",
            out_dir: dir,
            overrides,
            restart: None,
        }
    }

    #[test]
    fn bare_names_resolve_on_path_and_missing_ones_are_named() {
        assert!(resolve_program("sh", Role::Fluid).unwrap().is_absolute());
        let e = resolve_program("no-such-solver-xyz", Role::Structure).unwrap_err().to_string();
        assert!(e.contains("no-such-solver-xyz") && e.contains("structure"), "{e}");
        let e = Participant::spawn(Role::Fluid, &[], &args(Path::new("."), &[])).unwrap_err();
        assert!(e.to_string().contains("[fluid] command is empty"), "{e}");
    }

    #[test]
    fn participants_get_the_agreed_arguments() {
        let dir = tempfile::tempdir().unwrap();
        let log = dir.path().join("args");
        let script = format!("printf '%s\\n' \"$@\" > {}", log.display());
        let cmd = vec!["sh".into(), "-c".into(), script, "sh".into()];
        let sets = vec!["coupling.dt=1e-3".to_string()];
        let mut ps = Participants::default();
        ps.push(Participant::spawn(Role::Fluid, &cmd, &args(dir.path(), &sets)).unwrap());
        assert!(ps.wait_all(Instant::now() + Duration::from_secs(5)).is_empty());
        let got = std::fs::read_to_string(&log).unwrap();
        let want = format!(
            "run\ncase.toml\n--couple\nt1\n--out\n{}\n--set\ncoupling.dt=1e-3\n",
            dir.path().display()
        );
        assert_eq!(got, want);
        assert_eq!(ps.exits()[0].2.code(), Some(0));
    }

    #[test]
    fn a_killed_child_is_reported_with_its_signal() {
        let dir = tempfile::tempdir().unwrap();
        let cmd = vec!["sh".into(), "-c".into(), "exit 3".into(), "sh".into()];
        let mut ps = Participants::default();
        ps.push(Participant::spawn(Role::Structure, &cmd, &args(dir.path(), &[])).unwrap());
        let start = Instant::now();
        let death = loop {
            if let Some(d) = ps.first_dead() {
                break d;
            }
            assert!(start.elapsed() < Duration::from_secs(5));
            std::thread::sleep(Duration::from_millis(5));
        };
        assert_eq!(death.role, Role::Structure);
        assert!(death.how.contains("exited with code 3"), "{death}");

        let cmd = vec!["sh".into(), "-c".into(), "sleep 30".into(), "sh".into()];
        let mut ps = Participants::default();
        ps.push(Participant::spawn(Role::Fluid, &cmd, &args(dir.path(), &[])).unwrap());
        let pid = ps.get(Role::Fluid).unwrap().pid() as i32;
        // SAFETY: sends SIGKILL to the child started just above.
        unsafe { libc::kill(pid, libc::SIGKILL) };
        let death = loop {
            if let Some(d) = ps.first_dead() {
                break d;
            }
            std::thread::sleep(Duration::from_millis(5));
        };
        assert!(death.to_string().contains("killed by SIGKILL (signal 9)"), "{death}");
        assert!(death.to_string().contains("fluid"), "{death}");
    }

    #[test]
    fn stop_all_ends_a_stopped_child_and_its_group_quickly() {
        let dir = tempfile::tempdir().unwrap();
        // The shell ignores SIGTERM, so only SIGKILL after the grace ends it; its `sleep` child
        // goes with the group.
        let cmd =
            vec!["sh".into(), "-c".into(), "trap '' TERM; sleep 30; sleep 30".into(), "sh".into()];
        let mut ps = Participants::default();
        ps.push(Participant::spawn(Role::Fluid, &cmd, &args(dir.path(), &[])).unwrap());
        let pid = ps.get(Role::Fluid).unwrap().pid() as i32;
        std::thread::sleep(Duration::from_millis(100));
        // SAFETY: stops the child started just above.
        unsafe { libc::kill(pid, libc::SIGSTOP) };
        let start = Instant::now();
        ps.stop_all();
        let took = start.elapsed();
        assert!(ps.first_dead().is_some());
        assert!(took < KILL_GRACE + Duration::from_millis(500), "{took:?}");
        // The group's `sleep` was killed too (give its new parent a moment to reap it).
        let gone = Instant::now() + Duration::from_secs(2);
        // SAFETY: `kill(-pgid, 0)` only checks whether any process of the group is left.
        while unsafe { libc::kill(-pid, 0) } == 0 {
            assert!(Instant::now() < gone, "a process of the stopped child's group survived");
            std::thread::sleep(Duration::from_millis(10));
        }
    }
}
