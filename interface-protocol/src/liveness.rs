//! Liveness of a participant (DESIGN §3): it ends cleanly on SIGTERM/SIGINT and when the launcher
//! dies, and every wait checks both once per poll slice (`POLL_SLICE`).
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

/// Installs the SIGTERM/SIGINT handler that records the signal (idempotent).
pub fn install_signal_handlers() {
    for signal in [libc::SIGTERM, libc::SIGINT] {
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
        let launcher = std::env::var(LAUNCHER_PID_ENV).ok().and_then(|s| s.trim().parse::<i32>().ok());
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
        if let Some(s) = termination_signal() {
            return Err(Stop::Signal(s));
        }
        if let Some(pid) = self.launcher {
            // SAFETY: `getppid` has no preconditions; `kill(pid, 0)` only checks existence.
            let (parent, alive) = unsafe { (libc::getppid(), libc::kill(pid, 0) == 0) };
            let reparented = self.launcher_is_parent && parent != pid;
            if reparented || !alive {
                return Err(Stop::LauncherGone(pid));
            }
        }
        Ok(())
    }
}
