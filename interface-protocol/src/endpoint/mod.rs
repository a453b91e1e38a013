//! Endpoints: the only place that speaks iceoryx2 (DESIGN §3). Solver code sees slices of the
//! wire types, commands and typed errors; every wait has a deadline and polls liveness in slices
//! of at most `liveness::POLL_SLICE`.
//!
//! - [`StructureEndpoint`]: publishes topology and kinematics, reads loads.
//! - [`FluidEndpoint`]: reads topology and kinematics, publishes loads.
//! - [`LauncherLink`]: the launcher's side: handshake, commands, replies, clean-up.
//!
//! Both participants answer commands through [`crate::participant::serve`].
//!
//! ```no_run
//! use interface_protocol::endpoint::{FluidEndpoint, StructureEndpoint, Timeouts};
//! use interface_protocol::messages::{NodeLoad, NodeState, StepHeader};
//! use interface_protocol::handshake::HelloInfo;
//!
//! let info = HelloInfo { n_surface_nodes: 2, n_surface_elements: 0, case_hash: 42, capabilities: 0 };
//! let mut s = StructureEndpoint::open("run-1", info, Timeouts::default())?;
//! let mut f = FluidEndpoint::open("run-1", info, Timeouts::default())?;
//! let header = StepHeader { step: 0, time: 0.0, dt: 1e-3, topology_version: 1, count: 0 };
//! // Fill the shared buffer in place: no Vec, no copy.
//! s.publish_kinematics(header, 2, |nodes: &mut [NodeState]| {
//!     for (i, n) in nodes.iter_mut().enumerate() {
//!         *n = NodeState { x: [i as f64, 0.0, 0.0], v: [0.0; 3] };
//!     }
//! })?;
//! // Read in place, answer in place.
//! let v0 = f.read_kinematics(|_h, nodes: &[NodeState]| nodes[0].v[0])?;
//! f.publish_loads(header, 2, |loads: &mut [NodeLoad]| loads.fill(NodeLoad { f: [-v0, 0.0, 0.0] }))?;
//! let total = s.read_loads(|_h, loads: &[NodeLoad]| loads.iter().map(|l| l.f[0]).sum::<f64>())?;
//! # Ok::<(), interface_protocol::endpoint::ProtocolError>(())
//! ```

mod control;
mod data;
mod fluid;
mod launcher;
mod structure;

pub use control::ControlPort;
pub use fluid::FluidEndpoint;
pub use launcher::LauncherLink;
pub use structure::StructureEndpoint;

use crate::liveness::{self, Stop, Watch};
use std::time::{Duration, Instant};

/// Deadlines of one endpoint.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Timeouts {
    /// Longest wait for a command, a sample or a reply (the case's `coupling.timeout_s`).
    pub wait: Duration,
    /// Longest time a send retries when the reader's buffer is full before it fails.
    pub delivery: Duration,
}

impl Default for Timeouts {
    fn default() -> Self {
        Timeouts { wait: Duration::from_secs(60), delivery: Duration::from_secs(1) }
    }
}

/// The most the launcher adds to a participant's wait for its next command (see
/// [`Timeouts::command`]).
pub const COMMAND_MARGIN: Duration = Duration::from_secs(2);

impl Timeouts {
    /// `wait` from the case's `coupling.timeout_s`, `delivery` the default.
    pub fn from_secs(timeout_s: f64) -> Timeouts {
        Timeouts { wait: Duration::from_secs_f64(timeout_s), ..Timeouts::default() }
    }

    /// A participant's longest wait for its next command: `2 wait + min(wait, COMMAND_MARGIN)`.
    /// Between two commands to one participant the launcher may await up to two replies of the
    /// other (up to `wait` each); waiting longer than that lets the launcher, which knows whose
    /// reply is missing, always be the one that names a silent participant.
    pub fn command(&self) -> Duration {
        self.wait * 2 + self.wait.min(COMMAND_MARGIN)
    }
}

/// Everything that can go wrong on the wire.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ProtocolError {
    /// A wait passed its deadline.
    #[error("timed out after {:.3} s waiting for {what}", waited.as_secs_f64())]
    Timeout { what: String, waited: Duration },
    /// SIGTERM or SIGINT arrived.
    #[error("stopped by {}", liveness::signal_name(*signal))]
    Terminated { signal: i32 },
    /// The launcher process is gone.
    #[error("the launcher (pid {pid}) is gone")]
    LauncherGone { pid: i32 },
    /// The peers disagree (handshake), or a message broke the command sequence.
    #[error("{0}")]
    Mismatch(String),
    /// A sample could not be delivered or received.
    #[error("{0}")]
    Delivery(String),
    /// Bad arguments or an environment that cannot hold the run.
    #[error("{0}")]
    Setup(String),
    /// iceoryx2 refused to create or open a resource.
    #[error("{0}")]
    Ipc(String),
}

impl From<Stop> for ProtocolError {
    fn from(s: Stop) -> Self {
        match s {
            Stop::Signal(signal) => ProtocolError::Terminated { signal },
            Stop::LauncherGone(pid) => ProtocolError::LauncherGone { pid },
        }
    }
}

/// Formats an iceoryx2 error with what was being done.
pub(crate) fn ipc_err(doing: &str, e: impl std::fmt::Debug) -> ProtocolError {
    ProtocolError::Ipc(format!("{doing}: {e:?}"))
}

/// Polls `ready` until it yields, sleeping on `listener` (the reader's wake event) in slices of at
/// most `POLL_SLICE` and checking `watch` each slice; fails at `deadline`.
pub(crate) fn wait_for<T>(
    listener: &iceoryx2::port::listener::Listener<iceoryx2::prelude::ipc::Service>,
    watch: &Watch,
    deadline: Instant,
    what: &dyn Fn() -> String,
    mut ready: impl FnMut() -> Result<Option<T>, ProtocolError>,
) -> Result<T, ProtocolError> {
    let start = Instant::now();
    loop {
        if let Some(v) = ready()? {
            return Ok(v);
        }
        watch.check()?;
        let now = Instant::now();
        if now >= deadline {
            return Err(ProtocolError::Timeout { what: what(), waited: now - start });
        }
        let slice = (deadline - now).min(liveness::POLL_SLICE);
        // An interrupted wait (a signal) is one more slice: `watch` sees the signal next round.
        let _ = listener.timed_wait(|_| {}, slice);
    }
}

#[cfg(test)]
mod tests;
