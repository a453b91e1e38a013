//! Geometric predicates of the interface tracking (thesis §4.2.1 and §4.3): the exact orientation
//! of four points (Shewchuk's adaptive `orient3d` through the `robust` crate), the crossing of a
//! fluid edge with a surface triangle, the closest point of a triangle to a node, and the instant
//! at which a moving triangle passes over a fixed node (continuous collision, Alg. 4.2 step 5.1).
//!
//! The crossing test decides every sign exactly, so it has no tolerance: a triangle is closed (its
//! edges and vertices belong to it), hence an edge through the common edge or vertex of several
//! triangles is found by each of them, and no edge slips between two triangles that share an
//! edge. The positions returned (α along the edge, barycentric coordinates) are rounded values
//! computed from the same determinants.

use crate::mesh::geometry::{add, cross, dot, scale, sub};

/// Orientation of `d` against the plane of the triangle `(a, b, c)`: positive where the normal
/// `(b - a) × (c - a)` points, negative on the other side, zero exactly when the four points are
/// coplanar. The sign is exact; the magnitude is six times the signed volume, rounded.
#[inline]
pub fn orient(a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3]) -> f64 {
    let p = |x: [f64; 3]| robust::Coord3D { x: x[0], y: x[1], z: x[2] };
    // Shewchuk's orient3d is positive when d lies below the plane seen with abc counterclockwise.
    -robust::orient3d(p(a), p(b), p(c), p(d))
}

/// Where a fluid edge crosses a triangle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EdgeHit {
    /// `x = p + α (q - p)`, `α ∈ [0, 1]`.
    pub alpha: f64,
    /// Barycentric coordinates of the crossing in the triangle (each `>= 0`, sum 1).
    pub bary: [f64; 3],
}

/// The crossing of the segment `p q` with the closed triangle `(a, b, c)`, if any
/// ([`TriangleFrom::crossing`]).
pub fn segment_triangle(
    p: [f64; 3],
    q: [f64; 3],
    a: [f64; 3],
    b: [f64; 3],
    c: [f64; 3],
) -> Option<EdgeHit> {
    TriangleFrom::new(p, [a, b, c]).crossing(q)
}

/// Relative bound on the rounding error of a triple product of rounded differences, above
/// Shewchuk's `(7 + 56ε)ε` for `orient3d`'s first stage (`ε = 2⁻⁵³`): the same cofactor
/// expansion, taken along a row of the matrix instead of a column.
const TRIPLE_ERROR: f64 = 4.0 * f64::EPSILON;

/// The cross product `u × v` of two rounded difference vectors, with the permanent of its
/// components (`|u₁v₂| + |u₂v₁|`, …) that bounds the rounding of a triple product `w · (u × v)`.
#[derive(Debug, Clone, Copy)]
struct Cross {
    uv: [f64; 3],
    permanent: [f64; 3],
}

impl Cross {
    #[inline]
    fn of(u: [f64; 3], v: [f64; 3]) -> Self {
        let pair = |k: usize, l: usize| (u[k] * v[l], u[l] * v[k]);
        let terms = [pair(1, 2), pair(2, 0), pair(0, 1)];
        Self { uv: terms.map(|(x, y)| x - y), permanent: terms.map(|(x, y)| x.abs() + y.abs()) }
    }

    /// `w · (u × v)` rounded, and whether the rounding cannot have changed its sign (then its
    /// sign is exact and it is nonzero).
    #[inline]
    fn triple_rounded(&self, w: [f64; 3]) -> (f64, bool) {
        let det = w[0] * self.uv[0] + w[1] * self.uv[1] + w[2] * self.uv[2];
        let permanent = w[0].abs() * self.permanent[0]
            + w[1].abs() * self.permanent[1]
            + w[2].abs() * self.permanent[2];
        (det, det.abs() > TRIPLE_ERROR * permanent)
    }

