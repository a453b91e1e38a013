//! The cut edges of the fluid mesh (thesis §4.2-4.3): [`collision()`] is Alg. 4.2 (every edge
//! tested against the triangles near it; open, thin and unresolved surfaces, cracks through phi),
//! [`projection()`] is Alg. 4.1 (sides by projection and flood fill; closed, resolved surfaces).
//! Both return [`Intersections`]: one [`CutEdge`] per cut edge, sorted by edge, with the offsets
//! of each edge block of [`crate::mesh::EdgeBlocks`], and the occluded nodes. Each has a form
//! over the part of the mesh the surface can touch ([`near`]: the tracker's, same result) and a
//! form over the whole mesh (the reference it is tested against).
//!
//! The surface is taken at one set of nodal positions `x` (for example `Surface::x_b`, or
//! `Surface::node_at` at a stage time); the hierarchy's boxes must hold the triangles there
//! ([`super::bvh::Bvh::refit`] covers `x_a` and `x_b`, [`super::bvh::Bvh::refit_with`] any other).

mod by_node;
mod closest;
pub mod collision;
mod crossings;
mod halves;
pub mod near;
pub mod projection;
mod pseudo_normals;
mod reach;
pub mod skin;

pub use collision::{collision, collision_near};
pub use near::{Near, NodeBoxes, ReachBoxes};
pub use projection::{projection, projection_inside, projection_near, KeptInside};
pub use skin::NearSkin;

use super::bvh::Bvh;
use super::predicates::{closest_point, unit_normal, Closest, TriangleFrom};
use super::{CutEdge, Surface};
use crate::mesh::Mesh;
use closest::Nearest;

/// Occlusion tolerance (thesis §4.3.2, `ε = 1e-8`), relative to the node's shortest edge: a node
/// closer than `OCCLUSION * h_min(i)` to a triangle (where that triangle's phi is `>= 0`) is
/// occluded.
pub const OCCLUSION: f64 = 1e-8;

/// Whether an interpolated phi rules a hit out: negative, or NaN (never `>= 0`).
#[inline]
fn below_zero_or_nan(phi: f64) -> bool {
    phi.is_nan() || phi < 0.0
}

/// The cut edges of a mesh at one time.
#[derive(Debug, Clone, PartialEq)]
pub struct Intersections {
    /// Sorted by `edge`, one per cut edge.
    pub cuts: Vec<CutEdge>,
    /// Block `b`'s cut edges are `cuts[block_offsets[b]..block_offsets[b + 1]]`.
    pub block_offsets: Vec<u32>,
    /// Per node: within the occlusion tolerance of the surface.
    pub occluded: Vec<bool>,
}

impl Intersections {
    /// The cut edges of block `b`.
    pub fn block(&self, b: usize) -> &[CutEdge] {
        &self.cuts[self.block_offsets[b] as usize..self.block_offsets[b + 1] as usize]
    }

    /// The record of edge `e`, if it is cut.
    pub fn find(&self, e: u32) -> Option<&CutEdge> {
        self.cuts.binary_search_by_key(&e, |c| c.edge).ok().map(|k| &self.cuts[k])
    }

    /// Per edge: whether it is cut.
    pub fn cut_mask(&self, n_edges: usize) -> Vec<bool> {
        let mut m = vec![false; n_edges];
        for c in &self.cuts {
            m[c.edge as usize] = true;
        }
        m
    }

    /// The sorted list `cuts` cut into the edge blocks of `mesh`.
    fn from_sorted(mesh: &Mesh, cuts: Vec<CutEdge>, occluded: Vec<bool>) -> Intersections {
        let blocks = &mesh.blocks;
        let mut block_offsets: Vec<u32> = (0..blocks.len())
            .map(|b| cuts.partition_point(|c| (c.edge as usize) < blocks.edges(b).start) as u32)
            .collect();
        block_offsets.push(cuts.len() as u32);
        Intersections { cuts, block_offsets, occluded }
    }
}

/// The crossing of an edge nearest to its first end found so far.
#[derive(Debug, Clone, Copy)]
struct Crossing {
    alpha: f64,
    triangle: u32,
    bary: [f64; 3],
}

