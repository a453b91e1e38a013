//! The structure participant's endpoint: publishes topology and kinematics, reads loads.

use super::control::{Control, ControlPort};
use super::data::{wake, SliceReader, SliceWriter};
use super::{ProtocolError, Timeouts};
use crate::handshake::HelloInfo;
use crate::messages::{NodeLoad, NodeState, Role, StepHeader, SurfaceElement};
use crate::services;

/// The structure side of a run. Dropping it removes its ports and node.
pub struct StructureEndpoint {
    topology: SliceWriter<SurfaceElement>,
    kinematics: SliceWriter<NodeState>,
    loads: SliceReader<NodeLoad>,
    control: Control,
}

impl StructureEndpoint {
    /// Joins run `run_id` as the structure and publishes its `Hello` (`info`).
    pub fn open(run_id: &str, info: HelloInfo, timeouts: Timeouts) -> Result<Self, ProtocolError> {
        let control = Control::open(run_id, Role::Structure, info, timeouts)?;
        let node = &control.node;
        let n_nodes = info.n_surface_nodes as usize;
        let n_elements = info.n_surface_elements as usize;
        let endpoint = StructureEndpoint {
            topology: SliceWriter::create(
                node,
                run_id,
                services::TOPOLOGY,
                1,
                n_elements,
                timeouts,
            )?,
            kinematics: SliceWriter::create(
                node,
                run_id,
                services::KINEMATICS,
                0,
                n_nodes,
                timeouts,
            )?,
            loads: SliceReader::create(node, run_id, services::LOADS, 0)?,
            control,
        };
        endpoint.control.announce()?;
        Ok(endpoint)
    }

    /// Publishes the wet-surface elements (`header.topology_version` says which), written in place
    /// by `fill`.
    pub fn publish_topology<R>(
        &mut self,
        header: StepHeader,
        n_elements: usize,
        fill: impl FnOnce(&mut [SurfaceElement]) -> R,
    ) -> Result<R, ProtocolError> {
        let r = self.topology.publish(header, n_elements, fill)?;
        wake(&self.control.wake_peer);
        Ok(r)
    }

    /// Publishes the wet-node positions and velocities for the time in `header`, written in place.
    pub fn publish_kinematics<R>(
        &mut self,
        header: StepHeader,
        n_nodes: usize,
        fill: impl FnOnce(&mut [NodeState]) -> R,
    ) -> Result<R, ProtocolError> {
        let r = self.kinematics.publish(header, n_nodes, fill)?;
        wake(&self.control.wake_peer);
        Ok(r)
    }

    /// Waits for the fluid's loads and reads them in place.
    pub fn read_loads<R>(
        &mut self,
        read: impl FnOnce(&StepHeader, &[NodeLoad]) -> R,
    ) -> Result<R, ProtocolError> {
        let c = &mut self.control;
        self.loads.read(&c.listener, &c.watch, c.timeouts.wait, &mut c.waited, read)
    }

    /// The run this endpoint belongs to.
    pub fn run_id(&self) -> &str {
        &self.control.run_id
    }
}

impl ControlPort for StructureEndpoint {
    fn control(&mut self) -> &mut Control {
        &mut self.control
    }
}
