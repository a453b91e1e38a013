//! The part of the fluid mesh the surface can touch in a step, so that the tracking passes cost
//! what the surface costs and not what the grid costs (thesis §4.1: the search structure serves
//! to "avoid testing every edge against every triangle"; here it also avoids testing every edge).
//!
//! Each node's *reach box* is the box of the node and its neighbours ([`NodeEdges::node_box`]),
//! widened by the largest occlusion radius `ρ = max OCCLUSION * h_min`. It holds every edge of the
//! node and the occlusion balls of the node and its neighbours, and it is the node's projection
//! box (Alg. 4.1 step 1, [`ReachBoxes`]). So a node whose reach box meets no swept triangle box of the hierarchy is neither
//! near nor occluded nor swept, and an edge is cut (crossed, or with an occluded end) only if the
//! reach boxes of both its ends meet a triangle box: each pass over [`Near`] gives
//! exactly what the same pass gives over the whole mesh. A static hierarchy over the reach boxes
//! ([`NodeBoxes`], built once with the mesh) is queried with each triangle box, in parallel, and
//! the pairs found are regrouped by node by counting (`by_node.rs`): the reach boxes are all
//! of a size, so each query costs about what it finds, with no query from the nodes inside a
//! closed surface that meet none.
//!
//! Those queries meet every pair of a node and a triangle whose boxes overlap, and [`Near`]
//! keeps them, grouped by node: each box a pass searches around node `i` (an edge of `i`, its
//! occlusion ball, its projection box, the node itself) lies in the reach box of `i`, so the
//! triangles recorded for `i` hold every triangle whose box meets it, and the pass tests those
//! instead of querying the tree from its root. An edge takes the triangles of its first end
//! (read once for all the edges that end starts: [`super::crossings`]), and none when an end is
//! not near: that end's reach box, which holds the edge, meets no triangle box.
//!
//! Each recorded pair also keeps which halves of the reach box, split at the node along each
//! axis, the triangle box reaches ([`Split::halves`]). A query box on one side of the node along an
//! axis (an edge leaving the node upwards in x, say) needs a triangle box reaching that half, so
//! a pass first tests those six bits and then the box itself: the same triangles, from a scan
//! that skips most of the list without reading the triangle boxes.

use super::by_node::{concat, join_offsets, pairs_by_node, par_node_chunks};
pub(super) use super::halves::Split;
pub use super::reach::{NodeBoxes, ReachBoxes};
use crate::embedded::adjacency::{ascending_once, NodeEdges};
use crate::embedded::bvh::{overlaps, Bvh};
use crate::mesh::Mesh;
use crate::prefetch::prefetch;

/// Places ahead in its node list at which a pass hints the rows it will read
/// ([`Near::prefetch_ahead`]): the near nodes lie scattered over the mesh arrays, and each
/// node's rows are a chain of loads (bounds, then list).
pub const AHEAD: usize = 8;

/// The mesh nodes whose reach box meets a triangle box, ascending (their edges: [`Near::edges`]);
/// with, from [`Near::find`], the triangles whose box meets each node's reach box and the halves
/// of it each reaches.
#[derive(Debug, Clone, PartialEq)]
pub struct Near {
    pub nodes: Vec<u32>,
    /// The triangles of node `i` are `triangles[offsets[i]..offsets[i + 1]]` (`offsets` has one
    /// entry per mesh node and one more); empty for the full passes of [`Near::all`].
    offsets: Vec<u32>,
    triangles: Vec<u32>,
    /// Per recorded triangle, the halves of the node's reach box its box reaches ([`Split::halves`]).
    halves: Vec<u8>,
    /// The recorded nodes with a triangle box reaching every half of their reach box, ascending:
    /// the only ones that can be occluded ([`Near::occlusion_candidates`]).
    inside_a_box: Vec<u32>,
    /// The widening of the halves ([`NodeBoxes::rho`]).
    rho: f64,
}

/// The triangle lists of a run of nodes: the nodes with a non-empty list (ascending), the length
/// of each, the triangles and their halves.
#[derive(Debug, Default)]
pub(super) struct Lists {
    nodes: Vec<u32>,
    counts: Vec<u32>,
    triangles: Vec<u32>,
    halves: Vec<u8>,
    inside_a_box: Vec<u32>,
}