    /// `w · (u × v)` when the rounding cannot have changed its sign, else `None`.
    #[inline]
    fn triple(&self, w: [f64; 3]) -> Option<f64> {
        let (det, certain) = self.triple_rounded(w);
        certain.then_some(det)
    }
}

/// A triangle `(a, b, c)` seen from the first end `p` of fluid edges: what the crossing tests of
/// all the edges from `p` share (the triangle's normal, the side of `p`, and the three cross
/// products of the corners seen from `p`).
///
/// Every orientation is a triple product of rounded differences, kept when its error bound
/// ([`TRIPLE_ERROR`]) shows its sign, else replaced by the exact [`orient`]: signs are exact,
/// and the values depend only on `p`, `q` and the corners, shared or not.
///
/// Making one and testing it are always inlined into the scans over a node's triangles: as
/// calls, the fresh triangle was stored and read back from memory at each test.
#[derive(Debug, Clone)]
pub struct TriangleFrom {
    p: [f64; 3],
    corners: [[f64; 3]; 3],
    /// `(b - a) × (c - a)`.
    normal: Cross,
    /// `orient(a, b, c, p)`.
    sp: f64,
    /// `(b - p) × (c - p)`, `(c - p) × (a - p)`, `(a - p) × (b - p)`, made at the first edge
    /// whose ends are not on one side of the plane.
    fans: Option<[Cross; 3]>,
}

impl TriangleFrom {
    #[inline(always)]
    pub fn new(p: [f64; 3], corners: [[f64; 3]; 3]) -> Self {
        let [a, b, c] = corners;
        let normal = Cross::of(sub(b, a), sub(c, a));
        let sp = normal.triple(sub(p, a)).unwrap_or_else(|| orient(a, b, c, p));
        Self { p, corners, normal, sp, fans: None }
    }

    /// The crossing of the segment `p q` with the closed triangle, if any.
    ///
    /// The segment crosses when its ends are not strictly on one side of the triangle's plane
    /// and the line `p q` passes through the closed triangle: the three orientations of `p, q`
    /// against the triangle's edges do not take both signs. A segment lying in the plane of the
    /// triangle (both ends coplanar) is not a crossing, whatever it touches. With the volumes
    /// `V_a = orient(p, q, b, c)`, `V_b = orient(p, q, c, a)`, `V_c = orient(p, q, a, b)` the
    /// barycentric coordinates are `V_k / ΣV`, and `α = s_p / (s_p - s_q)` with
    /// `s = orient(a, b, c, ·)`.
    ///
    /// The side of `q` first (an edge on one side needs no volume), then the three volumes
    /// together, decided from their rounded values where those show their signs; else each is
    /// replaced by the exact one where needed ([`TriangleFrom::crossing_exact`]), which gives the
    /// same values wherever the rounded ones show their sign.
    #[inline(always)]
    pub fn crossing(&mut self, q: [f64; 3]) -> Option<EdgeHit> {
        let (a, p, sp) = (self.corners[0], self.p, self.sp);
        let (sq, certain_q) = self.normal.triple_rounded(sub(q, a));
        // `sq` is nonzero with an exact sign when certain; `sp` may be zero.
        if certain_q & (sp != 0.0) & ((sp > 0.0) == (sq > 0.0)) {
            return None;
        }
        let d = sub(q, p);
        let [(va, ca), (vb, cb), (vc, cc)] = self.fans().map(|f| f.triple_rounded(d));
        if !(certain_q & ca & cb & cc) {
            return self.crossing_exact(q);
        }
        // `va`, `vb`, `vc` are nonzero with exact signs.
        let positive = u8::from(va > 0.0) + u8::from(vb > 0.0) + u8::from(vc > 0.0);
        if positive % 3 != 0 {
            return None;
        }
        Some(Self::hit(sp, sq, [va, vb, vc]))
    }

    /// The cross products of the corners seen from `p`.
    #[inline(always)]
    fn fans(&mut self) -> [Cross; 3] {
        if let Some(fans) = self.fans {
            return fans;
        }
        let [pa, pb, pc] = self.corners.map(|x| sub(x, self.p));
        let fans = [Cross::of(pb, pc), Cross::of(pc, pa), Cross::of(pa, pb)];
        self.fans = Some(fans);
        fans
    }

