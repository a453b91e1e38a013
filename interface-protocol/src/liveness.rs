//! Liveness of a participant (DESIGN §3): it ends cleanly on SIGTERM, SIGINT or SIGHUP and when
//! the launcher dies, and every wait checks both once per poll slice (`POLL_SLICE`).
//!
//! iceoryx2's own handling is disabled (it would swallow SIGTERM); the handler here only records
//! the signal, and the waits in `endpoint` turn it into `ProtocolError::Terminated`. The launcher
//! exports its pid in `LAUNCHER_PID_ENV`; a participant whose parent is that launcher also asks the
//! kernel for SIGTERM when the parent dies (`PR_SET_PDEATHSIG`), and checks `getppid()` and
//! `kill(pid, 0)` in every slice (the signal alone is lost if the parent died before `prctl`).

use std::sync::atomic::{AtomicI32, Ordering};
use std::time::Duration;

/// Environment variable in which the launcher passes its pid to the participants.
pub const LAUNCHER_PID_ENV: &str = "FSI_LAUNCHER_PID";

/// Longest sleep of any wait between two liveness checks.
pub const POLL_SLICE: Duration = Duration::from_millis(50);

/// The last termination signal received, 0 if none.
static RECEIVED: AtomicI32 = AtomicI32::new(0);

extern "C" fn record_signal(signal: libc::c_int) {
    RECEIVED.store(signal, Ordering::SeqCst);
}

/// The signals that end a run cleanly: recorded, then acted on at the next poll slice.
pub const TERMINATION_SIGNALS: [libc::c_int; 3] = [libc::SIGTERM, libc::SIGINT, libc::SIGHUP];

/// Installs the handler of `TERMINATION_SIGNALS` that records the signal (idempotent).
pub fn install_signal_handlers() {
    for signal in TERMINATION_SIGNALS {
        // SAFETY: `sigaction` with a zeroed struct, an empty mask and a handler that only stores
        // into an atomic (async-signal-safe) is the documented way to install a handler.
        unsafe {
            let mut action: libc::sigaction = std::mem::zeroed();
            action.sa_sigaction = record_signal as extern "C" fn(libc::c_int) as usize;
            libc::sigemptyset(&mut action.sa_mask);
            libc::sigaction(signal, &action, std::ptr::null_mut());
        }
    }
}

/// The termination signal received so far, if any.
pub fn termination_signal() -> Option<i32> {
    match RECEIVED.load(Ordering::SeqCst) {
        0 => None,
        s => Some(s),
    }
}

/// Name of a signal number for messages.
pub fn signal_name(signal: i32) -> &'static str {
    match signal {
        libc::SIGTERM => "SIGTERM",
        libc::SIGINT => "SIGINT",
        libc::SIGKILL => "SIGKILL",
        libc::SIGHUP => "SIGHUP",
        _ => "a signal",
    }
}

/// What a participant watches besides its own signals.
#[derive(Debug, Clone, Copy)]
pub struct Watch {
    /// The launcher's pid, from `LAUNCHER_PID_ENV`.
    launcher: Option<i32>,
    /// Whether the launcher is this process' parent (then `getppid()` must stay equal to it).
    launcher_is_parent: bool,
}

/// Why a participant must stop.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Stop {
    Signal(i32),
    LauncherGone(i32),
}

