//! The model's topology apart from its storage: stable user ids of nodes and elements (gmsh
//! tags, generator ids) mapped to and from storage slots, where each element (mesh cell) is
//! stored, and the version counter of run-time changes (DESIGN §6, "ready for coupling and
//! fracture"; the phantom elements of thesis §3.5, Fig. 3.2, are added through it).
//!
//! A model is built with ids equal to slots; the case build (`crate::build`) gives the user's
//! ids ([`FeModel::set_ids`]: gmsh node tags, else the input numbers) after renumbering
//! storage for locality. Elements are named by the
//! slot of their mesh cell: slot `c` is either a corotated/solid element or a BT4 shell.

use std::collections::HashMap;

use super::FeModel;

/// Stable ids of one kind of entity and their storage slots, both ways.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct IdMap {
    ids: Vec<u64>,
    slot_of: HashMap<u64, usize>,
}

impl IdMap {
    /// Ids equal to the slots `0..n`.
    pub fn identity(n: usize) -> Self {
        let ids: Vec<u64> = (0..n as u64).collect();
        let slot_of = ids.iter().enumerate().map(|(s, &i)| (i, s)).collect();
        IdMap { ids, slot_of }
    }

    /// The map of `ids` (slot `s` has id `ids[s]`); `Err(id)` names an id given twice.
    pub fn from_ids(ids: Vec<u64>) -> Result<Self, u64> {
        let mut slot_of = HashMap::with_capacity(ids.len());
        for (s, &id) in ids.iter().enumerate() {
            if slot_of.insert(id, s).is_some() {
                return Err(id);
            }
        }
        Ok(IdMap { ids, slot_of })
    }

    /// Number of slots.
    pub fn len(&self) -> usize {
        self.ids.len()
    }

    /// `true` when there is no slot.
    pub fn is_empty(&self) -> bool {
        self.ids.is_empty()
    }

    /// The id of slot `s`.
    pub fn id(&self, s: usize) -> Option<u64> {
        self.ids.get(s).copied()
    }

    /// The slot of `id`.
    pub fn slot(&self, id: u64) -> Option<usize> {
        self.slot_of.get(&id).copied()
    }

    /// The ids, in slot order.
    pub fn ids(&self) -> &[u64] {
        &self.ids
    }

    /// An id no slot has (one past the largest).
    pub fn next_id(&self) -> u64 {
        self.ids.iter().max().map_or(0, |m| m + 1)
    }

    /// Appends a slot with `id`; `Err(id)` when it is taken.
    pub fn push(&mut self, id: u64) -> Result<usize, u64> {
        let s = self.ids.len();
        if self.slot_of.insert(id, s).is_some() {
            return Err(id);
        }
        self.ids.push(id);
        Ok(s)
    }
}

/// Where the element of a mesh cell is stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Store {
    /// `FeModel::elements()[i]`.
    Element(usize),
    /// Element `i` of the BT4 shells (quadrilaterals of the explicit shell parts).
    Bt4(usize),
    /// Element `i` of the BLT3 shells (their triangles).
    Blt3(usize),
}

/// Ids, element storage and version of a model's topology.
#[derive(Debug, Clone)]
pub struct Topology {
    pub(super) nodes: IdMap,
    pub(super) elements: IdMap,
    pub(super) store: Vec<Store>,
    /// The cell each cell was copied from (itself for cells of the built model).
    pub(super) source: Vec<usize>,
    pub(super) version: u64,
}

