//! The participant's side of the command channel: its `Hello`, the `control/<role>` server and the
//! wake events (DESIGN §3 and coupling-sequence).

use super::{ipc_err, wait_for, ProtocolError, Timeouts};
use crate::handshake::HelloInfo;
use crate::liveness::Watch;
use crate::messages::{Command, Hello, Reply, Role};
use crate::services;
use iceoryx2::active_request::ActiveRequest;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::server::Server;
use iceoryx2::port::update_connections::UpdateConnections;
use iceoryx2::prelude::{ipc, Node};
use std::time::{Duration, Instant};

type Request = ActiveRequest<ipc::Service, Command, (), Reply, ()>;

/// What every participant endpoint holds: node, handshake, command server, wake events.
/// Field order is drop order: ports before the node.
pub struct Control {
    pending: Option<Request>,
    server: Server<ipc::Service, Command, (), Reply, ()>,
    hello: Publisher<ipc::Service, Hello, ()>,
    pub(crate) listener: Listener<ipc::Service>,
    wake_launcher: Notifier<ipc::Service>,
    pub(crate) wake_peer: Notifier<ipc::Service>,
    pub(crate) watch: Watch,
    pub(crate) timeouts: Timeouts,
    pub(crate) run_id: String,
    role: Role,
    info: HelloInfo,
    /// Seconds spent waiting for samples since the last reply.
    pub(crate) waited: Duration,
    pub(crate) node: Node<ipc::Service>,
}

/// Opens a pub-sub service with one setting everywhere (all sides must ask for the same).
pub(crate) fn event(
    node: &Node<ipc::Service>,
    run_id: &str,
    reader: &str,
) -> Result<iceoryx2::service::port_factory::event::PortFactory<ipc::Service>, ProtocolError> {
    node.service_builder(&services::service_name(run_id, &services::wake(reader))?)
        .event()
        .open_or_create()
        .map_err(|e| ipc_err(&format!("cannot open the wake event of {reader}"), e))
}

/// The request-response service of one role's commands.
pub(crate) fn control_service(
    node: &Node<ipc::Service>,
    run_id: &str,
    role: Role,
) -> Result<
    iceoryx2::service::port_factory::request_response::PortFactory<
        ipc::Service,
        Command,
        (),
        Reply,
        (),
    >,
    ProtocolError,
> {
    node.service_builder(&services::service_name(run_id, &services::control(role))?)
        .request_response::<Command, Reply>()
        .enable_safe_overflow_for_requests(false)
        .enable_safe_overflow_for_responses(false)
        .max_active_requests_per_client(1)
        .max_response_buffer_size(1)
        .open_or_create()
        .map_err(|e| ipc_err(&format!("cannot open the control service of the {}", role.name()), e))
}

/// The `hello/<role>` service (history 1).
pub(crate) fn hello_service(
    node: &Node<ipc::Service>,
    run_id: &str,
    role: Role,
) -> Result<
    iceoryx2::service::port_factory::publish_subscribe::PortFactory<ipc::Service, Hello, ()>,
    ProtocolError,
> {
    node.service_builder(&services::service_name(run_id, &services::hello(role))?)
        .publish_subscribe::<Hello>()
        .history_size(1)
        .subscriber_max_buffer_size(1)
        .enable_safe_overflow(true)
        .open_or_create()
        .map_err(|e| ipc_err(&format!("cannot open the hello service of the {}", role.name()), e))
}

impl Control {
    /// Creates the node of `role`, its command server and wake events (`announce` publishes the
    /// `Hello` afterwards).
    pub(crate) fn open(
        run_id: &str,
        role: Role,
        info: HelloInfo,
        timeouts: Timeouts,
    ) -> Result<Control, ProtocolError> {
        let watch = Watch::from_env();
        let node = services::node(run_id, role.name())?;
        let peer = match role {
            Role::Fluid => Role::Structure,
            Role::Structure => Role::Fluid,
        };
        let server = control_service(&node, run_id, role)?
            .server_builder()
            .set_backpressure_handler(super::data::retry_until(timeouts.delivery))
            .create()
            .map_err(|e| ipc_err("cannot create the command server", e))?;
        let listener = event(&node, run_id, role.name())?
            .listener_builder()
            .create()
            .map_err(|e| ipc_err("cannot create the wake listener", e))?;
        let wake_launcher =
            event(&node, run_id, services::LAUNCHER)?
                .notifier_builder()
                .create()
                .map_err(|e| ipc_err("cannot create the launcher's wake notifier", e))?;
        let wake_peer = event(&node, run_id, peer.name())?
            .notifier_builder()
            .create()
            .map_err(|e| ipc_err("cannot create the peer's wake notifier", e))?;
        let hello = hello_service(&node, run_id, role)?
            .publisher_builder()
            .create()
            .map_err(|e| ipc_err("cannot create the hello publisher", e))?;
        Ok(Control {
            info,
            pending: None,
            server,
            hello,
            listener,
            wake_launcher,
            wake_peer,
            watch,
            timeouts,
            run_id: run_id.to_string(),
            role,
            waited: Duration::ZERO,
            node,
        })
    }

    /// Publishes the `Hello`: called by the endpoints once all their ports exist, so that no
    /// sample sent after the launcher's handshake can miss a subscriber.
    pub(crate) fn announce(&self) -> Result<(), ProtocolError> {
        self.hello
            .send_copy(self.info.hello(self.role))
            .map_err(|e| ipc_err("cannot publish the hello", e))?;
        let _ = self.wake_launcher.notify();
        Ok(())
    }

    /// The role this endpoint plays.
    pub fn role(&self) -> Role {
        self.role
    }

    /// Waits for the next command (deadline `Timeouts::command`). The command must be answered
    /// with `reply` before the next one is taken.
    pub fn next_command(&mut self) -> Result<Command, ProtocolError> {
        if self.pending.is_some() {
            return Err(ProtocolError::Mismatch(
                "a command was taken before the previous one was answered".into(),
            ));
        }
        let deadline = Instant::now() + self.timeouts.command();
        let role = self.role;
        let (server, hello) = (&self.server, &self.hello);
        let request = wait_for(
            &self.listener,
            &self.watch,
            deadline,
            &|| format!("the launcher's next command to the {}", role.name()),
            || {
                // Delivers the hello's history to a launcher that subscribed late.
                let _ = hello.update_connections();
                server.receive().map_err(|e| ipc_err("cannot receive a command", e))
            },
        )?;
        let command = *request.payload();
        self.pending = Some(request);
        Ok(command)
    }

    /// Answers the command taken last and wakes the launcher.
    pub fn reply(&mut self, reply: &Reply) -> Result<(), ProtocolError> {
        let request = self
            .pending
            .take()
            .ok_or_else(|| ProtocolError::Mismatch("a reply without a command to answer".into()))?;
        request.send_copy(*reply).map_err(|e| {
            ProtocolError::Delivery(format!("cannot send the reply to the launcher: {e:?}"))
        })?;
        drop(request);
        let _ = self.wake_launcher.notify();
        self.waited = Duration::ZERO;
        Ok(())
    }

    /// Seconds spent waiting for samples since the last reply.
    pub fn waited(&self) -> Duration {
        self.waited
    }

    /// Checks signals and the launcher once.
    pub fn check_liveness(&self) -> Result<(), ProtocolError> {
        self.watch.check().map_err(ProtocolError::from)
    }
}

/// A participant endpoint: gives `participant::serve` its command channel.
pub trait ControlPort {
    fn control(&mut self) -> &mut Control;
}
