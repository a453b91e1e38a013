//! The merge of coincident nodes of generated meshes: the seams of closed surfaces, and poles
//! where quadrilaterals collapse into triangles. Node sets follow; cells keep their indices.

use super::validate::{close_pairs, diagonal};
use super::{Cell, CellKind, Mesh};

/// Nodes closer than this fraction of the bounding-box diagonal are one node.
pub const TOLERANCE: f64 = 1e-9;

/// A cell that collapses to fewer nodes than any cell kind has.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Collapsed {
    pub cell: usize,
    pub kind: CellKind,
    pub nodes: usize,
}

/// Merges nodes closer than [`TOLERANCE`] of the mesh size into the first of them and turns
/// quadrilaterals collapsed at a pole into triangles.
pub fn merge_coincident(mesh: Mesh) -> Result<Mesh, Collapsed> {
    let tol = TOLERANCE * diagonal(&mesh.nodes).max(f64::MIN_POSITIVE);
    // Each node's representative: the first node it is close to (pairs sorted by that node).
    let mut rep: Vec<usize> = (0..mesh.nodes.len()).collect();
    let mut pairs = close_pairs(&mesh.nodes, tol);
    pairs.sort_unstable_by_key(|&(a, b)| (b, a));
    for (a, b) in pairs {
        rep[b] = rep[b].min(rep[a]);
    }
    let mut new_id = vec![usize::MAX; mesh.nodes.len()];
    let mut nodes = Vec::new();
    let mut node_ids = Vec::new();
    for i in 0..mesh.nodes.len() {
        new_id[i] = if rep[i] == i {
            nodes.push(mesh.nodes[i]);
            node_ids.push(mesh.node_id(i));
            nodes.len() - 1
        } else {
            new_id[rep[i]]
        };
    }
    let mut cells = Vec::with_capacity(mesh.cells.len());
    for (c, cell) in mesh.cells.iter().enumerate() {
        let mut ids: Vec<usize> = Vec::with_capacity(cell.nodes.len());
        for &n in &cell.nodes {
            if !ids.contains(&new_id[n]) {
                ids.push(new_id[n]);
            }
        }
        let kind = match (cell.kind, ids.len()) {
            (k, n) if n == k.n_nodes() => k,
            (CellKind::Quad4, 3) => CellKind::Tri3,
            (kind, nodes) => return Err(Collapsed { cell: c, kind, nodes }),
        };
        cells.push(Cell { kind, nodes: ids });
    }
    let node_sets = mesh
        .node_sets
        .into_iter()
        .map(|(name, v)| {
            let mut out: Vec<usize> = Vec::with_capacity(v.len());
            for n in v {
                if !out.contains(&new_id[n]) {
                    out.push(new_id[n]);
                }
            }
            (name, out)
        })
        .collect();
    Ok(Mesh { nodes, cells, node_sets, cell_sets: mesh.cell_sets, node_ids, ..Mesh::default() })
}
