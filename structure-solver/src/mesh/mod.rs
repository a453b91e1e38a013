//! Structural meshes: nodes, cells of the element families, and named node and cell sets
//! (supports, load points, the wet surface). Generators for the benchmark geometries
//! (`generate`), a gmsh reader (`gmsh`), the merge of generated seams (`merge`), the
//! validity pass every mesh goes through (`validate`) and the locality renumbering of the
//! model build (`renumber`), which keeps the user's numbering apart from storage slots.

use std::collections::BTreeMap;

pub use renumber::Numbering;

pub mod generate;
pub mod gmsh;
pub mod merge;
pub mod renumber;
pub mod validate;

/// Cell shapes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CellKind {
    Line2,
    Tri3,
    Quad4,
    Tet4,
}

impl CellKind {
    pub fn n_nodes(self) -> usize {
        match self {
            CellKind::Line2 => 2,
            CellKind::Tri3 => 3,
            CellKind::Quad4 | CellKind::Tet4 => 4,
        }
    }
}

/// One cell: its shape and node indices.
#[derive(Debug, Clone, PartialEq)]
pub struct Cell {
    pub kind: CellKind,
    pub nodes: Vec<usize>,
}

/// Nodes, cells and named sets.
#[derive(Debug, Clone, Default)]
pub struct Mesh {
    pub nodes: Vec<[f64; 3]>,
    pub cells: Vec<Cell>,
    pub node_sets: BTreeMap<String, Vec<usize>>,
    pub cell_sets: BTreeMap<String, Vec<usize>>,
    /// The user's id of each node slot (a gmsh node tag); empty: the user's number
    /// ([`Mesh::node_user`], the generator id) is the id.
    pub node_ids: Vec<u64>,
    /// Node slots and the user's node numbers (input order); identity until renumbered.
    pub node_numbering: Numbering,
    /// Cell slots and the user's cell numbers (input order); identity until renumbered.
    pub cell_numbering: Numbering,
}

impl Mesh {
    /// The user's id of node slot `i`, for messages: its gmsh tag, else its user number.
    pub fn node_id(&self, i: usize) -> u64 {
        self.node_ids.get(i).copied().unwrap_or(self.node_user(i) as u64)
    }

    /// The user's number (input position) of node slot `i`.
    pub fn node_user(&self, i: usize) -> usize {
        self.node_numbering.user_of(i)
    }

    /// The user's number (input position) of cell slot `c`: the cell of messages and outputs.
    pub fn cell_user(&self, c: usize) -> usize {
        self.cell_numbering.user_of(c)
    }

    /// The node slots in the user's order.
    pub fn nodes_in_user_order(&self) -> Vec<usize> {
        self.node_numbering.slots_in_user_order(self.nodes.len())
    }

    /// The cell slots in the user's order.
    pub fn cells_in_user_order(&self) -> Vec<usize> {
        self.cell_numbering.slots_in_user_order(self.cells.len())
    }

    /// Adds a node at `p` (with the next free user id when nodes have ids, and the next user
    /// number); returns its slot.
    pub fn push_node(&mut self, p: [f64; 3]) -> usize {
        if !self.node_ids.is_empty() {
            let next = self.node_ids.iter().max().map_or(0, |m| m + 1);
            self.node_ids.push(next);
        }
        self.node_numbering.push(self.nodes.len());
        self.nodes.push(p);
        self.nodes.len() - 1
    }

    /// The nodes of set `name`, or an error naming the set and the ones that exist.
    pub fn node_set(&self, name: &str) -> Result<&[usize], MeshError> {
        self.node_sets.get(name).map(|v| v.as_slice()).ok_or_else(|| MeshError::UnknownSet {
            name: name.to_string(),
            known: self.node_sets.keys().cloned().collect(),
        })
    }

    /// The cells of set `name`.
    pub fn cell_set(&self, name: &str) -> Result<&[usize], MeshError> {
        self.cell_sets.get(name).map(|v| v.as_slice()).ok_or_else(|| MeshError::UnknownSet {
            name: name.to_string(),
            known: self.cell_sets.keys().cloned().collect(),
        })
    }

    /// The node nearest to `p`; of equally near ones the first slot (once renumbered, an
    /// order set by the geometry, not by the input numbering).
    pub fn nearest_node(&self, p: [f64; 3]) -> usize {
        let d2 = |q: &[f64; 3]| (0..3).map(|c| (q[c] - p[c]).powi(2)).sum::<f64>();
        (0..self.nodes.len())
            .min_by(|&a, &b| d2(&self.nodes[a]).total_cmp(&d2(&self.nodes[b])))
            .unwrap_or(0)
    }

    /// Nodes satisfying `pred`, in index order.
    pub fn nodes_where(&self, pred: impl Fn(&[f64; 3]) -> bool) -> Vec<usize> {
        (0..self.nodes.len()).filter(|&i| pred(&self.nodes[i])).collect()
    }

    /// Splits every quad into two triangles along its 1-3 diagonal; sets keep their cells,
    /// which are numbered anew (split before renumbering).
    pub fn to_triangles(&self) -> Mesh {
        let mut cells = Vec::new();
        let mut map = Vec::with_capacity(self.cells.len());
        for c in &self.cells {
            let first = cells.len();
            if c.kind == CellKind::Quad4 {
                let n = &c.nodes;
                cells.push(Cell { kind: CellKind::Tri3, nodes: vec![n[0], n[1], n[2]] });
                cells.push(Cell { kind: CellKind::Tri3, nodes: vec![n[0], n[2], n[3]] });
            } else {
                cells.push(c.clone());
            }
            map.push(first..cells.len());
        }
        let cell_sets = self
            .cell_sets
            .iter()
            .map(|(k, v)| (k.clone(), v.iter().flat_map(|&c| map[c].clone()).collect()))
            .collect();
        Mesh {
            nodes: self.nodes.clone(),
            cells,
            node_sets: self.node_sets.clone(),
            cell_sets,
            node_ids: self.node_ids.clone(),
            node_numbering: self.node_numbering.clone(),
            ..Mesh::default()
        }
    }
}

/// Mesh errors: reading, unknown sets, unsupported cells.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    #[error("unknown set `{name}` (known: {known:?})")]
    UnknownSet { name: String, known: Vec<String> },
    #[error("{file}: {message}")]
    Read { file: String, message: String },
}