impl Watch {
    /// Installs the signal handlers and reads the launcher's pid from the environment; if the
    /// launcher is the parent, arms `PR_SET_PDEATHSIG` with SIGTERM.
    pub fn from_env() -> Watch {
        install_signal_handlers();
        let launcher =
            std::env::var(LAUNCHER_PID_ENV).ok().and_then(|s| s.trim().parse::<i32>().ok());
        // SAFETY: `getppid` has no preconditions.
        let parent = unsafe { libc::getppid() };
        let launcher_is_parent = launcher == Some(parent);
        if launcher_is_parent {
            // SAFETY: `prctl(PR_SET_PDEATHSIG, sig)` only sets a process attribute.
            unsafe {
                libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGTERM as libc::c_ulong, 0, 0, 0);
            }
        }
        Watch { launcher, launcher_is_parent }
    }

    /// A watch of nothing but signals (the launcher itself, tests).
    pub fn signals_only() -> Watch {
        install_signal_handlers();
        Watch { launcher: None, launcher_is_parent: false }
    }

    /// `Err` once a termination signal arrived or the launcher is gone.
    pub fn check(&self) -> Result<(), Stop> {
        if let Some(pid) = self.launcher {
            // SAFETY: `getppid` has no preconditions; `kill(pid, 0)` only checks existence.
            let (parent, found) = unsafe { (libc::getppid(), libc::kill(pid, 0) == 0) };
            // EPERM: the process exists but belongs to someone else.
            let alive =
                found || std::io::Error::last_os_error().raw_os_error() == Some(libc::EPERM);
            let reparented = self.launcher_is_parent && parent != pid;
            if reparented || !alive {
                return Err(Stop::LauncherGone(pid));
            }
        }
        // After the launcher: its death also arrives as SIGTERM (parent-death signal), and the
        // message should say which.
        if let Some(s) = termination_signal() {
            return Err(Stop::Signal(s));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    //! Real processes: the test binary re-runs itself as a participant (and as a launcher that
    //! dies), selected by `FSI_TEST_ROLE`.
    use crate::endpoint::{ControlPort, LauncherLink, StructureEndpoint, Timeouts};
    use crate::handshake::HelloInfo;
    use crate::messages::Role;
    use crate::shm;
    use std::path::{Path, PathBuf};
    use std::process::{Child, Command};
    use std::time::{Duration, Instant};

    const ENTRY: &str = "liveness::tests::process_entry";

    fn reexec(role: &str, run_id: &str, out: &Path) -> Command {
        let mut c = Command::new(std::env::current_exe().unwrap());
        c.args(["--exact", ENTRY, "--ignored", "--nocapture", "--test-threads=1"])
            .env("FSI_TEST_ROLE", role)
            .env("FSI_TEST_RUN", run_id)
            .env("FSI_TEST_OUT", out)
            .env_remove(super::LAUNCHER_PID_ENV)
            .stdout(std::process::Stdio::null());
        c
    }

    /// Entry point of the child processes (ignored in a normal test run).
    #[test]
    #[ignore = "entry point of the processes started by the liveness tests"]
    fn process_entry() {
        let (Ok(role), Ok(run_id), Ok(out)) = (
            std::env::var("FSI_TEST_ROLE"),
            std::env::var("FSI_TEST_RUN"),
            std::env::var("FSI_TEST_OUT"),
        ) else {
            return;
        };
        match role.as_str() {
            "participant" => {
                let timeouts = Timeouts { wait: Duration::from_secs(30), ..Timeouts::default() };
                let mut s =
                    StructureEndpoint::open(&run_id, HelloInfo::default(), timeouts).unwrap();
                let e = s.control().next_command().unwrap_err();
                drop(s);
                std::fs::write(&out, e.to_string()).unwrap();
                std::process::exit(3);
            }
            "stale" => {
                let s = StructureEndpoint::open(&run_id, HelloInfo::default(), Timeouts::default())
                    .unwrap();
                std::fs::write(&out, "open").unwrap();
                std::thread::sleep(Duration::from_secs(30));
                drop(s);
            }
            "link" => {
                // A launcher's start-up in a run holding a dead node; iceoryx2 logs go to stderr.
                let link = LauncherLink::open(&run_id, Timeouts::default()).unwrap();
                drop(link);
                std::fs::write(&out, "done").unwrap();
            }
            "launcher" => {
                let mut c = reexec("participant", &run_id, Path::new(&out));
                c.env(super::LAUNCHER_PID_ENV, std::process::id().to_string());
                // Killed by the test while it waits for its participant.
                let _ = c.spawn().unwrap().wait();
            }
            _ => {}
        }
    }

    fn setup(test: &str) -> (String, PathBuf, LauncherLink) {
        let run_id = format!("t{}-{test}", std::process::id());
        let out = std::env::temp_dir().join(format!("fsi-{run_id}.txt"));
        let _ = std::fs::remove_file(&out);
        let link = LauncherLink::open(&run_id, Timeouts::default()).unwrap();
        (run_id, out, link)
    }

    /// Waits until the child wrote its error; returns it and the time it took.
    fn outcome(out: &Path, since: Instant) -> (String, Duration) {
        while since.elapsed() < Duration::from_secs(5) {
            if let Ok(text) = std::fs::read_to_string(out) {
                if !text.is_empty() {
                    return (text, since.elapsed());
                }
            }
            std::thread::sleep(Duration::from_millis(5));
        }
        panic!("the participant did not stop within 5 s");
    }

    fn kill(child: &Child, signal: i32) {
        // SAFETY: sends a signal to our own child process.
        unsafe { libc::kill(child.id() as i32, signal) };
    }

    #[test]
    fn sigterm_ends_a_waiting_participant_cleanly() {
        let (run_id, out, mut link) = setup("sigterm");
        let mut child = reexec("participant", &run_id, &out).spawn().unwrap();
        link.wait_hello(Role::Structure, Instant::now() + Duration::from_secs(20)).unwrap();
        let start = Instant::now();
        kill(&child, libc::SIGTERM);
        let status = child.wait().unwrap();
        let (text, took) = outcome(&out, start);
        assert_eq!(status.code(), Some(3));
        assert_eq!(text, "stopped by SIGTERM");
        assert!(took < Duration::from_secs(1), "took {took:?}");
        link.remove_resources().unwrap();
        assert!(shm::run_files(&run_id).is_empty());
        let _ = std::fs::remove_file(&out);
    }

    #[test]
    fn a_participant_leaves_within_a_second_when_its_launcher_dies() {
        let (run_id, out, mut link) = setup("orphan");
        let mut launcher = reexec("launcher", &run_id, &out).spawn().unwrap();
        link.wait_hello(Role::Structure, Instant::now() + Duration::from_secs(20)).unwrap();
        let start = Instant::now();
        kill(&launcher, libc::SIGKILL);
        launcher.wait().unwrap();
        let (text, took) = outcome(&out, start);
        assert!(text == "stopped by SIGTERM" || text.contains("launcher"), "{text}");
        assert!(took < Duration::from_secs(1), "took {took:?}");
        link.remove_resources().unwrap();
        assert!(shm::run_files(&run_id).is_empty());
        let _ = std::fs::remove_file(&out);
    }

    #[test]
    fn a_dead_node_without_its_details_draws_no_global_config_warning() {
        let run_id = format!("t{}-nodetails", std::process::id());
        let out = std::env::temp_dir().join(format!("fsi-{run_id}.txt"));
        let _ = std::fs::remove_file(&out);
        let mut child = reexec("stale", &run_id, &out).spawn().unwrap();
        outcome(&out, Instant::now());
        kill(&child, libc::SIGKILL);
        child.wait().unwrap();
        // A node killed while it was created or removed: its monitor is there, its details not.
        let details: Vec<_> =
            shm::run_files(&run_id).into_iter().filter(|p| p.ends_with_details()).collect();
        assert!(!details.is_empty(), "no node details among {:?}", shm::run_files(&run_id));
        details.iter().for_each(|p| std::fs::remove_file(p).unwrap());
        let _ = std::fs::remove_file(&out);
        let logged =
            reexec("link", &run_id, &out).stderr(std::process::Stdio::piped()).output().unwrap();
        let stderr = String::from_utf8_lossy(&logged.stderr);
        assert_eq!(std::fs::read_to_string(&out).unwrap_or_default(), "done", "{stderr}");
        assert!(!stderr.contains("global_config"), "iceoryx2 warned:\n{stderr}");
        shm::cleanup_run(&run_id).unwrap();
        let _ = std::fs::remove_file(&out);
    }

    trait DetailsFile {
        fn ends_with_details(&self) -> bool;
    }

    impl DetailsFile for PathBuf {
        fn ends_with_details(&self) -> bool {
            self.extension().is_some_and(|e| e == "details")
        }
    }

    #[test]
    fn files_of_a_run_whose_nodes_died_are_removed_as_stale() {
        let run_id = format!("t{}-stale", std::process::id());
        let out = std::env::temp_dir().join(format!("fsi-{run_id}.txt"));
        let _ = std::fs::remove_file(&out);
        let mut child = reexec("stale", &run_id, &out).spawn().unwrap();
        outcome(&out, Instant::now());
        assert!(shm::run_has_live_node(&run_id));
        kill(&child, libc::SIGKILL);
        child.wait().unwrap();
        assert!(!shm::run_files(&run_id).is_empty(), "a killed node leaves its files");
        assert!(!shm::run_has_live_node(&run_id));
        shm::cleanup_if_stale(&run_id, Duration::ZERO);
        assert!(shm::run_files(&run_id).is_empty());
        let _ = std::fs::remove_file(&out);
    }
}