impl Topology {
    /// The topology of a built model: `n_nodes` nodes, cells of `cell_nodes[c]` nodes,
    /// `element_cell[i]` the cell of element `i`, the other cells explicit shells in cell
    /// order (BT4 on quadrilaterals, BLT3 on triangles).
    pub(super) fn built(n_nodes: usize, cell_nodes: &[usize], element_cell: &[usize]) -> Self {
        let n_cells = cell_nodes.len();
        let mut store = vec![None; n_cells];
        for (i, &c) in element_cell.iter().enumerate() {
            store[c] = Some(Store::Element(i));
        }
        let (mut n_bt4, mut n_blt3) = (0, 0);
        let store = store
            .into_iter()
            .zip(cell_nodes)
            .map(|(s, &n)| {
                s.unwrap_or_else(|| {
                    let (count, store): (&mut usize, fn(usize) -> Store) =
                        if n == 4 { (&mut n_bt4, Store::Bt4) } else { (&mut n_blt3, Store::Blt3) };
                    *count += 1;
                    store(*count - 1)
                })
            })
            .collect();
        Topology {
            nodes: IdMap::identity(n_nodes),
            elements: IdMap::identity(n_cells),
            store,
            source: (0..n_cells).collect(),
            version: 1,
        }
    }

    /// Node ids and slots.
    pub fn nodes(&self) -> &IdMap {
        &self.nodes
    }

    /// Element (mesh cell) ids and slots.
    pub fn elements(&self) -> &IdMap {
        &self.elements
    }

    /// Where the element in cell slot `c` is stored.
    pub fn store(&self, c: usize) -> Option<Store> {
        self.store.get(c).copied()
    }

    /// 1 for the model as built, increased by every change at run time: what a coupled run
    /// publishes as `topology_version`.
    pub fn version(&self) -> u64 {
        self.version
    }
}

/// A topology change or record that cannot be applied.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TopologyError {
    #[error("{kind} id {id} is given twice or already taken")]
    TakenId { kind: &'static str, id: u64 },
    #[error("{what}: {got} {kind} ids for {expected} {kind}s")]
    IdCount { what: &'static str, kind: &'static str, got: usize, expected: usize },
    #[error("no node has id {id}")]
    UnknownNode { id: u64 },
    #[error("no element has id {id}")]
    UnknownElement { id: u64 },
    #[error("element {element}: {got} nodes given, the element has {expected}")]
    NodeCount { element: u64, got: usize, expected: usize },
    #[error(
        "element {element}: node {node} is at {got:?} in the reference configuration, the \
         copied element's node at {expected:?}"
    )]
    Reference { element: u64, node: u64, got: [f64; 3], expected: [f64; 3] },
    #[error("node {node}: {field} is not finite")]
    NotFinite { node: u64, field: &'static str },
    #[error("topology record: {0}")]
    Record(String),
}

impl FeModel {
    /// The model's ids, element storage and version.
    pub fn topology(&self) -> &Topology {
        &self.topology
    }

    /// The version of the topology (1 as built; see [`Topology::version`]).
    pub fn topology_version(&self) -> u64 {
        self.topology.version
    }

    /// Gives nodes and elements (mesh cells) the user's ids, one per slot; refuses an id
    /// given twice or a list of another length.
    pub fn set_ids(
        &mut self,
        node_ids: Vec<u64>,
        element_ids: Vec<u64>,
    ) -> Result<(), TopologyError> {
        let t = &self.topology;
        for (kind, got, expected) in [
            ("node", node_ids.len(), t.nodes.len()),
            ("element", element_ids.len(), t.elements.len()),
        ] {
            if got != expected {
                return Err(TopologyError::IdCount { what: "set_ids", kind, got, expected });
            }
        }
        let nodes =
            IdMap::from_ids(node_ids).map_err(|id| TopologyError::TakenId { kind: "node", id })?;
        let elements = IdMap::from_ids(element_ids)
            .map_err(|id| TopologyError::TakenId { kind: "element", id })?;
        self.topology.nodes = nodes;
        self.topology.elements = elements;
        Ok(())
    }

    /// The slot of node `id`.
    pub(super) fn node_slot(&self, id: u64) -> Result<usize, TopologyError> {
        self.topology.nodes.slot(id).ok_or(TopologyError::UnknownNode { id })
    }
}
