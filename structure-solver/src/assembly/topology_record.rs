//! What a checkpoint holds of a model's topology, and the rebuild of a changed model at a
//! restart: the restarted run builds the model from its case as the first run did, then adds
//! the nodes and element copies the record has beyond it, so the state arrays that follow
//! (`FeModel::restore_committed`) fit the changed model.

use nalgebra::Vector3;

use super::topology::TopologyError;
use super::FeModel;
use crate::model::Model;

/// Ids, reference positions, user-fixed dofs and element list of a model, flat.
#[derive(Debug, Clone, PartialEq)]
pub struct TopologyRecord {
    pub version: u64,
    /// User id of each node slot.
    pub node_ids: Vec<u64>,
    /// Reference positions, 3 per node.
    pub x0: Vec<f64>,
    /// The user's fixed dofs (`FeModel::fix`), 6 per node.
    pub fixed: Vec<bool>,
    /// User id of each element (mesh cell) slot.
    pub element_ids: Vec<u64>,
    /// The slot of the element each element was copied from (its own slot when built).
    pub element_source: Vec<u64>,
    /// The node slots of element `c` are `element_nodes[element_offsets[c]..element_offsets[c + 1]]`.
    pub element_offsets: Vec<u64>,
    pub element_nodes: Vec<u64>,
}

impl FeModel {
    /// The record of the current topology.
    pub fn topology_record(&self) -> TopologyRecord {
        let t = &self.topology;
        let mut element_offsets = vec![0u64];
        let mut element_nodes = Vec::new();
        for c in &self.cells {
            element_nodes.extend(c.iter().map(|&n| n as u64));
            element_offsets.push(element_nodes.len() as u64);
        }
        TopologyRecord {
            version: t.version,
            node_ids: t.nodes.ids().to_vec(),
            x0: self.x0.iter().flat_map(|p| [p.x, p.y, p.z]).collect(),
            fixed: self.user_fixed.clone(),
            element_ids: t.elements.ids().to_vec(),
            element_source: t.source.iter().map(|&s| s as u64).collect(),
            element_offsets,
            element_nodes,
        }
    }

    /// Rebuilds the changes of `rec` on this model, the model `rec`'s was changed from (built
    /// from the same case): its nodes and elements must be the record's first ones, ids and
    /// connectivity alike; the record's further nodes are added at their reference positions,
    /// the user's fixed dofs of the record applied, its further elements copied from their
    /// sources, and the version set to the record's. The configuration and the state of every
    /// element come next from `restore_committed`.
    pub fn rebuild_topology(&mut self, rec: &TopologyRecord) -> Result<(), TopologyError> {
        let bad = |m: String| Err(TopologyError::Record(m));
        let (nn, nc) = (rec.node_ids.len(), rec.element_ids.len());
        let (have_n, have_c) = (self.x0.len(), self.cells.len());
        if rec.x0.len() != 3 * nn || rec.fixed.len() != 6 * nn {
            return bad(format!(
                "{} reference coordinates and {} fixed flags for {nn} nodes",
                rec.x0.len(),
                rec.fixed.len()
            ));
        }
        if rec.element_source.len() != nc || rec.element_offsets.len() != nc + 1 {
            return bad(format!(
                "{} sources and {} offsets for {nc} elements",
                rec.element_source.len(),
                rec.element_offsets.len()
            ));
        }
        if nn < have_n || nc < have_c {
            return bad(format!(
                "{nn} nodes and {nc} elements, fewer than the model's {have_n} and {have_c} \
                 (a checkpoint of another case?)"
            ));
        }
        let o = &rec.element_offsets;
        if o[0] != 0
            || o.windows(2).any(|w| w[1] < w[0])
            || o[nc] as usize != rec.element_nodes.len()
        {
            return bad("element offsets do not increase to the length of the node list".into());
        }
        let nodes_of = |c: usize| &rec.element_nodes[o[c] as usize..o[c + 1] as usize];
        if rec.node_ids[..have_n] != *self.topology.nodes.ids() {
            return bad(
                "the node ids differ from the model's (a checkpoint of another mesh?)".into()
            );
        }
        for c in 0..have_c {
            let same = nodes_of(c).iter().map(|&n| n as usize).eq(self.cells[c].iter().copied());
            if rec.element_ids[c] != self.topology.elements.ids()[c] || !same {
                return bad(format!(
                    "element slot {c}: id {} on nodes {:?}, the model's id {} on nodes {:?} (a \
                     checkpoint of another mesh?)",
                    rec.element_ids[c],
                    nodes_of(c),
                    self.topology.elements.ids()[c],
                    self.cells[c]
                ));
            }
        }
        self.check_new(rec, have_n, have_c)?;
        self.revert();
        for s in have_n..nn {
            let p = Vector3::new(rec.x0[3 * s], rec.x0[3 * s + 1], rec.x0[3 * s + 2]);
            self.append_node(rec.node_ids[s], p);
        }
        for n in 0..nn {
            let mask: [bool; 6] = std::array::from_fn(|c| rec.fixed[6 * n + c]);
            if mask.iter().zip(&self.user_fixed[6 * n..6 * n + 6]).any(|(&r, &h)| r && !h) {
                self.fix(&[n], mask);
            }
        }
        for c in have_c..nc {
            let slots = nodes_of(c).iter().map(|&n| n as usize).collect();
            self.copy_cell(rec.element_source[c] as usize, rec.element_ids[c], slots);
        }
        self.committed.clone_from(&self.trial);
        self.changed();
        self.topology.version = rec.version;
        Ok(())
    }