    /// [`TriangleFrom::crossing`] with each orientation exact where its rounded value cannot
    /// show its sign.
    #[inline(never)]
    fn crossing_exact(&mut self, q: [f64; 3]) -> Option<EdgeHit> {
        let ([a, b, c], p, sp) = (self.corners, self.p, self.sp);
        let sq = self.normal.triple(sub(q, a)).unwrap_or_else(|| orient(a, b, c, q));
        if (sp == 0.0 && sq == 0.0) || (sp > 0.0 && sq > 0.0) || (sp < 0.0 && sq < 0.0) {
            return None;
        }
        // orient(p, q, x, y) = (q - p) · ((x - p) × (y - p)).
        let d = sub(q, p);
        let fans = self.fans();
        let volume = |k: usize, x: [f64; 3], y: [f64; 3]| {
            fans[k].triple(d).unwrap_or_else(|| orient(p, q, x, y))
        };
        // The line misses the closed triangle when two of the volumes take opposite signs: the
        // third is computed only when the first two do not.
        let opposite = |x: f64, y: f64| (x > 0.0 && y < 0.0) || (x < 0.0 && y > 0.0);
        let (va, vb) = (volume(0, b, c), volume(1, c, a));
        if opposite(va, vb) {
            return None;
        }
        let vc = volume(2, a, b);
        if opposite(va, vc) || opposite(vb, vc) {
            return None;
        }
        Some(Self::hit(sp, sq, [va, vb, vc]))
    }

    /// The crossing from the orientations of its ends and its volumes, which share one sign (not
    /// coplanar: the line meets the plane in one point).
    #[inline]
    fn hit(sp: f64, sq: f64, v: [f64; 3]) -> EdgeHit {
        let sum = v[0] + v[1] + v[2];
        let bary = [v[0] / sum, v[1] / sum, v[2] / sum];
        let alpha = (sp / (sp - sq)).clamp(0.0, 1.0);
        EdgeHit { alpha, bary }
    }
}

/// The part of a triangle that holds the closest point to a node: its interior, the edge opposite
/// corner `k` (the edge `(k+1, k+2)`), or corner `k`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Feature {
    Face,
    Edge(u8),
    Vertex(u8),
}

/// The closest point of a triangle to a node.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Closest {
    /// Squared distance from the node.
    pub dist2: f64,
    /// Barycentric coordinates of the closest point (each `>= 0`, sum 1).
    pub bary: [f64; 3],
    pub feature: Feature,
}

