//! Alg. 4.2 (thesis §4.3.1, collision based): every fluid edge whose box meets a triangle box is
//! tested against that triangle with the exact crossing test of [`super::super::predicates`].
//!
//! - Step 3.1: a node within `OCCLUSION * h_min(i)` of a triangle (distance to its closest point,
//!   where phi `>= 0`) is occluded.
//! - Step 4: an edge is cut where it crosses a triangle at a point with interpolated phi `>= 0`
//!   (§4.3.3: the crack's phantom part is not a wall); of several crossings the one nearest to
//!   node `i` is kept. The exact test is symmetric in the two ends, so the thesis' second ray
//!   from `j` to `i` (there to discard false positives of a rounded test) would find the same.
//! - Step 4.2: an edge with an occluded end and no crossing is cut at that end (α = 0 or 1), on
//!   the triangle nearest to it.
//!
//! Doubly cut edges of thin bodies are found, and an open surface needs no inside.

use super::crossings::GROUP;
use super::near::AHEAD;
use super::{Crossing, Intersections, Near, SurfaceAt};
use crate::embedded::adjacency::NodeEdges;
use crate::embedded::CutEdge;
use crate::mesh::Mesh;
use crate::prefetch::prefetch;
use rayon::prelude::*;

/// Near nodes per parallel task.
const CHUNK: usize = 64;

/// Cut edges and occluded nodes of `mesh` against the surface at positions `at.x` (Alg. 4.2),
/// testing every node and edge.
pub fn collision(mesh: &Mesh, adjacency: &NodeEdges, at: SurfaceAt<'_>) -> Intersections {
    collision_near(mesh, adjacency, at, &Near::all(mesh))
}

/// [`collision()`] testing only the nodes and edges of `near` (which must hold every node and
/// edge the hierarchy's boxes can reach: [`Near::find`]).
///
/// Node by node: each edge `[i, j]` (`i < j`) is tested at its node `i` against the triangles
/// recorded for `i` (they hold every triangle whose box meets the edge's), once both its ends are
/// near (an end that is not has a reach box, holding the edge, that meets no triangle box). A
/// node's position and list are read once for all its edges, and the cuts come out in edge order
/// (the edges are sorted by `(i, j)`).
pub fn collision_near(
    mesh: &Mesh,
    adjacency: &NodeEdges,
    at: SurfaceAt<'_>,
    near: &Near,
) -> Intersections {
    collision_grouped::<GROUP>(mesh, adjacency, at, near)
}

/// [`collision_near`] scanning the edges of a node by groups of `G`.
fn collision_grouped<const G: usize>(
    mesh: &Mesh,
    adjacency: &NodeEdges,
    at: SurfaceAt<'_>,
    near: &Near,
) -> Intersections {
    debug_assert_eq!(adjacency.h_min.len(), mesh.n_nodes(), "adjacency of another mesh");
    let occluded = at.occluded(mesh, &adjacency.h_min, true, near);
    let pass = Pass { mesh, adjacency, at, near, occluded: &occluded };
    let cuts: Vec<CutEdge> = near
        .nodes
        .par_chunks(CHUNK)
        .flat_map_iter(|chunk| {
            let (mut cuts, mut ends) = (Vec::new(), Vec::new());
            for (k, &i) in chunk.iter().enumerate() {
                pass.prefetch_ahead(chunk, k);
                pass.node_cuts::<G>(i as usize, &mut ends, &mut cuts);
            }
            cuts
        })
        .collect();
    Intersections::from_sorted(mesh, cuts, occluded)
}

/// What the cuts of one pass read: the mesh, the surface, the near part and the occluded nodes.
#[derive(Clone, Copy)]
struct Pass<'a> {
    mesh: &'a Mesh,
    adjacency: &'a NodeEdges,
    at: SurfaceAt<'a>,
    near: &'a Near,
    occluded: &'a [bool],
}

