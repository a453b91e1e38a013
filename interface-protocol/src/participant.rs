//! The command loop every participant runs (coupling-sequence): take a command, let the solver's
//! `Handler` do it, answer `Ready`/`Done`/`Failed` with the work and wait seconds, until `Finish`.
//! Solvers implement `Handler`; none writes its own loop.

use crate::endpoint::{ControlPort, ProtocolError};
use crate::messages::{command_kind, Command, Reply};
use std::time::Instant;

/// Codes of `Reply::code` in a `Failed` reply.
pub mod failure_code {
    /// The command sequence or the wire broke (a sample missing, a timeout).
    pub const PROTOCOL: u32 = 1;
    /// The solver failed (divergence, NaN, a singular system).
    pub const SOLVER: u32 = 2;
    /// Output could not be written.
    pub const IO: u32 = 3;
    /// The participant does not support what was asked (scheme, command).
    pub const UNSUPPORTED: u32 = 4;
}

/// Where a participant stands after a command.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Progress {
    /// Coupling step completed (the command's `step`).
    pub step: u64,
    /// Time the participant has reached.
    pub t: f64,
    /// Largest stable step from here (`f64::INFINITY` if unlimited).
    pub dt_stable: f64,
    /// `Reply::interface_work` at `t` (0 from a participant that does not keep it).
    pub interface_work: f64,
}

impl Progress {
    /// The `Done` reply that reports it (the seconds are filled in by [`serve`]).
    fn reply(&self) -> Reply {
        Reply {
            interface_work: self.interface_work,
            ..Reply::done(self.step, self.t, self.dt_stable, 0.0, 0.0)
        }
    }
}

/// Why a command failed: sent to the launcher as `Failed { code, message }`.
#[derive(Debug, Clone, PartialEq)]
pub struct Failure {
    pub code: u32,
    pub message: String,
    /// Set when the failure ends the participant at once (a signal, the launcher gone).
    fatal: Option<ProtocolError>,
}

impl Failure {
    pub fn new(code: u32, message: impl Into<String>) -> Failure {
        Failure { code, message: message.into(), fatal: None }
    }
}

impl From<ProtocolError> for Failure {
    fn from(e: ProtocolError) -> Failure {
        let fatal =
            matches!(e, ProtocolError::Terminated { .. } | ProtocolError::LauncherGone { .. });
        Failure { code: failure_code::PROTOCOL, message: e.to_string(), fatal: fatal.then_some(e) }
    }
}

/// A solver's answers to the commands (see coupling-sequence for what each must publish).
pub trait Handler<E> {
    /// `Init`: publish the initial state (structure) or the initial loads (fluid); returns the
    /// stable step.
    fn init(&mut self, endpoint: &mut E) -> Result<f64, Failure>;
    /// `Advance`: one phase of one coupling step.
    fn advance(&mut self, endpoint: &mut E, command: &Command) -> Result<Progress, Failure>;
    /// `Checkpoint`: save the state under `tag`.
    fn checkpoint(&mut self, endpoint: &mut E, tag: &str) -> Result<(), Failure>;
    /// `Finish`: flush output; the loop ends after the reply.
    fn finish(&mut self, endpoint: &mut E) -> Result<(), Failure>;
}

/// Answers commands until `Finish` (then `Ok`), or until a wait fails, a signal arrives or the
/// launcher dies (then `Err`; the caller drops the endpoint, reports on stderr and exits non-zero).
pub fn serve<E: ControlPort, H: Handler<E>>(
    endpoint: &mut E,
    handler: &mut H,
) -> Result<(), ProtocolError> {
    let mut last = Progress { step: 0, t: 0.0, dt_stable: f64::INFINITY, interface_work: 0.0 };
    loop {
        let command = endpoint.control().next_command()?;
        let start = Instant::now();
        let outcome = match command.kind {
            command_kind::INIT => handler.init(endpoint).map(|dt| {
                last.dt_stable = dt;
                Reply::ready(dt)
            }),
            command_kind::ADVANCE => handler.advance(endpoint, &command).map(|p| {
                last = p;
                p.reply()
            }),
            command_kind::CHECKPOINT => {
                handler.checkpoint(endpoint, &command.tag_str()).map(|()| last.reply())
            }
            command_kind::FINISH => handler.finish(endpoint).map(|()| last.reply()),
            k => Err(Failure::new(failure_code::PROTOCOL, format!("unknown command kind {k}"))),
        };
        let waited = endpoint.control().waited().as_secs_f64();
        let work = (start.elapsed().as_secs_f64() - waited).max(0.0);
        let reply = match outcome {
            Ok(r) => Reply { work_s: work, wait_s: waited, ..r },
            Err(Failure { fatal: Some(e), .. }) => return Err(e),
            Err(f) => Reply { work_s: work, wait_s: waited, ..Reply::failed(f.code, &f.message) },
        };
        endpoint.control().reply(&reply)?;
        if command.kind == command_kind::FINISH {
            return Ok(());
        }
    }
}