/// Closest point of the triangle `(a, b, c)` to `p` (thesis §4.2.1: the projection onto the plane
/// when its barycentric coordinates are all non-negative, else onto an edge, else a corner), by
/// the Voronoi regions of the corners and edges (Ericson, Real-Time Collision Detection §5.1.5).
/// A degenerate triangle (zero area) returns its nearest corner.
pub fn closest_point(p: [f64; 3], a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> Closest {
    let at = |bary: [f64; 3], feature| {
        let x = add(add(scale(a, bary[0]), scale(b, bary[1])), scale(c, bary[2]));
        let d = sub(p, x);
        Closest { dist2: dot(d, d), bary, feature }
    };
    let (ab, ac, ap) = (sub(b, a), sub(c, a), sub(p, a));
    let (d1, d2) = (dot(ab, ap), dot(ac, ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return at([1.0, 0.0, 0.0], Feature::Vertex(0));
    }
    let bp = sub(p, b);
    let (d3, d4) = (dot(ab, bp), dot(ac, bp));
    if d3 >= 0.0 && d4 <= d3 {
        return at([0.0, 1.0, 0.0], Feature::Vertex(1));
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return at([1.0 - v, v, 0.0], Feature::Edge(2));
    }
    let cp = sub(p, c);
    let (d5, d6) = (dot(ab, cp), dot(ac, cp));
    if d6 >= 0.0 && d5 <= d6 {
        return at([0.0, 0.0, 1.0], Feature::Vertex(2));
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return at([1.0 - w, 0.0, w], Feature::Edge(1));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return at([0.0, 1.0 - w, w], Feature::Edge(0));
    }
    let denom = va + vb + vc;
    if denom.abs() <= f64::MIN_POSITIVE {
        // Zero area (the Voronoi tests above are then inconclusive): the nearest corner.
        return [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
            .into_iter()
            .enumerate()
            .map(|(k, bary)| at(bary, Feature::Vertex(k as u8)))
            .fold(
                at([1.0, 0.0, 0.0], Feature::Vertex(0)),
                |m, x| if x.dist2 < m.dist2 { x } else { m },
            );
    }
    let (v, w) = (vb / denom, vc / denom);
    at([1.0 - v - w, v, w], Feature::Face)
}

/// Unit normal `(b - a) × (c - a) / |…|` of a triangle (zero for a degenerate one).
#[inline]
pub fn unit_normal(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> [f64; 3] {
    let n = cross(sub(b, a), sub(c, a));
    let l = dot(n, n).sqrt();
    if l > 0.0 {
        scale(n, 1.0 / l)
    } else {
        [0.0; 3]
    }
}

/// Bisection steps for a crossing instant: the bracket shrinks below `2^-52` of the step.
const SWEEP_BISECTIONS: usize = 52;
/// Barycentric slack of the inside test at the crossing instant (the instant is rounded).
const SWEEP_BARY_SLACK: f64 = 1e-9;

/// The first fraction `s ∈ [0, 1]` of the step at which the triangle moving linearly from
/// `(a0, b0, c0)` to `(a1, b1, c1)` passes over the fixed point `p`: the instant `p` is coplanar
/// with it (a root of the cubic `f(s) = orient(a(s), b(s), c(s), p)`) and lies inside it (thesis
/// Alg. 4.2 step 5.1; the triangle moves on the straight line between its positions at `t_a` and
/// `t_b`, not on the Hermite path: the swept boxes of the hierarchy hold exactly this motion).
///
/// The cubic is split at the roots of its derivative into monotone pieces and each piece with a
/// sign change is bisected on `f` itself; the signs at `s = 0` and `s = 1` are exact. A point
/// that stays in the plane of the triangle for the whole step is not swept (nothing crosses it).
pub fn sweep_over_point(p: [f64; 3], from: [[f64; 3]; 3], to: [[f64; 3]; 3]) -> Option<f64> {
    let corners = |s: f64| {
        let m = |k: usize| add(from[k], scale(sub(to[k], from[k]), s));
        [m(0), m(1), m(2)]
    };
    let f = |s: f64| {
        let [a, b, c] = corners(s);
        if s == 0.0 || s == 1.0 {
            orient(a, b, c, p)
        } else {
            dot(cross(sub(b, a), sub(c, a)), sub(p, a))
        }
    };
    // The cubic through f at s = 0, 1/3, 2/3, 1, in the monomial basis c0 + c1 s + c2 s² + c3 s³.
    let (f0, f1, f2, f3) = (f(0.0), f(1.0 / 3.0), f(2.0 / 3.0), f(1.0));
    let c1 = (-11.0 * f0 + 18.0 * f1 - 9.0 * f2 + 2.0 * f3) / 2.0;
    let c2 = (18.0 * f0 - 45.0 * f1 + 36.0 * f2 - 9.0 * f3) / 2.0;
    let c3 = (-9.0 * f0 + 27.0 * f1 - 27.0 * f2 + 9.0 * f3) / 2.0;
    // Break points: 0, the derivative's roots in (0, 1), 1.
    let mut cuts = [0.0, 1.0, 1.0, 1.0];
    let mut n = 1;
    let (qa, qb, qc) = (3.0 * c3, 2.0 * c2, c1);
    let scale_q = qa.abs().max(qb.abs()).max(qc.abs());
    if scale_q > 0.0 {
        let mut push = |r: f64| {
            if r > 0.0 && r < 1.0 {
                cuts[n] = r;
                n += 1;
            }
        };
        if qa.abs() > 1e-12 * scale_q {
            let disc = qb * qb - 4.0 * qa * qc;
            if disc >= 0.0 {
                let sq = disc.sqrt();
                let qq = -0.5 * (qb + qb.signum() * sq);
                if qq != 0.0 {
                    push(qq / qa);
                    push(qc / qq);
                } else {
                    push(0.0);
                }
            }
        } else if qb != 0.0 {
            push(-qc / qb);
        }
    }
    cuts[n] = 1.0;
    cuts[..=n].sort_by(f64::total_cmp);
    for k in 0..n {
        let (mut lo, mut hi) = (cuts[k], cuts[k + 1]);
        let (mut flo, fhi) = (f(lo), f(hi));
        let root = if flo == 0.0 {
            lo
        } else if fhi == 0.0 {
            hi
        } else if (flo > 0.0) != (fhi > 0.0) {
            for _ in 0..SWEEP_BISECTIONS {
                let mid = 0.5 * (lo + hi);
                let fm = f(mid);
                if (fm > 0.0) == (flo > 0.0) && fm != 0.0 {
                    lo = mid;
                    flo = fm;
                } else {
                    hi = mid;
                }
            }
            0.5 * (lo + hi)
        } else {
            continue;
        };
        let [a, b, c] = corners(root);
        let cp = closest_point(p, a, b, c);
        let size = dot(sub(b, a), sub(b, a)).max(dot(sub(c, a), sub(c, a)));
        if cp.dist2 <= SWEEP_BARY_SLACK * SWEEP_BARY_SLACK * size {
            // Not an instant of the whole step in the plane (f ≡ 0 has no crossing).
            if f0 == 0.0 && f3 == 0.0 && f1 == 0.0 && f2 == 0.0 {
                return None;
            }
            return Some(root);
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    const A: [f64; 3] = [0.0, 0.0, 0.0];
    const B: [f64; 3] = [1.0, 0.0, 0.0];
    const C: [f64; 3] = [0.0, 1.0, 0.0];
    const D: [f64; 3] = [1.0, 1.0, 0.0];

    #[test]
    fn orientation_sign_follows_the_normal() {
        assert!(orient(A, B, C, [0.2, 0.2, 1.0]) > 0.0);
        assert!(orient(A, B, C, [0.2, 0.2, -1e-300]) < 0.0);
        assert_eq!(orient(A, B, C, [5.0, -3.0, 0.0]), 0.0);
        // Exactly on the plane x + y + z = 1, and one ulp off it.
        let (a, b, c) = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
        assert_eq!(orient(a, b, c, [0.125, 0.375, 0.5]), 0.0);
        assert!(orient(a, b, c, [0.125, 0.375, 0.5 + f64::EPSILON / 2.0]) > 0.0);
        assert!(orient(a, b, c, [0.125 - f64::EPSILON / 16.0, 0.375, 0.5]) < 0.0);
    }

    #[test]
    fn crossing_gives_alpha_and_barycentrics() {
        let h = segment_triangle([0.2, 0.3, -1.0], [0.2, 0.3, 3.0], A, B, C).unwrap();
        assert!((h.alpha - 0.25).abs() < 1e-15);
        let x = [0.5, 0.2, 0.3];
        for k in 0..3 {
            assert!((h.bary[k] - x[k]).abs() < 1e-15, "{:?}", h.bary);
        }
        assert!(segment_triangle([0.6, 0.6, -1.0], [0.6, 0.6, 1.0], A, B, C).is_none());
        assert!(segment_triangle([0.2, 0.2, 0.5], [0.2, 0.2, 1.0], A, B, C).is_none());
    }

    /// The square `A B D C` as two triangles sharing the diagonal `B C`.
    fn square_hits(p: [f64; 3], q: [f64; 3]) -> Vec<EdgeHit> {
        [[A, B, C], [B, D, C]]
            .iter()
            .filter_map(|t| segment_triangle(p, q, t[0], t[1], t[2]))
            .collect()
    }

    #[test]
    fn edge_through_a_shared_edge_is_found_by_both_triangles() {
        // Through the diagonal x + y = 1 (exactly: 0.3 + 0.7 is not 1 in binary, 0.375 + 0.625 is).
        let (x, y) = (0.375, 0.625);
        let hits = square_hits([x, y, -0.1], [x, y, 0.3]);
        assert_eq!(hits.len(), 2);
        for h in &hits {
            assert!((h.alpha - 0.25).abs() < 1e-15);
        }
        // Slanted edges through many points of the diagonal: never a leak between the two.
        for k in 1..200 {
            let s = k as f64 / 200.0 + 1e-3 * (k as f64).sin();
            let m = [s, 1.0 - s, 0.0];
            let d = [0.31, -0.17, 0.9];
            let hits = square_hits(sub(m, scale(d, 0.37)), add(m, scale(d, 0.63)));
            assert!(!hits.is_empty() && hits.len() <= 2, "{k}: {} hits", hits.len());
        }
    }

    #[test]
    fn edge_through_a_vertex_is_found() {
        assert_eq!(square_hits([0.0, 0.0, -1.0], [0.0, 0.0, 1.0]).len(), 1);
        assert_eq!(square_hits([1.0, 0.0, -1.0], [1.0, 0.0, 1.0]).len(), 2);
        // A fan of six triangles around the origin: each reports the shared vertex.
        let ring: Vec<[f64; 3]> = (0..6)
            .map(|k| {
                let t = k as f64 * std::f64::consts::PI / 3.0;
                [t.cos(), t.sin(), 0.1 * t.sin()]
            })
            .collect();
        let hits = (0..6)
            .filter_map(|k| {
                segment_triangle([0.0, 0.0, -1.0], [0.0, 0.0, 2.0], A, ring[k], ring[(k + 1) % 6])
            })
            .count();
        assert_eq!(hits, 6);
    }

    #[test]
    fn coplanar_edges_are_not_crossings() {
        assert!(square_hits([-0.5, 0.5, 0.0], [1.5, 0.5, 0.0]).is_empty());
        assert!(square_hits([0.2, 0.2, 0.0], [0.3, 0.3, 0.0]).is_empty());
        // An edge ending on the triangle's face crosses it at α = 1.
        let h = segment_triangle([0.2, 0.2, 1.0], [0.2, 0.2, 0.0], A, B, C).unwrap();
        assert_eq!(h.alpha, 1.0);
    }

    /// The crossing test on exact orientations only (every volume by [`orient`]).
    fn crossing_by_orient(p: [f64; 3], q: [f64; 3], [a, b, c]: [[f64; 3]; 3]) -> Option<EdgeHit> {
        let (sp, sq) = (orient(a, b, c, p), orient(a, b, c, q));
        if (sp == 0.0 && sq == 0.0) || sp * sq > 0.0 {
            return None;
        }
        let v = [orient(p, q, b, c), orient(p, q, c, a), orient(p, q, a, b)];
        if v.iter().any(|&x| x > 0.0) && v.iter().any(|&x| x < 0.0) {
            return None;
        }
        let sum = v[0] + v[1] + v[2];
        Some(EdgeHit { alpha: (sp / (sp - sq)).clamp(0.0, 1.0), bary: v.map(|x| x / sum) })
    }

    #[test]
    fn filtered_volumes_decide_as_the_exact_orientations() {
        // Segments through points of a triangle's edges and corners, and segments ending on its
        // plane or a few ulps off it, from one node against many triangles: where the rounded
        // triple products cannot show a sign the exact one decides, so hits agree one for one.
        let mut state = 7u64;
        let mut unit = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut hits, mut cases) = (0, 0);
        for _ in 0..400 {
            let tri: [[f64; 3]; 3] = [(); 3].map(|_| [unit(), unit(), 0.3 * unit()]);
            let mut from = TriangleFrom::new([0.4, 0.45, 1.0], tri);
            for k in 0..24 {
                let (s, w) = (unit(), unit());
                // A point of the triangle's boundary (edge k % 3 at s, or a corner), or inside.
                let on = match k % 4 {
                    0 => add(scale(tri[k % 3], 1.0 - s), scale(tri[(k + 1) % 3], s)),
                    1 => tri[k % 3],
                    _ => add(
                        scale(tri[0], s * w),
                        add(scale(tri[1], (1.0 - s) * w), scale(tri[2], 1.0 - w)),
                    ),
                };
                // The segment from p through `on`, ending on it (k < 12) or past it.
                let beyond = if k < 12 { 1.0 } else { 1.0 + unit() };
                let q = add(from.p, scale(sub(on, from.p), beyond));
                let q = if k % 5 == 4 { q.map(|x| x + f64::EPSILON * (unit() - 0.5)) } else { q };
                let (got, want) = (from.crossing(q), crossing_by_orient(from.p, q, tri));
                assert_eq!(got.is_some(), want.is_some(), "{tri:?} {q:?}");
                if let (Some(g), Some(w)) = (got, want) {
                    assert!((g.alpha - w.alpha).abs() < 1e-12, "{} {}", g.alpha, w.alpha);
                    for d in 0..3 {
                        assert!(g.bary[d] >= 0.0 && (g.bary[d] - w.bary[d]).abs() < 1e-9);
                    }
                    hits += 1;
                }
                cases += 1;
            }
        }
        assert!(hits > cases / 3, "{hits} hits of {cases}");
    }

    #[test]
    fn closest_point_in_each_region() {
        let c = closest_point([0.2, 0.3, 2.0], A, B, C);
        assert_eq!(c.feature, Feature::Face);
        assert!((c.dist2 - 4.0).abs() < 1e-14);
        let c = closest_point([0.5, -1.0, 1.0], A, B, C);
        assert_eq!(c.feature, Feature::Edge(2));
        assert!((c.dist2 - 2.0).abs() < 1e-14 && (c.bary[1] - 0.5).abs() < 1e-15);
        let c = closest_point([1.0, 1.0, 0.0], A, B, C);
        assert_eq!(c.feature, Feature::Edge(0));
        assert!((c.dist2 - 0.5).abs() < 1e-14);
        let c = closest_point([-1.0, -2.0, 0.0], A, B, C);
        assert_eq!(c.feature, Feature::Vertex(0));
        assert!((c.dist2 - 5.0).abs() < 1e-14);
        assert_eq!(closest_point([0.0, 3.0, 0.0], A, B, C).feature, Feature::Vertex(2));
    }

    #[test]
    fn moving_triangle_sweeps_the_points_it_passes() {
        let up = |z: f64| [[0.0, 0.0, z], [1.0, 0.0, z], [0.0, 1.0, z]];
        let s = sweep_over_point([0.2, 0.2, 0.3], up(0.0), up(1.0)).unwrap();
        assert!((s - 0.3).abs() < 1e-14);
        assert!(sweep_over_point([0.2, 0.2, 1.3], up(0.0), up(1.0)).is_none());
        assert!(sweep_over_point([0.8, 0.8, 0.3], up(0.0), up(1.0)).is_none());
        assert!(sweep_over_point([0.2, 0.2, 0.0], up(0.0), up(0.0)).is_none());
        // A rotating triangle: the plane through the x axis turns from z = 0 to y = 0 (a cubic
        // in s because the corner moves on a chord); the point at angle 45° is passed half way.
        let from = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [1.0, 1.0, 0.0]];
        let to = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [1.0, 0.0, 1.0]];
        let s = sweep_over_point([1.0, 0.3, 0.3], from, to).unwrap();
        assert!((s - 0.5).abs() < 1e-12, "{s}");
    }
}