impl Pass<'_> {
    /// Prefetch hints ([`crate::prefetch`]) for the nodes after `nodes[k]`, each row a few
    /// nodes before the loads that depend on it: the near part's ([`Near::prefetch_ahead`]),
    /// the bounds of the owned edges, the owned edges, their ends, the ends' coordinates and
    /// list bounds.
    #[inline]
    fn prefetch_ahead(&self, nodes: &[u32], k: usize) {
        let (mesh, adjacency, near) = (self.mesh, self.adjacency, self.near);
        near.prefetch_ahead(mesh, nodes, k);
        let at = |d: usize| nodes.get(k + d).map(|&i| i as usize);
        if let Some(i) = at(AHEAD) {
            adjacency.prefetch_owned(i, false);
        }
        if let Some(i) = at(AHEAD / 2) {
            adjacency.prefetch_owned(i, true);
        }
        if let Some(i) = at(2) {
            let owned = adjacency.owned_by(i);
            for &e in owned.first().into_iter().chain(owned.last()) {
                prefetch(&mesh.edges, e as usize);
            }
        }
        if let Some(i) = at(1) {
            for &e in adjacency.owned_by(i) {
                let j = mesh.edges[e as usize][1] as usize;
                prefetch(&mesh.coords, j);
                near.prefetch_list(j, false);
            }
        }
    }

    /// Adds to `cuts` the cuts of the edges `[i, j]` of node `i` with `j > i` near, in edge
    /// order: each edge's crossing nearest to node `i` (step 4,
    /// [`SurfaceAt::for_each_crossing_from`] by groups of `G`), else its occluded end (step 4.2);
    /// `ends` is a buffer.
    fn node_cuts<const G: usize>(
        &self,
        i: usize,
        ends: &mut Vec<(usize, usize)>,
        cuts: &mut Vec<CutEdge>,
    ) {
        let (mesh, near) = (self.mesh, self.near);
        ends.clear();
        for &e in self.adjacency.owned_by(i) {
            let j = mesh.edges[e as usize][1] as usize;
            if !near.triangles_of(j).is_some_and(|l| l.is_empty()) {
                ends.push((e as usize, j));
            }
        }
        self.at.for_each_crossing_from::<G>(mesh, near, i, ends, true, |e, best| {
            cuts.extend(self.edge_cut(e, best))
        });
    }

    /// The cut of edge `e` from its nearest crossing `best` (step 4), else at its occluded end
    /// (step 4.2), if any.
    fn edge_cut(&self, e: usize, best: Option<Crossing>) -> Option<CutEdge> {
        let at = &self.at;
        if let Some(c) = best {
            return Some(c.cut(at, e));
        }
        let [i, j] = self.mesh.edges[e].map(|v| v as usize);
        // Step 4.2: the occluded end is the intersection point.
        [(i, 0.0), (j, 1.0)].into_iter().filter(|&(end, _)| self.occluded[end]).find_map(
            |(end, alpha)| {
                let r = super::OCCLUSION * self.adjacency.h_min[end];
                let p = self.mesh.coords[end];
                let (t, cp) = at.nearest_point(p, r, true, Some((self.near, end)), None)?;
                Some(at.cut(e, t, alpha, cp.bary))
            },
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::embedded::bvh::Bvh;
    use crate::embedded::intersect::NodeBoxes;
    use crate::embedded::tests::{cube_mesh, sphere};

    /// The node scan gives the full pass's cuts whatever the group of edges read together: one
    /// edge, several groups per node, all of a node's edges at once.
    #[test]
    fn every_group_size_gives_the_full_pass() {
        let mesh = cube_mesh(9, 0.3, 5);
        let adj = NodeEdges::build(&mesh);
        let boxes = NodeBoxes::build(&mesh, &adj);
        let s = sphere([0.48, 0.52, 0.5], 0.3, 10);
        let bvh = Bvh::build(&s, 1e-9);
        let near = Near::find(&mesh, &boxes, &bvh);
        let at = SurfaceAt::at_end(&s, &bvh).unwrap();
        let full = collision(&mesh, &adj, at);
        assert!(full.cuts.len() > 100, "{} cuts", full.cuts.len());
        assert_eq!(collision_grouped::<1>(&mesh, &adj, at, &near), full);
        assert_eq!(collision_grouped::<3>(&mesh, &adj, at, &near), full);
        assert_eq!(collision_grouped::<32>(&mesh, &adj, at, &near), full);
    }
}
