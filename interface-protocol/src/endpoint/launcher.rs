//! The launcher's side of a run: handshake, commands and replies, clean-up (DESIGN §3,
//! coupling-sequence). The launcher starts the participants as children with
//! `liveness::LAUNCHER_PID_ENV` set to its pid; this link never waits without a deadline.
//!
//! ```no_run
//! use interface_protocol::endpoint::{LauncherLink, Timeouts};
//! use interface_protocol::messages::{Command, Role};
//! use std::time::{Duration, Instant};
//!
//! let mut link = LauncherLink::open("run-7", Timeouts::default())?;
//! // ... spawn the two participants with `--couple run-7` ...
//! let soon = Instant::now() + Duration::from_secs(10);
//! let f = link.wait_hello(Role::Fluid, soon)?;
//! let s = link.wait_hello(Role::Structure, soon)?;
//! LauncherLink::check(&f, &s, 0x1234)?;
//! link.send(Role::Structure, &Command::init())?;
//! let ready = link.wait_reply(Role::Structure, Instant::now() + Duration::from_secs(60))?;
//! link.remove_resources()?;
//! # Ok::<(), interface_protocol::endpoint::ProtocolError>(())
//! ```

use super::control::{control_service, event, hello_service};
use super::{ipc_err, wait_for, ProtocolError, Timeouts};
use crate::liveness::Watch;
use crate::messages::{Command, Hello, Reply, Role};
use crate::{handshake, services, shm};
use iceoryx2::pending_response::PendingResponse;
use iceoryx2::port::client::Client;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::{ipc, Node};
use std::time::Instant;

/// The ports the launcher holds towards one participant.
struct Peer {
    pending: Option<PendingResponse<ipc::Service, Command, (), Reply, ()>>,
    client: Client<ipc::Service, Command, (), Reply, ()>,
    hello: Subscriber<ipc::Service, Hello, ()>,
    wake: Notifier<ipc::Service>,
    /// The hello received, kept for `wait_hello` called twice.
    received: Option<Hello>,
}

/// The launcher's link to both participants of one run. Fields drop in order: ports, then node.
pub struct LauncherLink {
    fluid: Peer,
    structure: Peer,
    listener: Listener<ipc::Service>,
    watch: Watch,
    run_id: String,
    _node: Node<ipc::Service>,
}

impl LauncherLink {
    /// Creates the run's services under `run_id` (after removing stale files of dead runs).
    /// `timeouts.delivery` bounds the send of a command; waits take explicit deadlines.
    pub fn open(run_id: &str, timeouts: Timeouts) -> Result<LauncherLink, ProtocolError> {
        services::validate_run_id(run_id)?;
        shm::cleanup_stale_runs(shm::STALE_AFTER);
        let watch = Watch::signals_only();
        let node = services::node(run_id, services::LAUNCHER)?;
        let listener = event(&node, run_id, services::LAUNCHER)?
            .listener_builder()
            .create()
            .map_err(|e| ipc_err("cannot create the launcher's wake listener", e))?;
        let peer = |role: Role| -> Result<Peer, ProtocolError> {
            Ok(Peer {
                pending: None,
                client: control_service(&node, run_id, role)?
                    .client_builder()
                    .set_backpressure_handler(super::data::retry_until(timeouts.delivery))
                    .create()
                    .map_err(|e| ipc_err("cannot create a command client", e))?,
                hello: hello_service(&node, run_id, role)?
                    .subscriber_builder()
                    .create()
                    .map_err(|e| ipc_err("cannot create a hello subscriber", e))?,
                wake: event(&node, run_id, role.name())?
                    .notifier_builder()
                    .create()
                    .map_err(|e| ipc_err("cannot create a wake notifier", e))?,
                received: None,
            })
        };
        Ok(LauncherLink {
            fluid: peer(Role::Fluid)?,
            structure: peer(Role::Structure)?,
            listener,
            watch,
            run_id: run_id.to_string(),
            _node: node,
        })
    }

