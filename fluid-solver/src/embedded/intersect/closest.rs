//! The closest surface point to a point among candidate triangles (Alg. 4.1 steps 1-2, the
//! occlusion test of Alg. 4.2 step 3.1), pruned by the triangle boxes: a box farther from the
//! point than the best closest point so far, by more than rounding can explain, holds no closer
//! triangle, so the closest points inside it are not computed. The result is that of testing
//! every candidate (the lowest `(dist2, triangle)`), bit for bit.
//!
//! Why the bound is safe: the computed closest point of a triangle is a combination of its
//! corners with rounded barycentric coordinates, so it lies within a few ulps of the corners'
//! size of the triangle, hence of its box (which holds the triangle at the positions searched);
//! its computed distance therefore exceeds the box's distance less `1e-12` of that size, and a
//! relative `1e-12` covers the rounding of the distances themselves. Both margins are thousands
//! of times the rounding they cover and far below any distance that prunes.

use crate::embedded::predicates::Closest;

/// Relative margin of the pruning bound (module docs).
const MARGIN: f64 = 1e-12;

/// The best closest point to `p` so far, with the distance a box must be within to hold a
/// better one.
pub(super) struct Nearest {
    p: [f64; 3],
    pub best: Option<(u32, Closest)>,
    /// `sqrt(best.dist2)` (infinite while there is none).
    reach: f64,
}

impl Nearest {
    pub fn new(p: [f64; 3]) -> Nearest {
        Nearest { p, best: None, reach: f64::INFINITY }
    }

    /// Squared distance from `p` to the box `[lo, hi]` and the size of its corners.
    #[inline]
    fn box_distance(&self, lo: &[f64; 3], hi: &[f64; 3]) -> (f64, f64) {
        let (mut d2, mut size) = (0.0, 1.0f64);
        for d in 0..3 {
            let gap = (lo[d] - self.p[d]).max(self.p[d] - hi[d]).max(0.0);
            d2 += gap * gap;
            size = size.max(lo[d].abs()).max(hi[d].abs());
        }
        (d2, size)
    }

    /// Squared distance from `p` to the box `[lo, hi]` (the order in which to offer candidates).
    #[inline]
    pub fn box_dist2(&self, lo: &[f64; 3], hi: &[f64; 3]) -> f64 {
        self.box_distance(lo, hi).0
    }

    /// Whether a triangle inside the box `[lo, hi]` may have a closest point that beats the best
    /// so far (module docs: `false` only when it cannot).
    #[inline]
    pub fn may_beat(&self, lo: &[f64; 3], hi: &[f64; 3]) -> bool {
        if self.best.is_none() {
            return true;
        }
        let (d2, size) = self.box_distance(lo, hi);
        let r = self.reach * (1.0 + MARGIN) + MARGIN * size;
        d2 <= r * r
    }

    /// Takes the closest point `cp` of triangle `t` if it beats the best (lower distance, then
    /// lower triangle).
    #[inline]
    pub fn offer(&mut self, t: u32, cp: Closest) {
        if self.best.is_none_or(|(bt, bc)| (cp.dist2, t) < (bc.dist2, bt)) {
            self.best = Some((t, cp));
            self.reach = cp.dist2.sqrt();
        }
    }
}

/// The search before pruning, for the tests: every triangle whose box meets `[lo, hi]`, the
/// lowest `(dist2, triangle)` of their closest points to `p`.
#[cfg(test)]
pub(crate) fn brute_nearest(
    at: &super::SurfaceAt<'_>,
    p: [f64; 3],
    lo: [f64; 3],
    hi: [f64; 3],
) -> Option<(u32, Closest)> {
    let mut best: Option<(u32, Closest)> = None;
    for t in 0..at.bvh.len() as u32 {
        let (a, b) = at.bvh.triangle_box(t as usize);
        if crate::embedded::bvh::overlaps(&a, &b, &lo, &hi) {
            let [a, b, c] = at.corners(t);
            let cp = crate::embedded::predicates::closest_point(p, a, b, c);
            if best.is_none_or(|(bt, bc)| (cp.dist2, t) < (bc.dist2, bt)) {
                best = Some((t, cp));
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::embedded::adjacency::NodeEdges;
    use crate::embedded::bvh::Bvh;
    use crate::embedded::intersect::{Near, NodeBoxes, SurfaceAt};
    use crate::embedded::predicates::closest_point;
    use crate::embedded::tests::{box_surface, cube_mesh, plane, sphere};

    /// [`brute_nearest`] in the cube of half-side `radius` about `p`.
    fn brute(at: &SurfaceAt<'_>, p: [f64; 3], radius: f64) -> Option<(u32, Closest)> {
        brute_nearest(at, p, p.map(|v| v - radius), p.map(|v| v + radius))
    }

    /// The pruned searches, from the root, from a node's recorded triangles and from a seed,
    /// give the brute-force triangle and closest point bit for bit: at the mesh nodes (some on
    /// the surfaces, some at their edges and corners) and at points between, for radii from the
    /// occlusion tolerance to past the node boxes.
    #[test]
    fn pruned_nearest_points_equal_the_unpruned_search() {
        let mesh = cube_mesh(8, 0.0, 0);
        let adj = NodeEdges::build(&mesh);
        let boxes = NodeBoxes::build(&mesh, &adj);
        let h = 1.0 / 8.0;
        let surfaces = [
            (sphere([0.52, 0.47, 0.5], 0.3, 6), 1e-3 * h),
            (box_surface([0.25, 0.25, 0.375], [0.75, 0.625, 0.75], 2), 0.0),
            (plane(-0.5, 1.5, -0.5, 1.5, 0.5), 0.0),
        ];
        let mut checked = 0;
        for (s, pad) in &surfaces {
            let bvh = Bvh::build(s, *pad);
            let near = Near::find(&mesh, &boxes, &bvh);
            let at = SurfaceAt::at_end(s, &bvh).unwrap();
            for &i in &near.nodes {
                let i = i as usize;
                let p = mesh.coords[i];
                for radius in [1e-8 * h, 0.3 * h, h] {
                    let want = brute(&at, p, radius);
                    assert_eq!(at.nearest_point(p, radius, false, None, None), want);
                    if radius < h {
                        let got = at.nearest_point(p, radius, false, Some((&near, i)), None);
                        assert_eq!(got, want);
                    }
                    for t in [0, (s.triangles.len() / 2) as u32] {
                        let [a, b, c] = at.corners(t);
                        let seed = Some((t, closest_point(p, a, b, c)));
                        assert_eq!(at.nearest_point(p, radius, false, None, seed), want);
                    }
                    checked += usize::from(want.is_some());
                }
                let q = [p[0] + 0.37 * h, p[1] - 0.21 * h, p[2] + 0.13 * h];
                assert_eq!(at.nearest_point(q, 2.0 * h, false, None, None), brute(&at, q, 2.0 * h));
            }
        }
        assert!(checked > 500, "{checked}");
    }
}
