//! Test-only stand-in for the tracking (Alg. 4.1, 4.2): the cut edges of a mesh against a surface
//! by brute force, every edge against every triangle with a plain (non-robust) segment-triangle
//! test (Möller-Trumbore). Test surfaces are placed so that no mesh node lies on them.

use super::{CutEdge, Surface};
use crate::mesh::geometry::{cross, dot, norm, scale, sub};
use crate::mesh::Mesh;

/// Intersection of the segment `a -> b` with triangle `x`: `(α, barycentric)`, inclusive of the
/// triangle's edges up to `1e-12`.
fn segment_triangle(a: [f64; 3], b: [f64; 3], x: [[f64; 3]; 3]) -> Option<(f64, [f64; 3])> {
    let d = sub(b, a);
    let (e1, e2) = (sub(x[1], x[0]), sub(x[2], x[0]));
    let p = cross(d, e2);
    let det = dot(e1, p);
    if det.abs() <= 1e-14 * norm(d) * norm(e1) * norm(e2) {
        return None;
    }
    let s = sub(a, x[0]);
    let u = dot(s, p) / det;
    let q = cross(s, e1);
    let v = dot(d, q) / det;
    let alpha = dot(e2, q) / det;
    let tol = 1e-12;
    (u >= -tol && v >= -tol && u + v <= 1.0 + tol && (0.0..=1.0).contains(&alpha))
        .then_some((alpha, [1.0 - u - v, u, v]))
}

/// The cut edges of `mesh` against `surface` at time `t`, sorted by edge, the intersection
/// nearest to node `i` kept.
pub fn brute_force_cuts(mesh: &Mesh, surface: &Surface, t: f64) -> Vec<CutEdge> {
    let tris: Vec<[[f64; 3]; 3]> =
        (0..surface.triangles.len()).map(|k| surface.triangle_at(k, t).0).collect();
    let mut cuts = Vec::new();
    for (e, &[i, j]) in mesh.edges.iter().enumerate() {
        let (a, b) = (mesh.coords[i as usize], mesh.coords[j as usize]);
        let mut best: Option<CutEdge> = None;
        for (k, x) in tris.iter().enumerate() {
            if let Some((alpha, bary)) = segment_triangle(a, b, *x) {
                if best.is_none_or(|c| alpha < c.alpha) {
                    let n = cross(sub(x[1], x[0]), sub(x[2], x[0]));
                    let normal = scale(n, 1.0 / norm(n));
                    best =
                        Some(CutEdge { edge: e as u32, alpha, triangle: k as u32, bary, normal });
                }
            }
        }
        cuts.extend(best);
    }
    cuts
}