impl Crossing {
    /// The cut record of edge `e` at this crossing.
    fn cut(self, at: &SurfaceAt<'_>, e: usize) -> CutEdge {
        at.cut(e, self.triangle, self.alpha, self.bary)
    }
}

/// The surface at one set of nodal positions, with the hierarchy over it.
#[derive(Clone, Copy)]
pub struct SurfaceAt<'a> {
    surface: &'a Surface,
    x: &'a [[f64; 3]],
    bvh: &'a Bvh,
}

/// A surface view whose parts do not fit together, named.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SurfaceAtError {
    #[error("{got} nodal positions given for a surface of {expected} nodes")]
    Positions { expected: usize, got: usize },
    #[error(transparent)]
    Bvh(#[from] super::bvh::BvhError),
}

impl<'a> SurfaceAt<'a> {
    /// The view of `surface` at positions `x` (one per surface node) with its hierarchy, which
    /// must have been built for this topology and fitted so that its boxes hold the triangles
    /// at `x` (not checked here: [`Bvh::refit`] covers `x_a`, `x_b`).
    pub fn new(
        surface: &'a Surface,
        x: &'a [[f64; 3]],
        bvh: &'a Bvh,
    ) -> Result<SurfaceAt<'a>, SurfaceAtError> {
        if x.len() != surface.n_nodes() {
            return Err(SurfaceAtError::Positions { expected: surface.n_nodes(), got: x.len() });
        }
        if bvh.len() != surface.triangles.len() || bvh.topology_version != surface.topology_version
        {
            return Err(super::bvh::BvhError::Topology {
                surface: surface.triangles.len(),
                tree: bvh.len(),
                version: bvh.topology_version,
            }
            .into());
        }
        Ok(SurfaceAt { surface, x, bvh })
    }

    /// The surface at its end-of-step positions `x_b`.
    pub fn at_end(surface: &'a Surface, bvh: &'a Bvh) -> Result<SurfaceAt<'a>, SurfaceAtError> {
        SurfaceAt::new(surface, &surface.x_b, bvh)
    }
}

