//! The near part of the mesh ([`Near`]) from node-triangle pairs kept over several steps: a
//! Verlet list with a skin, the classic way particle codes avoid a neighbour search every step.
//!
//! At a rebuild every triangle box of the hierarchy is widened by the skin `δ` and the pairs of
//! reach boxes and widened boxes are found by the tree traversal [`Near::find`] uses. While
//! each triangle's current (swept, padded) box stays inside its widened one, a pair whose boxes
//! overlap now is among the kept pairs, so filtering the kept pairs by the current boxes gives
//! exactly the pairs of a fresh traversal: [`NearSkin::find`] equals [`Near::find`] (tested),
//! at the cost of a linear pass. A triangle that leaves its widened box, a new topology or a new
//! hierarchy size triggers the next rebuild. Nothing here is state of the run: a restarted run
//! rebuilds at its first step and gets the same [`Near`].

use super::near::{group_by_node, par_node_chunks, Lists, Near, NodeBoxes, Split};
use crate::embedded::adjacency::NodeEdges;
use crate::embedded::bvh::{overlaps, Bvh};
use crate::mesh::Mesh;

/// Skin width relative to the mean shortest edge at the mesh nodes: a surface moving a tenth of
/// a cell per step rebuilds about every fifth step.
pub const SKIN: f64 = 0.5;

/// Node-triangle pairs within the skin, grouped by node (module docs).
#[derive(Debug, Clone, Default)]
pub struct NearSkin {
    /// Width added on every side of every triangle box at a rebuild.
    skin: f64,
    /// The widened boxes of the last rebuild.
    lo: Vec<[f64; 3]>,
    hi: Vec<[f64; 3]>,
    topology_version: u64,
    /// Kept triangles of node `i`: `kept[offsets[i]..offsets[i + 1]]`, ascending.
    offsets: Vec<u32>,
    kept: Vec<u32>,
    /// The nodes with kept triangles, ascending.
    kept_nodes: Vec<u32>,
    /// Rebuilds so far (run statistics).
    pub rebuilds: usize,
}

impl NearSkin {
    /// An empty skin (the first [`NearSkin::find`] rebuilds) of width [`SKIN`] times the mean
    /// of the finite `h_min` of `adjacency`.
    pub fn new(adjacency: &NodeEdges) -> NearSkin {
        let finite = adjacency.h_min.iter().filter(|h| h.is_finite());
        let (sum, n) = finite.fold((0.0, 0usize), |(s, n), h| (s + h, n + 1));
        let h = if n > 0 { sum / n as f64 } else { 0.0 };
        NearSkin { skin: SKIN * h, ..NearSkin::default() }
    }

    /// Whether the kept pairs hold every overlapping pair of `bvh`'s current boxes.
    fn holds(&self, bvh: &Bvh) -> bool {
        bvh.topology_version == self.topology_version
            && bvh.len() == self.lo.len()
            && (0..bvh.len()).all(|t| {
                let (lo, hi) = bvh.triangle_box(t);
                (0..3).all(|d| lo[d] >= self.lo[t][d] && hi[d] <= self.hi[t][d])
            })
    }

    /// Widens the current boxes of `bvh` and keeps the pairs they make with the reach boxes.
    fn rebuild(&mut self, boxes: &NodeBoxes, bvh: &Bvh) {
        let s = self.skin;
        (self.lo, self.hi) = (0..bvh.len())
            .map(|t| {
                let (lo, hi) = bvh.triangle_box(t);
                (lo.map(|v| v - s), hi.map(|v| v + s))
            })
            .unzip();
        self.topology_version = bvh.topology_version;
        let widened = Bvh::over_boxes(self.lo.clone(), self.hi.clone());
        let pairs = boxes.tree.overlapping_pairs(&widened);
        (self.offsets, self.kept) = group_by_node(boxes.len(), &pairs);
        let offsets = &self.offsets;
        self.kept_nodes = (0..boxes.len() as u32)
            .filter(|&i| offsets[i as usize + 1] > offsets[i as usize])
            .collect();
        self.rebuilds += 1;
    }

    /// [`Near::find`] for `bvh`'s current boxes, from the kept pairs (rebuilt when they no
    /// longer hold every pair).
    pub fn find(
        &mut self,
        mesh: &Mesh,
        adjacency: &NodeEdges,
        boxes: &NodeBoxes,
        bvh: &Bvh,
    ) -> Near {
        debug_assert_eq!(boxes.len(), mesh.n_nodes(), "node boxes of another mesh");
        if !self.holds(bvh) {
            self.rebuild(boxes, bvh);
        }
        let rho = boxes.rho;
        let chunks: Vec<Lists> = par_node_chunks(&self.kept_nodes, |run| {
            let mut lists = Lists::default();
            for &i in run {
                let i_ = i as usize;
                let start = lists.len();
                let (lo, hi) = boxes.tree.triangle_box(i_);
                let split = Split::new(&mesh.coords[i_], rho);
                for &t in &self.kept[self.offsets[i_] as usize..self.offsets[i_ + 1] as usize] {
                    let (a, b) = bvh.triangle_box(t as usize);
                    if overlaps(&lo, &hi, &a, &b) {
                        lists.push(t, &split, &a, &b);
                    }
                }
                lists.close(i, start);
            }
            lists
        });
        Near::from_lists(mesh, adjacency, rho, chunks)
    }

    /// Memory in bytes.
    pub fn memory_bytes(&self) -> usize {
        use std::mem::size_of_val;
        size_of_val(&self.lo[..])
            + size_of_val(&self.hi[..])
            + size_of_val(&self.offsets[..])
            + size_of_val(&self.kept[..])
            + size_of_val(&self.kept_nodes[..])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::embedded::tests::{cube_mesh, sphere};

    /// A sphere moving a small and then a large distance per step: the skin's near part equals a
    /// fresh traversal every step, it rebuilds only when a box leaves the skin, and a jump of
    /// several cells rebuilds at once.
    #[test]
    fn the_skin_gives_the_fresh_near_part_and_rebuilds_only_when_a_box_leaves_it() {
        let mesh = cube_mesh(12, 0.3, 4);
        let adj = NodeEdges::build(&mesh);
        let boxes = NodeBoxes::build(&mesh, &adj);
        let rest = sphere([0.45, 0.5, 0.48], 0.25, 8);
        let mut surface = rest.clone();
        let mut bvh = Bvh::build(&surface, 1e-4);
        let mut skin = NearSkin::new(&adj);
        let h = 1.0 / 12.0;
        let mut shift = 0.0;
        for step in 1..=14 {
            shift += if step < 12 { 0.01 * h } else { 3.0 * h };
            let x: Vec<[f64; 3]> =
                rest.x_b.iter().map(|p| [p[0] + shift, p[1] - 0.5 * shift, p[2]]).collect();
            surface.advance(0.01 * step as f64, &x, &vec![[0.0; 3]; x.len()]);
            bvh.update(&surface);
            let fresh = Near::find(&mesh, &adj, &boxes, &bvh);
            assert!(!fresh.nodes.is_empty());
            assert_eq!(skin.find(&mesh, &adj, &boxes, &bvh), fresh, "step {step}");
            if step == 11 {
                // 0.11 h moved against a skin of half the mean shortest edge: one rebuild, the first.
                assert_eq!(skin.rebuilds, 1, "step {step}");
            }
        }
        // Each of the three jumps left the skin.
        assert_eq!(skin.rebuilds, 4);
    }
}