impl Lists {
    /// Adds triangle `t`, whose box is `[lo, hi]`, to the list being written of the node split
    /// by `split`.
    #[inline]
    pub fn push(&mut self, t: u32, split: &Split, lo: &[f64; 3], hi: &[f64; 3]) {
        self.triangles.push(t);
        self.halves.push(split.halves(lo, hi));
    }

    /// Adds the triangles of `candidates` whose box (`box_of`) overlaps `[lo, hi]` to the list
    /// being written of the node split by `split`: every candidate is written and the length
    /// advanced by the outcome of the test, so the pass does not branch on it.
    #[inline]
    pub fn push_overlapping(
        &mut self,
        candidates: impl ExactSizeIterator<Item = u32>,
        split: &Split,
        lo: &[f64; 3],
        hi: &[f64; 3],
        box_of: impl Fn(usize) -> ([f64; 3], [f64; 3]),
    ) {
        let start = self.triangles.len();
        self.triangles.resize(start + candidates.len(), 0);
        self.halves.resize(start + candidates.len(), 0);
        let (triangles, halves) = (&mut self.triangles[start..], &mut self.halves[start..]);
        let filter = split.filter(lo, hi);
        let mut len = 0;
        for t in candidates {
            let (a, b) = box_of(t as usize);
            let (h, meets) = filter.test(&a, &b);
            triangles[len] = t;
            halves[len] = h;
            len += usize::from(meets);
        }
        self.triangles.truncate(start + len);
        self.halves.truncate(start + len);
    }

    /// Ends the list of node `i`, begun when `start` triangles were written (an empty one is
    /// dropped).
    #[inline]
    pub fn close(&mut self, i: u32, start: usize) {
        let count = self.triangles.len() - start;
        if count > 0 {
            self.nodes.push(i);
            self.counts.push(count as u32);
        }
        if self.halves[start..].contains(&Split::EVERY_HALF) {
            self.inside_a_box.push(i);
        }
    }

    pub fn len(&self) -> usize {
        self.triangles.len()
    }
}

impl Near {
    /// Every node and edge (the full passes), queried from the root of the hierarchy.
    pub fn all(mesh: &Mesh) -> Near {
        Near {
            nodes: (0..mesh.n_nodes() as u32).collect(),
            offsets: Vec::new(),
            triangles: Vec::new(),
            halves: Vec::new(),
            inside_a_box: Vec::new(),
            rho: 0.0,
        }
    }

    /// The nodes of `boxes` whose reach boxes meet a triangle box of `bvh`, with the triangles
    /// each reach box meets (ascending). [`super::skin::NearSkin`] gives the same
    /// from pairs kept over several steps.
    pub fn find(mesh: &Mesh, boxes: &NodeBoxes, bvh: &Bvh) -> Near {
        debug_assert_eq!(boxes.len(), mesh.n_nodes(), "node boxes of another mesh");
        let (listed, offsets, triangles) = pairs_by_node(boxes, bvh.len(), |t| bvh.triangle_box(t));
        let rho = boxes.rho;
        let chunks: Vec<Lists> = par_node_chunks(&listed, |run| {
            let mut lists = Lists::default();
            for &i in run {
                let start = lists.len();
                let i_ = i as usize;
                let split = Split::new(&mesh.coords[i_], rho);
                for &t in &triangles[offsets[i_] as usize..offsets[i_ + 1] as usize] {
                    let (lo, hi) = bvh.triangle_box(t as usize);
                    lists.push(t, &split, &lo, &hi);
                }
                lists.close(i, start);
            }
            lists
        });
        Near::from_lists(mesh.n_nodes(), &listed, rho, chunks)
    }

