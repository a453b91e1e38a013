//! Which node a probe or a line sample reads when the mesh has an embedded surface (DESIGN §7):
//! never an inactive or occluded node, never one on the other side of the surface.
//!
//! A node is admissible for a sample point `x` when it is active and visible from `x`: the
//! segment from `x` to the node crosses no surface triangle (the exact segment-triangle test of
//! the tracking, [`segment_triangle`], a crossing counting only where the interpolated crack
//! level set is `>= 0`, as in Alg. 4.2). The sample takes the node nearest to `x` when it is
//! admissible (what a run without a surface takes, so the two agree away from the surface);
//! otherwise the nearest admissible node among that node's edge neighbours; with none, the sample
//! has no fluid state (its values are `NaN`, [`crate::probes::NO_FLUID`] its material).

use super::predicates::segment_triangle;
use super::tracker::Tracker;
use crate::mesh::geometry::{dot, sub};
use crate::mesh::Mesh;

/// Whether the segment `p q` crosses the surface of `tracker` at its current positions.
pub fn blocked(tracker: &Tracker, p: [f64; 3], q: [f64; 3]) -> bool {
    let lo: [f64; 3] = std::array::from_fn(|k| p[k].min(q[k]));
    let hi: [f64; 3] = std::array::from_fn(|k| p[k].max(q[k]));
    let surface = &tracker.surface;
    let mut hit = false;
    tracker.bvh.for_each_overlap(&lo, &hi, |t| {
        if hit {
            return;
        }
        let t = t as usize;
        let [a, b, c] = surface.triangles[t].map(|n| surface.x_b[n as usize]);
        if let Some(h) = segment_triangle(p, q, a, b, c) {
            let phi = surface.phi[t];
            hit = h.bary[0] * phi[0] + h.bary[1] * phi[1] + h.bary[2] * phi[2] >= 0.0;
        }
    });
    hit
}

/// Whether node `i` is admissible for a sample at `x` (module doc).
pub fn admissible(mesh: &Mesh, tracker: &Tracker, x: [f64; 3], i: usize) -> bool {
    tracker.active[i] && !blocked(tracker, x, mesh.coords[i])
}

/// The node a sample at `x` reads, `nearest` being the mesh node nearest to `x` (module doc);
/// `None` when no admissible node is found.
pub fn sample_node(mesh: &Mesh, tracker: &Tracker, x: [f64; 3], nearest: usize) -> Option<usize> {
    if admissible(mesh, tracker, x, nearest) {
        return Some(nearest);
    }
    let distance = |j: usize| {
        let d = sub(mesh.coords[j], x);
        dot(d, d)
    };
    let mut candidates: Vec<usize> =
        tracker.adjacency.neighbours(mesh, nearest).map(|(j, _)| j).collect();
    candidates.sort_by(|&a, &b| distance(a).total_cmp(&distance(b)).then(a.cmp(&b)));
    candidates.into_iter().find(|&j| admissible(mesh, tracker, x, j))
}
