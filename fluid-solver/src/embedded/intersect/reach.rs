//! The reach box of each mesh node (the box of the node and its neighbours, widened by the
//! largest occlusion radius `ρ`: the box every pass searches around the node, [`super::near`])
//! and the hierarchy over them, built once per mesh.

use super::OCCLUSION;
use crate::embedded::adjacency::NodeEdges;
use crate::embedded::bvh::Bvh;
use crate::mesh::Mesh;

/// The hierarchy over the reach boxes of the mesh nodes (module docs), built once per mesh.
#[derive(Debug, Clone, PartialEq)]
pub struct NodeBoxes {
    pub(super) tree: Bvh,
    /// The largest occlusion radius of a node, by which every reach box is widened (so a node's
    /// box holds the occlusion ball of each of its neighbours, and an edge with an occluded end
    /// has both ends near) and the halves of each reach box overlap.
    pub(super) rho: f64,
}

impl NodeBoxes {
    pub fn build(mesh: &Mesh, adjacency: &NodeEdges) -> NodeBoxes {
        let reach = ReachBoxes::computed(mesh, adjacency);
        let (lo, hi) = (0..mesh.n_nodes()).map(|i| reach.of(i)).unzip();
        NodeBoxes { tree: Bvh::over_boxes(lo, hi), rho: reach.rho() }
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.tree.len()
    }

    pub fn is_empty(&self) -> bool {
        self.tree.is_empty()
    }

    /// Memory in bytes.
    pub fn memory_bytes(&self) -> usize {
        self.tree.memory_bytes()
    }
}

/// The reach boxes of the nodes of a mesh: read from [`NodeBoxes`], or computed as it computes
/// them (the same values).
#[derive(Clone, Copy)]
pub enum ReachBoxes<'a> {
    Stored(&'a NodeBoxes),
    Computed { mesh: &'a Mesh, adjacency: &'a NodeEdges, rho: f64 },
}

impl<'a> ReachBoxes<'a> {
    /// The reach boxes of `mesh` computed from its adjacency, widened by the largest occlusion
    /// radius of a node.
    pub fn computed(mesh: &'a Mesh, adjacency: &'a NodeEdges) -> ReachBoxes<'a> {
        let radius = |h: f64| Some(OCCLUSION * h).filter(|r| r.is_finite());
        let rho = adjacency.h_min.iter().filter_map(|&h| radius(h)).fold(0.0, f64::max);
        ReachBoxes::Computed { mesh, adjacency, rho }
    }

    /// The widening `ρ` of every box.
    pub fn rho(&self) -> f64 {
        match self {
            ReachBoxes::Stored(boxes) => boxes.rho,
            ReachBoxes::Computed { rho, .. } => *rho,
        }
    }

    /// The reach box of node `i`.
    #[inline]
    pub fn of(&self, i: usize) -> ([f64; 3], [f64; 3]) {
        match self {
            ReachBoxes::Stored(boxes) => boxes.tree.triangle_box(i),
            ReachBoxes::Computed { mesh, adjacency, rho } => {
                let (lo, hi) = adjacency.node_box(mesh, i);
                (lo.map(|v| v - rho), hi.map(|v| v + rho))
            }
        }
    }
}
