//! The fluid participant's endpoint: reads topology and kinematics, publishes loads.

use super::control::{Control, ControlPort};
use super::data::{wake, SliceReader, SliceWriter};
use super::{ProtocolError, Timeouts};
use crate::handshake::HelloInfo;
use crate::messages::{NodeLoad, NodeState, Role, StepHeader, SurfaceElement};
use crate::services;

/// The fluid side of a run. Dropping it removes its ports and node.
pub struct FluidEndpoint {
    topology: SliceReader<SurfaceElement>,
    kinematics: SliceReader<NodeState>,
    loads: SliceWriter<NodeLoad>,
    control: Control,
}

/// Initial capacity of the loads buffer when the node count is not known yet (it grows).
const DEFAULT_NODES: usize = 1024;

impl FluidEndpoint {
    /// Joins run `run_id` as the fluid and publishes its `Hello` (`info`; node and element counts
    /// are the ones the fluid expects, 0 if it accepts any).
    pub fn open(run_id: &str, info: HelloInfo, timeouts: Timeouts) -> Result<Self, ProtocolError> {
        let control = Control::open(run_id, Role::Fluid, info, timeouts)?;
        let node = &control.node;
        let n_nodes = match info.n_surface_nodes as usize {
            0 => DEFAULT_NODES,
            n => n,
        };
        let endpoint = FluidEndpoint {
            topology: SliceReader::create(node, run_id, services::TOPOLOGY, 1)?,
            kinematics: SliceReader::create(node, run_id, services::KINEMATICS, 0)?,
            loads: SliceWriter::create(node, run_id, services::LOADS, 0, n_nodes, timeouts)?,
            control,
        };
        endpoint.control.announce()?;
        Ok(endpoint)
    }

    /// Waits for a topology and reads it in place.
    pub fn read_topology<R>(
        &mut self,
        read: impl FnOnce(&StepHeader, &[SurfaceElement]) -> R,
    ) -> Result<R, ProtocolError> {
        let c = &mut self.control;
        self.topology.read(&c.listener, &c.watch, c.timeouts.wait, &mut c.waited, read)
    }

    /// A newer topology if the structure published one (after a crack), without waiting.
    pub fn try_read_topology<R>(
        &mut self,
        read: impl FnOnce(&StepHeader, &[SurfaceElement]) -> R,
    ) -> Result<Option<R>, ProtocolError> {
        self.topology.try_read(read)
    }

    /// Waits for the structure's kinematics and reads them in place.
    pub fn read_kinematics<R>(
        &mut self,
        read: impl FnOnce(&StepHeader, &[NodeState]) -> R,
    ) -> Result<R, ProtocolError> {
        let c = &mut self.control;
        self.kinematics.read(&c.listener, &c.watch, c.timeouts.wait, &mut c.waited, read)
    }

    /// Waits for the kinematics and answers them at once: `answer` reads the nodes in place from
    /// the sample and writes one load per node in place into the loan (no copy either way); the
    /// loads carry the kinematics' header.
    pub fn answer_kinematics<R>(
        &mut self,
        answer: impl FnOnce(&StepHeader, &[NodeState], &mut [NodeLoad]) -> R,
    ) -> Result<R, ProtocolError> {
        let c = &mut self.control;
        let loads = &mut self.loads;
        let r = self.kinematics.read(
            &c.listener,
            &c.watch,
            c.timeouts.wait,
            &mut c.waited,
            |h, nodes| loads.publish(*h, nodes.len(), |out| answer(h, nodes, out)),
        )??;
        wake(&self.control.wake_peer);
        Ok(r)
    }

    /// Publishes the nodal loads for the time in `header`, written in place by `fill`.
    pub fn publish_loads<R>(
        &mut self,
        header: StepHeader,
        n_nodes: usize,
        fill: impl FnOnce(&mut [NodeLoad]) -> R,
    ) -> Result<R, ProtocolError> {
        let r = self.loads.publish(header, n_nodes, fill)?;
        wake(&self.control.wake_peer);
        Ok(r)
    }

    /// The run this endpoint belongs to.
    pub fn run_id(&self) -> &str {
        &self.control.run_id
    }
}

impl ControlPort for FluidEndpoint {
    fn control(&mut self) -> &mut Control {
        &mut self.control
    }
}