    /// The near part from the triangle lists written by [`par_node_chunks`] over the ascending
    /// `candidates` (each list ascending): the nodes with a non-empty list, joined in parallel.
    pub(super) fn from_lists(n: usize, candidates: &[u32], rho: f64, chunks: Vec<Lists>) -> Near {
        let runs: Vec<_> = chunks.iter().map(|c| (&c.nodes[..], &c.counts[..])).collect();
        let (nodes, offsets) = join_offsets(n, candidates, &runs);
        let triangles = concat(&chunks.iter().map(|c| &c.triangles[..]).collect::<Vec<_>>());
        let halves = concat(&chunks.iter().map(|c| &c.halves[..]).collect::<Vec<_>>());
        let inside_a_box = concat(&chunks.iter().map(|c| &c.inside_a_box[..]).collect::<Vec<_>>());
        Near { nodes, offsets, triangles, halves, inside_a_box, rho }
    }

    /// Every edge touching a node of the near part, ascending (through a bit set over the edges).
    pub fn edges(&self, mesh: &Mesh, adjacency: &NodeEdges) -> Vec<u32> {
        let edges = self.nodes.iter().flat_map(|&i| adjacency.edges_of(i as usize));
        ascending_once(mesh.n_edges(), edges.copied())
    }

    /// Prefetch hints ([`crate::prefetch`]) for a pass at place `k` of `nodes`: the coordinates
    /// and list bounds of the node [`AHEAD`] places on, the list of the node half as far.
    #[inline]
    pub fn prefetch_ahead(&self, mesh: &Mesh, nodes: &[u32], k: usize) {
        if let Some(&i) = nodes.get(k + AHEAD) {
            prefetch(&mesh.coords, i as usize);
            self.prefetch_list(i as usize, false);
        }
        if let Some(&i) = nodes.get(k + AHEAD / 2) {
            self.prefetch_list(i as usize, true);
        }
    }

    /// Prefetch hints ([`crate::prefetch`]) for the list of node `i`: its bounds, then (once
    /// those are in cache) the list.
    #[inline]
    pub fn prefetch_list(&self, i: usize, list: bool) {
        match self.offsets.get(i) {
            Some(&a) if list => {
                prefetch(&self.triangles, a as usize);
                prefetch(&self.halves, a as usize);
            }
            _ => prefetch(&self.offsets, i),
        }
    }

    /// The nodes that can be occluded: with triangles recorded, those with a triangle box
    /// reaching every half of their reach box (an occlusion search looks at the triangle boxes
    /// meeting the box of half-width `OCCLUSION * h_min <= ρ` around the node, and those reach
    /// every half), else every node.
    pub fn occlusion_candidates(&self) -> &[u32] {
        match self.offsets.is_empty() {
            true => &self.nodes,
            false => &self.inside_a_box,
        }
    }

    /// The triangles whose box meets the reach box of node `i`, if recorded ([`Near::find`]).
    #[inline]
    pub fn triangles_of(&self, i: usize) -> Option<&[u32]> {
        let (a, b) = (*self.offsets.get(i)?, *self.offsets.get(i + 1)?);
        Some(&self.triangles[a as usize..b as usize])
    }

    /// The triangles recorded for node `i` at `p` with the halves of its reach box each reaches
    /// and the split that tells the halves a query needs ([`Split::needed`]), if recorded
    /// ([`Near::find`]).
    #[inline]
    pub(super) fn recorded(&self, i: usize, p: &[f64; 3]) -> Option<(&[u32], &[u8], Split)> {
        let (a, b) = (*self.offsets.get(i)? as usize, *self.offsets.get(i + 1)? as usize);
        Some((&self.triangles[a..b], &self.halves[a..b], Split::new(p, self.rho)))
    }

