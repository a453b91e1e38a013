//! Topology changes at run time: nodes added, and an element duplicated with its full state
//! onto other nodes — the phantom elements of the phantom-node formulation (thesis §3.5,
//! Eqs. 3.24-3.26, Fig. 3.2: a cracked element becomes two superposed copies on real and
//! phantom nodes).
//!
//! A change is made between steps, on the committed state (a pending trial state is dropped,
//! as `Model::revert` does). Every node array grows (configuration, constraints, loads, the
//! BT4 part's positions and increments), new nodes and elements are appended after the last
//! slot, the lumped mass and element step bounds are recomputed from the elements as a model
//! built with that topology computes them, and the version increases (`Model::topology_epoch`,
//! so sparse solvers renumber their free dofs). The integrator follows with
//! `CentralDifference::follow_topology` / `Implicit::follow_topology`.

use std::ops::Range;

use nalgebra::{Matrix3, Vector3};

use super::topology::{Store, TopologyError};
use super::FeModel;
use crate::model::Model;

/// A node added at run time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewNode {
    pub id: u64,
    /// Position in the reference configuration (what elements copied onto the node measure
    /// their reference geometry from).
    pub x0: [f64; 3],
    /// Current position and rotation.
    pub x: [f64; 3],
    pub rotation: Matrix3<f64>,
}

impl FeModel {
    /// Adds `nodes` after the last slot; they have no mass and no free dof until an element
    /// is put on them. Returns their slots; refuses an id taken or given twice, or a
    /// position or rotation that is not finite.
    pub fn add_nodes(&mut self, nodes: &[NewNode]) -> Result<Range<usize>, TopologyError> {
        self.check_new_ids("node", nodes.iter().map(|n| n.id), |m, id| {
            m.topology.nodes.slot(id).is_some()
        })?;
        for n in nodes {
            let finite = |v: &[f64]| v.iter().all(|c| c.is_finite());
            for (field, ok) in [
                ("reference position", finite(&n.x0)),
                ("position", finite(&n.x)),
                ("rotation", finite(n.rotation.as_slice())),
            ] {
                if !ok {
                    return Err(TopologyError::NotFinite { node: n.id, field });
                }
            }
        }
        self.revert();
        let first = self.x0.len();
        for n in nodes {
            let s = self.append_node(n.id, Vector3::from(n.x0));
            for st in [&mut self.trial, &mut self.committed] {
                st.x[s] = Vector3::from(n.x);
                st.r[s] = n.rotation;
            }
        }
        self.changed();
        Ok(first..self.x0.len())
    }

    /// Adds a copy of each node `(source id, new id)`: reference and current position,
    /// rotation and accumulated spin (phantom nodes). Returns the new slots.
    pub fn duplicate_nodes(&mut self, pairs: &[(u64, u64)]) -> Result<Range<usize>, TopologyError> {
        self.check_new_ids("node", pairs.iter().map(|p| p.1), |m, id| {
            m.topology.nodes.slot(id).is_some()
        })?;
        let sources =
            pairs.iter().map(|&(s, _)| self.node_slot(s)).collect::<Result<Vec<_>, _>>()?;
        self.revert();
        let first = self.x0.len();
        for (&(_, id), &src) in pairs.iter().zip(&sources) {
            let s = self.append_node(id, self.x0[src]);
            for st in [&mut self.trial, &mut self.committed] {
                st.x[s] = st.x[src];
                st.r[s] = st.r[src];
                st.spin_sum[s] = st.spin_sum[src];
            }
        }
        self.changed();
        Ok(first..self.x0.len())
    }

    /// Copies element `element` (a mesh cell's id) onto the nodes `nodes` (ids, in the
    /// element's node order) as element `new_id`, with its full committed state: material
    /// state of every point (stress, plastic strain, hardening), hourglass stresses, the
    /// corotated reference frame and section. The nodes must sit where the element's own
    /// nodes sit in the reference configuration (within 1e-12 of its size). Loads on cells
    /// (pressures) stay on the cells they were given for. Returns the new element's slot.
    pub fn duplicate_element(
        &mut self,
        element: u64,
        new_id: u64,
        nodes: &[u64],
    ) -> Result<usize, TopologyError> {
        let c = self
            .topology
            .elements
            .slot(element)
            .ok_or(TopologyError::UnknownElement { id: element })?;
        self.check_new_ids("element", [new_id], |m, id| m.topology.elements.slot(id).is_some())?;
        let slots = nodes.iter().map(|&n| self.node_slot(n)).collect::<Result<Vec<_>, _>>()?;
        self.check_copy(c, &slots)?;
        self.revert();
        let slot = self.copy_cell(c, new_id, slots);
        self.changed();
        Ok(slot)
    }