impl SurfaceAt<'_> {
    #[inline]
    fn corners(&self, t: u32) -> [[f64; 3]; 3] {
        self.surface.triangles[t as usize].map(|n| self.x[n as usize])
    }

    /// Interpolated phi at a point of triangle `t` (finite: `Surface::new` rejects other phi).
    #[inline]
    fn phi(&self, t: u32, bary: [f64; 3]) -> f64 {
        let p = self.surface.phi[t as usize];
        bary[0] * p[0] + bary[1] * p[1] + bary[2] * p[2]
    }

    /// The cut record of edge `e` for triangle `t` at `(α, bary)`.
    fn cut(&self, e: usize, t: u32, alpha: f64, bary: [f64; 3]) -> CutEdge {
        let [a, b, c] = self.corners(t);
        CutEdge { edge: e as u32, alpha, triangle: t, bary, normal: unit_normal(a, b, c) }
    }

    /// The crossing of edge `e` nearest to its node `i` (smallest α, then lowest triangle), among
    /// the triangles whose box meets the edge's box (those recorded in `near` for `i`, whose
    /// reach box holds the edge), counting only hits where phi `>= 0` when `crack_aware`.
    fn nearest_crossing(
        &self,
        mesh: &Mesh,
        near: &Near,
        e: usize,
        crack_aware: bool,
    ) -> Option<Crossing> {
        let [i, j] = mesh.edges[e].map(|v| v as usize);
        let (p, q) = (mesh.coords[i], mesh.coords[j]);
        let lo = [0, 1, 2].map(|d| p[d].min(q[d]));
        let hi = [0, 1, 2].map(|d| p[d].max(q[d]));
        let mut best = None;
        near.for_each_overlap(self.bvh, i, &p, &lo, &hi, |t| {
            let mut triangle = TriangleFrom::new(p, self.corners(t));
            self.offer_crossing(q, t, &mut triangle, crack_aware, &mut best);
        });
        best
    }

    /// Tests the segment from `triangle`'s point to `q` against triangle `t` and keeps the
    /// crossing in `best` if it is nearer to that point (smaller α, then lower triangle),
    /// counting only hits where phi `>= 0` when `crack_aware`.
    #[inline]
    fn offer_crossing(
        &self,
        q: [f64; 3],
        t: u32,
        triangle: &mut TriangleFrom,
        crack_aware: bool,
        best: &mut Option<Crossing>,
    ) {
        if let Some(h) = triangle.crossing(q) {
            if crack_aware && below_zero_or_nan(self.phi(t, h.bary)) {
                return;
            }
            if best.is_none_or(|b| (h.alpha, t) < (b.alpha, b.triangle)) {
                *best = Some(Crossing { alpha: h.alpha, triangle: t, bary: h.bary });
            }
        }
    }

    /// The closest point of the surface to `p` among the triangles whose box meets the box of
    /// half-width `radius` around it (lowest triangle on ties), with phi `>= 0` there when
    /// `crack_aware`. With `within = Some((near, i))` that box lies inside the reach box of node
    /// `i` at `p` and the triangles recorded for `i` are searched ([`Near::for_each_overlap`]),
    /// else the tree from its root. `seed`, the closest point to `p` of one of those triangles,
    /// starts the search; boxes too far to beat the best so far are skipped ([`Nearest`]).
    fn nearest_point(
        &self,
        p: [f64; 3],
        radius: f64,
        crack_aware: bool,
        within: Option<(&Near, usize)>,
        seed: Option<(u32, Closest)>,
    ) -> Option<(u32, Closest)> {
        let lo = p.map(|v| v - radius);
        let hi = p.map(|v| v + radius);
        let mut nearest = Nearest::new(p);
        if let Some((t, cp)) = seed {
            let (a, b) = self.bvh.triangle_box(t as usize);
            let phi_ok = !crack_aware || !below_zero_or_nan(self.phi(t, cp.bary));
            if phi_ok && super::bvh::overlaps(&a, &b, &lo, &hi) {
                nearest.offer(t, cp);
            }
        }
        let visit = |nearest: &mut Nearest, t: u32| {
            let (a, b) = self.bvh.triangle_box(t as usize);
            if !nearest.may_beat(&a, &b) {
                return;
            }
            let [a, b, c] = self.corners(t);
            let cp = closest_point(p, a, b, c);
            if crack_aware && below_zero_or_nan(self.phi(t, cp.bary)) {
                return;
            }
            nearest.offer(t, cp);
        };
        match within {
            Some((near, i)) => {
                near.for_each_overlap(self.bvh, i, &p, &lo, &hi, |t| visit(&mut nearest, t))
            }
            None => self.bvh.for_each_overlap_pruned(
                &lo,
                &hi,
                &mut nearest,
                |n, lo, hi| n.may_beat(lo, hi),
                |n, lo, hi| n.box_dist2(lo, hi),
                visit,
            ),
        }
        nearest.best
    }

    /// Occluded nodes (Alg. 4.2 step 3.1): within `OCCLUSION * h_min(i)` of the surface, among
    /// the nodes of `near` that can be ([`Near::occlusion_candidates`]; the others are not).
    fn occluded(&self, mesh: &Mesh, h_min: &[f64], crack_aware: bool, near: &Near) -> Vec<bool> {
        use rayon::prelude::*;
        let nodes = near.occlusion_candidates();
        let hit: Vec<bool> = nodes
            .par_iter()
            .enumerate()
            .map(|(k, &i)| {
                near.prefetch_ahead(mesh, nodes, k);
                let i = i as usize;
                let r = OCCLUSION * h_min[i];
                r.is_finite()
                    && self
                        .nearest_point(mesh.coords[i], r, crack_aware, Some((near, i)), None)
                        .is_some_and(|(_, c)| c.dist2 <= r * r)
            })
            .collect();
        let mut occluded = vec![false; mesh.n_nodes()];
        for (&i, h) in nodes.iter().zip(hit) {
            occluded[i as usize] = h;
        }
        occluded
    }
}