    /// Calls `visit` with every triangle of `bvh` whose box overlaps `[lo, hi]`, a box inside the
    /// reach box of node `i` at `p` (the node's edges, its occlusion ball, the reach box itself):
    /// from the triangles recorded for `i` that reach the halves the box needs
    /// ([`Split::halves`]), else (none recorded, [`Near::all`]) by a query from the root. The same triangles either way (a
    /// triangle box meeting `[lo, hi]` meets the reach box), in another order. `bvh` must be the
    /// hierarchy `find` was given, unchanged since.
    #[inline]
    pub fn for_each_overlap(
        &self,
        bvh: &Bvh,
        i: usize,
        p: &[f64; 3],
        lo: &[f64; 3],
        hi: &[f64; 3],
        mut visit: impl FnMut(u32),
    ) {
        let (Some(&a), Some(&b)) = (self.offsets.get(i), self.offsets.get(i + 1)) else {
            return bvh.for_each_overlap(lo, hi, visit);
        };
        let (a, b) = (a as usize, b as usize);
        let need = Split::new(p, self.rho).needed(lo, hi);
        for (&t, &h) in self.triangles[a..b].iter().zip(&self.halves[a..b]) {
            if h & need == need {
                let (tlo, thi) = bvh.triangle_box(t as usize);
                if overlaps(&tlo, &thi, lo, hi) {
                    visit(t);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::embedded::intersect::{collision, collision_near, projection, projection_near};
    use crate::embedded::intersect::{Intersections, SurfaceAt, OCCLUSION};
    use crate::embedded::status::swept_nodes_near;
    use crate::embedded::status::NodeStatus;
    use crate::embedded::status::{flood_fill, swept_nodes, swept_nodes_among, update_sides};
    use crate::embedded::tests::{box_surface, cube_mesh, plane, sphere};
    use crate::embedded::tracker::{Seed, Tracker};
    use crate::embedded::Surface;
    use interface_protocol::case::Tracking;

    /// Every pass over `Near::find` gives what the pass over the whole mesh gives, and `Near`
    /// is much smaller than the mesh.
    fn assert_same_as_full_passes(mesh: &Mesh, s: &Surface, pad: f64, label: &str) {
        let adj = NodeEdges::build(mesh);
        let boxes = NodeBoxes::build(mesh, &adj);
        let bvh = Bvh::build(s, pad);
        let near = Near::find(mesh, &boxes, &bvh);
        let at = SurfaceAt::at_end(s, &bvh).unwrap();
        let c42 = collision(mesh, &adj, at);
        assert_eq!(collision_near(mesh, &adj, at, &near), c42, "{label}: Alg. 4.2");
        assert_eq!(projection_near(mesh, &adj, at, &near), projection(mesh, &adj, at), "{label}");
        let swept = swept_nodes(mesh, s, &bvh);
        assert_eq!(swept_nodes_among(mesh, s, &bvh, &near.nodes), swept, "{label}: swept");
        assert_eq!(swept_nodes_near(mesh, s, &bvh, &near), swept, "{label}: swept, recorded");
        assert!(!c42.cuts.is_empty(), "{label}: nothing cut");
        assert!(near.edges(mesh, &adj).len() < mesh.n_edges(), "{label}: every edge is near");
        boxes.tree.validate().unwrap();
        // What `find` keeps is what the definition says, node by node.
        let want: Vec<u32> = (0..mesh.n_nodes() as u32)
            .filter(|&i| {
                let (lo, hi) = boxes.tree.triangle_box(i as usize);
                (0..bvh.len()).any(|t| {
                    let (a, b) = bvh.triangle_box(t);
                    crate::embedded::bvh::overlaps(&lo, &hi, &a, &b)
                })
            })
            .collect();
        assert_eq!(near.nodes, want, "{label}");
        let mut edges: Vec<u32> =
            want.iter().flat_map(|&i| adj.edges_of(i as usize).to_vec()).collect();
        edges.sort_unstable();
        edges.dedup();
        assert_eq!(near.edges(mesh, &adj), edges, "{label}");
    }

    /// The scan of a node's recorded triangles, filtered by the halves, visits exactly the
    /// triangles whose box meets the query box, for the boxes the passes ask (each edge of the
    /// node, the node itself, its occlusion ball, its node box) and for boxes on a node plane.
    #[test]
    fn the_halves_skip_only_triangles_whose_box_misses_the_query() {
        let mesh = cube_mesh(10, 0.3, 9);
        let adj = NodeEdges::build(&mesh);
        let boxes = NodeBoxes::build(&mesh, &adj);
        let flat = box_surface([0.2, 0.3, 0.4], [0.8, 0.7, 0.4 + 1e-9], 3);
        let mut queries = 0;
        for s in [sphere([0.52, 0.47, 0.5], 0.3, 6), flat, plane(-0.5, 1.5, -0.5, 1.5, 0.5)] {
            let bvh = Bvh::build(&s, 1e-9);
            let near = Near::find(&mesh, &boxes, &bvh);
            for &i in &near.nodes {
                let i = i as usize;
                let p = mesh.coords[i];
                let r = OCCLUSION * adj.h_min[i];
                let mut asks = vec![(p, p), (p.map(|v| v - r), p.map(|v| v + r))];
                asks.push(adj.node_box(&mesh, i));
                for (j, _) in adj.neighbours(&mesh, i) {
                    let q = mesh.coords[j];
                    asks.push((
                        [0, 1, 2].map(|d| p[d].min(q[d])),
                        [0, 1, 2].map(|d| p[d].max(q[d])),
                    ));
                    let mut flat_q = q;
                    flat_q[1] = p[1];
                    asks.push((
                        [0, 1, 2].map(|d| p[d].min(flat_q[d])),
                        [0, 1, 2].map(|d| p[d].max(flat_q[d])),
                    ));
                }
                for (lo, hi) in asks {
                    let mut got = Vec::new();
                    near.for_each_overlap(&bvh, i, &p, &lo, &hi, |t| got.push(t));
                    let want: Vec<u32> = (0..bvh.len() as u32)
                        .filter(|&t| {
                            let (a, b) = bvh.triangle_box(t as usize);
                            overlaps(&a, &b, &lo, &hi)
                        })
                        .collect();
                    assert_eq!(got, want, "node {i}");
                    queries += usize::from(!want.is_empty());
                }
            }
        }
        assert!(queries > 1000, "{queries}");
    }

    #[test]
    fn passes_over_the_near_part_equal_the_full_passes_on_the_test_surfaces() {
        let mesh = cube_mesh(12, 0.3, 5);
        let h = 1.0 / 12.0;
        let mut thin = box_surface([0.2, 0.25, 0.53], [0.8, 0.75, 0.53 + 0.1 * h], 2);
        let moved: Vec<[f64; 3]> = thin.x_b.iter().map(|p| [p[0] + 0.4 * h, p[1], p[2]]).collect();
        thin.advance(0.1, &moved, &vec![[0.0; 3]; moved.len()]);
        let mut cracked = plane(-0.2, 1.2, -0.2, 1.2, 0.47);
        cracked.phi[0] = [-1.0, 1.0, 0.5];
        let cases = [
            ("sphere", sphere([0.52, 0.47, 0.5], 0.3, 8), 1e-12),
            ("box", box_surface([0.3, 0.26, 0.34], [0.71, 0.66, 0.72], 3), 1e-3 * h),
            ("swept thin box", thin, 1e-12),
            ("cracked plane", cracked, 0.0),
        ];
        for (label, s, pad) in &cases {
            assert_same_as_full_passes(&mesh, s, *pad, label);
        }
        // A plane through mesh nodes: occluded nodes and the cuts at them.
        let mesh = cube_mesh(6, 0.0, 0);
        assert_same_as_full_passes(&mesh, &plane(-0.5, 1.5, -0.5, 1.5, 0.5), 1e-12, "on nodes");
    }

    /// A plane through a layer of nodes occludes the whole layer, and only the nodes of that
    /// layer have a triangle box reaching every half of their reach box: the occlusion search
    /// looks at a third of the near nodes and finds what the full pass finds.
    #[test]
    fn occluded_nodes_are_among_the_candidates() {
        let mesh = cube_mesh(8, 0.0, 1);
        let adj = NodeEdges::build(&mesh);
        let boxes = NodeBoxes::build(&mesh, &adj);
        let s = plane(-0.5, 1.5, -0.5, 1.5, 0.5);
        let bvh = Bvh::build(&s, 0.0);
        let near = Near::find(&mesh, &boxes, &bvh);
        let at = SurfaceAt::at_end(&s, &bvh).unwrap();
        let full = collision(&mesh, &adj, at);
        let layer: Vec<u32> =
            (0..mesh.n_nodes() as u32).filter(|&i| mesh.coords[i as usize][2] == 0.5).collect();
        assert_eq!(layer.len(), 81);
        assert!(layer.iter().all(|&i| full.occluded[i as usize]));
        assert_eq!(full.occluded.iter().filter(|o| **o).count(), layer.len());
        assert_eq!(near.occlusion_candidates(), &layer[..]);
        assert_eq!(near.nodes.len(), 3 * layer.len());
        assert_eq!(collision_near(&mesh, &adj, at, &near), full);
    }

    /// Cells halving upwards, and a plane (boxes not padded) just below a node `j`, within its
    /// occlusion radius but farther than the radius of its upper neighbour `i` (whose shortest
    /// edge is half as long): the edge from `j` up to `i` is cut at its occluded end `j`, and the
    /// near passes find it (every reach box is widened by the largest radius, so `i`'s reaches
    /// the plane too).
    #[test]
    fn an_occluded_end_below_a_finer_neighbour_is_cut_by_the_near_pass() {
        use crate::mesh::boxmesh::{BoxCells, BoxSpec};
        let spec = BoxSpec {
            lo: [0.0; 3],
            hi: [1.0, 1.0, 1.0],
            cells: [2, 2, 6],
            grading: [1.0, 1.0, 0.5],
            core: [0; 3],
            shape: BoxCells::Tet,
        };
        let mesh = Mesh::build(spec.raw().unwrap()).unwrap();
        let adj = NodeEdges::build(&mesh);
        let boxes = NodeBoxes::build(&mesh, &adj);
        // A node of the third layer, away from the box's sides, and its neighbour straight above.
        let z: Vec<f64> = {
            let mut z: Vec<f64> = mesh.coords.iter().map(|p| p[2]).collect();
            z.sort_by(f64::total_cmp);
            z.dedup();
            z
        };
        let j = (0..mesh.n_nodes())
            .find(|&k| mesh.coords[k] == [0.5, 0.5, z[2]])
            .expect("a node at the centre of the third layer");
        let (i, e) = adj
            .neighbours(&mesh, j)
            .find(|&(k, _)| mesh.coords[k] == [0.5, 0.5, z[3]])
            .expect("the node above it");
        assert!(adj.h_min[i] < 0.6 * adj.h_min[j], "{} {}", adj.h_min[i], adj.h_min[j]);
        let d = 0.75 * OCCLUSION * adj.h_min[j];
        assert!(d > OCCLUSION * adj.h_min[i]);
        let s = plane(-0.5, 1.5, -0.5, 1.5, z[2] - d);
        let bvh = Bvh::build(&s, 0.0);
        let near = Near::find(&mesh, &boxes, &bvh);
        assert!(near.triangles_of(i).is_some_and(|l| !l.is_empty()), "node {i} is not near");
        let at = SurfaceAt::at_end(&s, &bvh).unwrap();
        let full = collision(&mesh, &adj, at);
        assert!(full.occluded[j] && !full.occluded[i]);
        let cut = full.find(e).expect("the edge from the occluded node is cut");
        let alpha_j = if mesh.edges[e as usize][0] as usize == j { 0.0 } else { 1.0 };
        assert_eq!(cut.alpha, alpha_j);
        assert_eq!(collision_near(&mesh, &adj, at, &near), full);
    }

    /// A sphere moving through a perturbed mesh, by both algorithms: the tracker (which tests
    /// only the near part, keeps Alg. 4.1's inside and redecides only the swept and occluded
    /// nodes) has after every step the cuts and sides of the full passes, and the statuses of
    /// the whole-mesh flood fill from seeds carried with the body (Alg. 4.2 step 5').
    #[test]
    fn a_moving_sphere_is_tracked_as_by_the_full_passes() {
        let mesh = cube_mesh(12, 0.3, 21);
        let rest = sphere([0.4, 0.5, 0.48], 0.27, 8);
        let seeds =
            [Seed { point: [0.0; 3], fluid: true }, Seed { point: [0.4, 0.5, 0.48], fluid: false }];
        for tracking in [Tracking::Collision, Tracking::Projection] {
            let mut tracker = Tracker::new(&mesh, rest.clone(), tracking, &seeds).unwrap();
            let mut full = tracker.sides.clone();
            let mut changed = 0;
            for step in 1..=5 {
                let (shift, t) = (0.04 * step as f64, 0.01 * step as f64);
                let x: Vec<[f64; 3]> =
                    rest.x_b.iter().map(|p| [p[0] + shift, p[1], p[2] + 0.3 * shift]).collect();
                let v = vec![[4.0, 0.0, 1.2]; x.len()];
                let changes = tracker.advance(&mesh, t, &x, &v).unwrap();
                let s = &tracker.surface;
                let at = SurfaceAt::at_end(s, &tracker.bvh).unwrap();
                let cuts: Intersections = match tracking {
                    Tracking::Collision => collision(&mesh, &tracker.adjacency, at),
                    Tracking::Projection => projection(&mesh, &tracker.adjacency, at),
                };
                assert_eq!(tracker.cuts, cuts, "{tracking:?}, step {step}");
                let swept = swept_nodes(&mesh, s, &tracker.bvh);
                let (sides, full_changes) =
                    update_sides(&mesh, &tracker.adjacency, &full, &cuts, &swept);
                assert_eq!(tracker.sides, sides, "{tracking:?}, step {step}");
                assert_eq!(changes, full_changes);
                let carried = [
                    seeds[0],
                    Seed { point: [0.4 + shift, 0.5, 0.48 + 0.3 * shift], fluid: false },
                ];
                let fresh = flood_fill(&mesh, &tracker.adjacency, &cuts, &carried).unwrap();
                assert_eq!(tracker.sides.status, fresh.status, "{tracking:?}, step {step}");
                let active = tracker.sides.status.iter().map(|s| *s == NodeStatus::Active);
                assert!(active.eq(tracker.active.iter().copied()), "{tracking:?}, step {step}");
                changed += changes.len();
                full = sides;
            }
            assert!(changed > 40, "{tracking:?}: {changed} nodes changed");
            // Alg. 4.1 kept its inside through every step (no whole-mesh flood fill), and most
            // near nodes kept their side without being redecided (the surface moved less than
            // their distance to it).
            let kept = tracker.kept_inside.as_ref().map(|k| k.full_fills);
            assert_eq!(kept, (tracking == Tracking::Projection).then_some(0), "{tracking:?}");
            if let Some(k) = &tracker.kept_inside {
                println!("Alg. 4.1: {} near nodes redecided, {} kept", k.redecided, k.kept);
                assert!(k.kept > k.redecided, "{} kept, {} redecided", k.kept, k.redecided);
            }
        }
    }

    /// A sphere that jumps out of the box, moves outside it and jumps back. The swept boxes
    /// cover each jump, so the nodes it left are near and redecided; outside, no node is near,
    /// the check (b) of `KeptInside` fails and that step takes the whole-mesh flood fill. Every
    /// step has the cuts of Alg. 4.1 over the whole mesh.
    #[test]
    fn alg_4_1_keeps_the_whole_mesh_result_through_jumps_and_an_empty_near_part() {
        let mesh = cube_mesh(12, 0.3, 8);
        let rest = sphere([0.3, 0.5, 0.5], 0.15, 6);
        let seeds = [Seed { point: [0.0; 3], fluid: true }];
        let mut tracker = Tracker::new(&mesh, rest.clone(), Tracking::Projection, &seeds).unwrap();
        for (step, shift, fills, cut) in
            [(1, 2.0, 0, false), (2, 2.05, 1, false), (3, 0.4, 1, true)]
        {
            let x: Vec<[f64; 3]> = rest.x_b.iter().map(|p| [p[0] + shift, p[1], p[2]]).collect();
            let v = vec![[0.0; 3]; x.len()];
            tracker.advance(&mesh, 0.1 * step as f64, &x, &v).unwrap();
            let at = SurfaceAt::at_end(&tracker.surface, &tracker.bvh).unwrap();
            let cuts = projection(&mesh, &tracker.adjacency, at);
            assert_eq!(!cuts.cuts.is_empty(), cut, "step {step}");
            assert_eq!(tracker.cuts, cuts, "step {step}");
            assert_eq!(tracker.kept_inside.as_ref().unwrap().full_fills, fills, "step {step}");
        }
    }
}