    /// The element of cell `c` can be copied onto node slots `slots`: as many nodes, at its
    /// nodes' reference positions, numbered within the explicit shells' connectivity range.
    pub(super) fn check_copy(&self, c: usize, slots: &[usize]) -> Result<(), TopologyError> {
        let id = |n: usize| self.topology.nodes.id(n).unwrap_or(n as u64);
        let element = self.topology.elements.id(c).unwrap_or(c as u64);
        let own = &self.cells[c];
        if slots.len() != own.len() {
            return Err(TopologyError::NodeCount {
                element,
                got: slots.len(),
                expected: own.len(),
            });
        }
        let mut size: f64 = 0.0;
        for &a in own {
            for &b in own {
                size = size.max((self.x0[a] - self.x0[b]).norm());
            }
        }
        for (&n, &m) in slots.iter().zip(own) {
            if (self.x0[n] - self.x0[m]).norm() > 1e-12 * size {
                let p = |v: Vector3<f64>| [v.x, v.y, v.z];
                return Err(TopologyError::Reference {
                    element,
                    node: id(n),
                    got: p(self.x0[n]),
                    expected: p(self.x0[m]),
                });
            }
            if u32::try_from(n).is_err() {
                return Err(TopologyError::Record(format!(
                    "node slot {n} is past the range of the explicit shells' connectivity"
                )));
            }
        }
        Ok(())
    }

    /// Appends a copy of cell `c`'s element on `slots` as cell `id` (checked by the caller)
    /// and frees the dofs it gives stiffness to; returns the new cell slot.
    pub(super) fn copy_cell(&mut self, c: usize, id: u64, slots: Vec<usize>) -> usize {
        let (store, rotations) = match self.topology.store[c] {
            Store::Element(i) => {
                let mut e = self.elements[i].clone();
                e.nodes.clone_from(&slots);
                let rotations = e.has_rotations();
                let (a, b) = (self.state_offsets[i], self.state_offsets[i + 1]);
                self.committed.material.extend_from_within(a..b);
                self.trial.material.clone_from(&self.committed.material);
                let end = self.state_offsets[self.elements.len()] + (b - a);
                self.state_offsets.push(end);
                self.elements.push(e);
                self.element_cell.push(self.cells.len());
                (Store::Element(self.elements.len() - 1), rotations)
            }
            Store::Bt4(j) => {
                let b = self.explicit.as_mut().and_then(|e| e.quads.as_mut());
                let b = b.expect("a BT4 cell has its part");
                let conn = [0, 1, 2, 3].map(|k| slots[k] as u32);
                let k = b.push_copy(j, conn).expect("a BT4 cell's shell exists");
                (Store::Bt4(k), true)
            }
            Store::Blt3(j) => {
                let b = self.explicit.as_mut().and_then(|e| e.triangles.as_mut());
                let b = b.expect("a BLT3 cell has its part");
                let conn = [0, 1, 2].map(|k| slots[k] as u32);
                let k = b.push_copy(j, conn).expect("a BLT3 cell's shell exists");
                (Store::Blt3(k), true)
            }
        };
        let k = if rotations { 6 } else { 3 };
        for &n in &slots {
            if self.slave[n] || self.skew_of[n].is_some() {
                continue;
            }
            for d in 6 * n..6 * n + k {
                if !self.user_fixed[d] {
                    self.constrained[d] = false;
                }
            }
        }
        let t = &mut self.topology;
        t.elements.push(id).expect("an id checked free");
        t.store.push(store);
        t.source.push(c);
        self.cells.push(slots);
        self.cells.len() - 1
    }

    /// Appends node `id` (checked free by the caller) at reference position `p`, resting
    /// there with the identity rotation, every dof constrained until an element uses it;
    /// returns its slot.
    pub(super) fn append_node(&mut self, id: u64, p: Vector3<f64>) -> usize {
        self.add_node(id, p);
        let s = self.x0.len() - 1;
        self.constrained[6 * s..6 * s + 6].fill(true);
        s
    }

    /// After a change: masses and step bounds from the elements, a new version.
    pub(super) fn changed(&mut self) {
        self.set_rotary_inertia(self.rotary);
        self.fint_valid = false;
        self.topology.version += 1;
    }

    /// Refuses new ids that are taken (`taken`) or repeated.
    fn check_new_ids(
        &self,
        kind: &'static str,
        ids: impl IntoIterator<Item = u64>,
        taken: impl Fn(&Self, u64) -> bool,
    ) -> Result<(), TopologyError> {
        let mut seen = std::collections::HashSet::new();
        for id in ids {
            if taken(self, id) || !seen.insert(id) {
                return Err(TopologyError::TakenId { kind, id });
            }
        }
        Ok(())
    }
}