    /// The record's nodes and elements beyond the model's can be added: fresh ids, finite
    /// positions, earlier sources, nodes in range and at their sources' reference positions.
    fn check_new(
        &self,
        rec: &TopologyRecord,
        have_n: usize,
        have_c: usize,
    ) -> Result<(), TopologyError> {
        let bad = |m: String| Err(TopologyError::Record(m));
        let mut nodes = self.topology.nodes.clone();
        for s in have_n..rec.node_ids.len() {
            if nodes.push(rec.node_ids[s]).is_err() {
                return Err(TopologyError::TakenId { kind: "node", id: rec.node_ids[s] });
            }
            if !rec.x0[3 * s..3 * s + 3].iter().all(|v| v.is_finite()) {
                let node = rec.node_ids[s];
                return Err(TopologyError::NotFinite { node, field: "reference position" });
            }
        }
        let mut elements = self.topology.elements.clone();
        let o = &rec.element_offsets;
        for c in have_c..rec.element_ids.len() {
            let id = rec.element_ids[c];
            if elements.push(id).is_err() {
                return Err(TopologyError::TakenId { kind: "element", id });
            }
            let src = rec.element_source[c] as usize;
            if src >= c {
                return bad(format!("element {id} is copied from slot {src}, not an earlier one"));
            }
            let nodes = &rec.element_nodes[o[c] as usize..o[c + 1] as usize];
            if let Some(&n) = nodes.iter().find(|&&n| n as usize >= rec.node_ids.len()) {
                return bad(format!("element {id} has node slot {n} of {}", rec.node_ids.len()));
            }
            // positions: the record's reference positions against the source's nodes
            let src_nodes = &rec.element_nodes[o[src] as usize..o[src + 1] as usize];
            if nodes.len() != src_nodes.len() {
                let (got, expected) = (nodes.len(), src_nodes.len());
                return Err(TopologyError::NodeCount { element: id, got, expected });
            }
            let x =
                |n: u64| Vector3::from_column_slice(&rec.x0[3 * n as usize..3 * n as usize + 3]);
            let size = src_nodes
                .iter()
                .flat_map(|&a| src_nodes.iter().map(move |&b| (a, b)))
                .map(|(a, b)| (x(a) - x(b)).norm())
                .fold(0.0, f64::max);
            for (&n, &m) in nodes.iter().zip(src_nodes) {
                if (x(n) - x(m)).norm() > 1e-12 * size {
                    let (g, e) = (x(n), x(m));
                    return Err(TopologyError::Reference {
                        element: id,
                        node: rec.node_ids[n as usize],
                        got: [g.x, g.y, g.z],
                        expected: [e.x, e.y, e.z],
                    });
                }
            }
        }
        Ok(())
    }
}