    /// The run id.
    pub fn run_id(&self) -> &str {
        &self.run_id
    }

    fn peer(&mut self, role: Role) -> &mut Peer {
        match role {
            Role::Fluid => &mut self.fluid,
            Role::Structure => &mut self.structure,
        }
    }

    /// Waits until the participant playing `role` has published its `Hello`.
    pub fn wait_hello(&mut self, role: Role, deadline: Instant) -> Result<Hello, ProtocolError> {
        let (listener, watch) = (&self.listener, self.watch);
        let peer = match role {
            Role::Fluid => &mut self.fluid,
            Role::Structure => &mut self.structure,
        };
        if let Some(h) = peer.received {
            return Ok(h);
        }
        let hello = wait_for(
            listener,
            &watch,
            deadline,
            &|| format!("the hello of the {} (is it running with this run id?)", role.name()),
            || {
                peer.hello
                    .receive()
                    .map(|s| s.map(|s| *s.payload()))
                    .map_err(|e| ipc_err("cannot receive a hello", e))
            },
        )?;
        peer.received = Some(hello);
        Ok(hello)
    }

    /// Checks both hellos against each other and the launcher's case hash; the error names both
    /// sides' values of every mismatch (protocol version, case hash, units, node counts).
    pub fn check(
        fluid: &Hello,
        structure: &Hello,
        expected_case_hash: u64,
    ) -> Result<(), ProtocolError> {
        handshake::check(fluid, structure, expected_case_hash)
    }

    /// Sends `command` to the participant playing `role`; its reply is awaited with `wait_reply`
    /// before the next command to that role.
    pub fn send(&mut self, role: Role, command: &Command) -> Result<(), ProtocolError> {
        let peer = self.peer(role);
        if peer.pending.is_some() {
            return Err(ProtocolError::Mismatch(format!(
                "a command was sent to the {} before its previous reply was read",
                role.name()
            )));
        }
        let pending = peer.client.send_copy(*command).map_err(|e| {
            ProtocolError::Delivery(format!(
                "cannot send {} to the {}: {e:?}",
                command.describe(),
                role.name()
            ))
        })?;
        if pending.number_of_server_connections() == 0 {
            return Err(ProtocolError::Delivery(format!(
                "cannot send {} to the {}: it is not listening (gone?)",
                command.describe(),
                role.name()
            )));
        }
        peer.pending = Some(pending);
        let _ = peer.wake.notify();
        Ok(())
    }

    /// Waits until `deadline` for the reply of the participant playing `role` to the last command.
    /// A short deadline in a loop lets the caller watch its children between slices: a
    /// `ProtocolError::Timeout` leaves the command pending.
    pub fn wait_reply(&mut self, role: Role, deadline: Instant) -> Result<Reply, ProtocolError> {
        let (listener, watch) = (&self.listener, self.watch);
        let peer = match role {
            Role::Fluid => &mut self.fluid,
            Role::Structure => &mut self.structure,
        };
        let Some(pending) = &peer.pending else {
            return Err(ProtocolError::Mismatch(format!(
                "waiting for a reply of the {} to no command",
                role.name()
            )));
        };
        let reply = wait_for(
            listener,
            &watch,
            deadline,
            &|| format!("the reply of the {}", role.name()),
            || {
                if !pending.is_connected() && !pending.has_response() {
                    return Err(ProtocolError::Delivery(format!(
                        "the {} dropped its command without a reply (gone?)",
                        role.name()
                    )));
                }
                pending
                    .receive()
                    .map(|r| r.map(|r| *r.payload()))
                    .map_err(|e| ipc_err("cannot receive a reply", e))
            },
        )?;
        peer.pending = None;
        Ok(reply)
    }

    /// Closes the link and removes every file of the run (call after both participants exited).
    /// Returns the number of files removed.
    pub fn remove_resources(self) -> Result<usize, ProtocolError> {
        let run_id = self.run_id.clone();
        drop(self);
        shm::cleanup_run(&run_id)
    }
}
