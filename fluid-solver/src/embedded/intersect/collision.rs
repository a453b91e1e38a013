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

use super::{Crossing, Intersections, Near, SurfaceAt};
use crate::embedded::adjacency::NodeEdges;
use crate::embedded::bvh::overlaps;
use crate::embedded::predicates::orient;
use crate::embedded::CutEdge;
use crate::mesh::Mesh;
use rayon::prelude::*;

/// Near nodes per parallel task.
const CHUNK: usize = 64;
/// Edges of one node scanned together (one bit each of the halves table, at most 32).
const GROUP: usize = 16;

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
    let cuts: Vec<CutEdge> = near
        .nodes
        .par_chunks(CHUNK)
        .flat_map_iter(|chunk| {
            let mut cuts = Vec::new();
            for &i in chunk {
                node_cuts::<G>(mesh, adjacency, at, near, &occluded, i as usize, &mut cuts);
            }
            cuts
        })
        .collect();
    Intersections::from_sorted(mesh, cuts, occluded)
}

/// The cuts of the edges `[i, j]` of node `i` with `j > i` near, in edge order: each edge's
/// crossing nearest to node `i` (step 4), else its occluded end (step 4.2).
///
/// With `i`'s triangles recorded, its list is read once for up to `G` edges: a table over
/// the 64 sets of halves a triangle box can reach gives the edges whose box needs only halves of
/// that set ([`super::near::Split::needed`]), so each triangle meets just the edges it may overlap, the same
/// triangles [`Near::for_each_overlap`] gives each edge.
fn node_cuts<const G: usize>(
    mesh: &Mesh,
    adjacency: &NodeEdges,
    at: SurfaceAt<'_>,
    near: &Near,
    occluded: &[bool],
    i: usize,
    cuts: &mut Vec<CutEdge>,
) {
    let p = mesh.coords[i];
    let far = |j: usize| near.triangles_of(j).is_some_and(|l| l.is_empty());
    let Some((list, halves, split)) = near.recorded(i, &p) else {
        for &e in adjacency.owned_by(i) {
            let j = mesh.edges[e as usize][1] as usize;
            if !far(j) {
                let best = at.nearest_crossing(mesh, near, e as usize, i, true);
                edge_cut(mesh, adjacency, at, near, occluded, e as usize, best, cuts);
            }
        }
        return;
    };
    const { assert!(G > 0 && G <= 32, "one bit per edge of a group in a u32") };
    for group in adjacency.owned_by(i).chunks(G) {
        let mut table = [0u32; 64];
        let mut ends = [(0usize, p, p); G];
        for (k, &e) in group.iter().enumerate() {
            let j = mesh.edges[e as usize][1] as usize;
            if far(j) {
                continue;
            }
            let q = mesh.coords[j];
            let lo = [0, 1, 2].map(|d| p[d].min(q[d]));
            let hi = [0, 1, 2].map(|d| p[d].max(q[d]));
            ends[k] = (j, lo, hi);
            // Every superset of the halves the edge box needs, in increasing order.
            let need = split.needed(&lo, &hi);
            let mut set = need;
            loop {
                table[set as usize] |= 1 << k;
                if set == 63 {
                    break;
                }
                set = (set + 1) | need;
            }
        }
        let mut best = [None; G];
        for (&t, &h) in list.iter().zip(halves) {
            let mut edges = table[h as usize];
            if edges == 0 {
                continue;
            }
            let (tlo, thi) = at.bvh.triangle_box(t as usize);
            let corners = at.corners(t);
            // The side of node `i`, shared by its edges: computed at the first that needs it.
            let mut sp = None;
            while edges != 0 {
                let k = edges.trailing_zeros() as usize;
                edges &= edges - 1;
                let (j, lo, hi) = ends[k];
                if overlaps(&tlo, &thi, &lo, &hi) {
                    let [a, b, c] = corners;
                    let sp = *sp.get_or_insert_with(|| orient(a, b, c, p));
                    at.offer_crossing(p, mesh.coords[j], t, corners, sp, true, &mut best[k]);
                }
            }
        }
        for (k, &e) in group.iter().enumerate() {
            if !far(mesh.edges[e as usize][1] as usize) {
                edge_cut(mesh, adjacency, at, near, occluded, e as usize, best[k], cuts);
            }
        }
    }
}

/// The cut of edge `e` from its nearest crossing `best` (step 4), else at its occluded end
/// (step 4.2), if any.
#[allow(clippy::too_many_arguments)]
fn edge_cut(
    mesh: &Mesh,
    adjacency: &NodeEdges,
    at: SurfaceAt<'_>,
    near: &Near,
    occluded: &[bool],
    e: usize,
    best: Option<Crossing>,
    cuts: &mut Vec<CutEdge>,
) {
    if let Some(c) = best {
        cuts.push(c.cut(&at, e));
        return;
    }
    let [i, j] = mesh.edges[e].map(|v| v as usize);
    // Step 4.2: the occluded end is the intersection point.
    for (end, alpha) in [(i, 0.0), (j, 1.0)] {
        if occluded[end] {
            let r = super::OCCLUSION * adjacency.h_min[end];
            if let Some((t, cp)) =
                at.nearest_point(mesh.coords[end], r, true, Some((near, end)), None)
            {
                cuts.push(at.cut(e, t, alpha, cp.bary));
                return;
            }
        }
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
