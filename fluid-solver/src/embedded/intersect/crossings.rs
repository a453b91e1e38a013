//! The crossings of the edges a node starts (Alg. 4.1 step 5, Alg. 4.2 step 4), read from the
//! node's recorded triangles once for several edges.
//!
//! Each triangle recorded for node `i` keeps the halves of `i`'s reach box its box reaches
//! ([`super::halves::Split::halves`]), and an edge `[i, j]` needs a triangle box reaching the halves
//! its own box lies in ([`super::halves::Split::needed`]). A table over the 64 sets of halves gives,
//! for each set, the edges of a group whose needed halves it holds, so one pass over the list
//! meets every triangle with just the edges it may overlap: the triangles
//! [`Near::for_each_overlap`] gives each edge, each tested against the edge's box and then by
//! the exact crossing test, with what the tests of the group share about the triangle seen from
//! `i` ([`TriangleFrom`]) made once.

use super::{Crossing, Near, SurfaceAt};
use crate::embedded::bvh::overlaps;
use crate::embedded::predicates::TriangleFrom;
use crate::mesh::Mesh;

/// Edges of one node read together (one bit each of the halves table, at most 32).
pub(super) const GROUP: usize = 16;

impl SurfaceAt<'_> {
    /// Calls `found(e, crossing)` for each edge `(e, j)` of `edges` (edges `[i, j]` of node `i`,
    /// `e` its number), with its crossing nearest to `i` (smallest α, then lowest
    /// triangle; only where phi `>= 0` when `crack_aware`), in the order of `edges`. With `i`'s
    /// triangles recorded, the list is read once per group of `G` edges (module docs); else each
    /// edge is searched on its own ([`SurfaceAt::nearest_crossing`]).
    #[inline]
    pub(super) fn for_each_crossing_from<const G: usize>(
        &self,
        mesh: &Mesh,
        near: &Near,
        i: usize,
        edges: &[(usize, usize)],
        crack_aware: bool,
        mut found: impl FnMut(usize, Option<Crossing>),
    ) {
        const { assert!(G > 0 && G <= 32, "one bit per edge of a group in a u32") };
        let p = mesh.coords[i];
        let Some((list, halves, split)) = near.recorded(i, &p) else {
            return self.each_on_its_own(mesh, near, edges, crack_aware, found);
        };
        for edges in edges.chunks(G) {
            let mut table = [0u32; 64];
            let mut group = [(0usize, p, p); G];
            for (k, &(_, j)) in edges.iter().enumerate() {
                let q = mesh.coords[j];
                let lo = [0, 1, 2].map(|d| p[d].min(q[d]));
                let hi = [0, 1, 2].map(|d| p[d].max(q[d]));
                group[k] = (j, lo, hi);
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
                let mut hits = table[h as usize];
                if hits == 0 {
                    continue;
                }
                let (tlo, thi) = self.bvh.triangle_box(t as usize);
                // The triangle seen from node `i`, shared by the edges: made at the first that
                // needs it.
                let mut seen = None;
                while hits != 0 {
                    let k = hits.trailing_zeros() as usize;
                    hits &= hits - 1;
                    let (j, lo, hi) = group[k];
                    if overlaps(&tlo, &thi, &lo, &hi) {
                        let triangle = match &mut seen {
                            Some(triangle) => triangle,
                            None => seen.insert(TriangleFrom::new(p, self.corners(t))),
                        };
                        let q = mesh.coords[j];
                        self.offer_crossing(q, t, triangle, crack_aware, &mut best[k]);
                    }
                }
            }
            for (&(e, _), &b) in edges.iter().zip(&best) {
                found(e, b);
            }
        }
    }

    /// [`SurfaceAt::for_each_crossing_from`] without recorded triangles (the full passes).
    #[inline(never)]
    fn each_on_its_own(
        &self,
        mesh: &Mesh,
        near: &Near,
        edges: &[(usize, usize)],
        crack_aware: bool,
        mut found: impl FnMut(usize, Option<Crossing>),
    ) {
        for &(e, _) in edges {
            found(e, self.nearest_crossing(mesh, near, e, crack_aware));
        }
    }
}
