//! Alg. 4.1 (thesis §4.2, projection and flood fill) for closed surfaces whose inside the grid
//! resolves; the surface is wound so that `(b - a) × (c - a)` points out of the body.
//!
//! - Steps 1-3: a node whose box (the node and its neighbours) meets a triangle box is near the
//!   surface; it is inside when `(x_i - x'_i) · N ≤ 0`, with `x'_i` its closest surface point
//!   (§4.2.1) and `N` the normal of the feature holding `x'_i`: the face normal inside a face,
//!   and on an edge or a vertex the angle-weighted pseudo-normal (Bærentzen & Aanæs, IEEE TVCG
//!   2005; the sum of the two face normals on an edge, the corner-angle-weighted sum on a vertex).
//!   This replaces the case analysis of §4.2.2 (b) and (c) by one rule with the same answer on a
//!   closed, consistently wound surface.
//! - Step 4: the other nodes take the side of the nearest decided node by a flood fill over the
//!   adjacency; a part of the mesh with no decided node is outside.
//! - Step 5: an edge whose ends are on different sides is cut where it crosses the triangles near
//!   it (the crossing nearest to node `i`). If rounding put the ends on different sides without
//!   an exact crossing, the cut is the surface point nearest to the edge's midpoint (within one
//!   edge length), projected onto the edge.
//!
//! An edge that crosses a thin body twice has both ends on one side and is not cut (thesis
//! Fig. 4.5, Case II): [`super::collision()`] is the algorithm for such bodies. Phi is not used:
//! a cracked surface is not closed.

use super::{Intersections, Near, SurfaceAt};
use crate::embedded::adjacency::NodeEdges;
use crate::embedded::predicates::{closest_point, unit_normal, Closest, Feature};
use crate::mesh::geometry::{add, cross, dot, norm, scale, sub};
use crate::mesh::Mesh;
use rayon::prelude::*;

/// Cut edges and occluded nodes by Alg. 4.1; the inside test is [`projection_inside`]. Tests
/// every node.
pub fn projection(mesh: &Mesh, adjacency: &NodeEdges, at: SurfaceAt<'_>) -> Intersections {
    projection_near(mesh, adjacency, at, &Near::all(mesh))
}

/// [`projection()`] testing only the nodes of `near` against the surface ([`Near::find`]); the
/// flood fill and the comparison of the sides of each edge still run over the whole mesh.
pub fn projection_near(
    mesh: &Mesh,
    adjacency: &NodeEdges,
    at: SurfaceAt<'_>,
    near: &Near,
) -> Intersections {
    let inside = inside_among(mesh, adjacency, at, &near.nodes);
    let occluded = at.occluded(mesh, &adjacency.h_min, false, &near.nodes);
    let blocks: Vec<_> = (0..mesh.blocks.len())
        .into_par_iter()
        .map(|b| {
            let mut cuts = Vec::new();
            for e in mesh.blocks.edges(b) {
                let [i, j] = mesh.edges[e].map(|v| v as usize);
                if inside[i] == inside[j] {
                    continue;
                }
                if let Some(c) = at.nearest_crossing(mesh, e, false) {
                    cuts.push(c);
                    continue;
                }
                let (p, q) = (mesh.coords[i], mesh.coords[j]);
                let d = sub(q, p);
                let l2 = dot(d, d);
                let mid = add(p, scale(d, 0.5));
                if let Some((t, cp)) = at.nearest_point(mid, l2.sqrt(), false) {
                    let [a, b, c] = at.corners(t);
                    let x =
                        add(add(scale(a, cp.bary[0]), scale(b, cp.bary[1])), scale(c, cp.bary[2]));
                    let alpha = (dot(sub(x, p), d) / l2).clamp(0.0, 1.0);
                    cuts.push(at.cut(e, t, alpha, cp.bary));
                }
            }
            cuts
        })
        .collect();
    Intersections::from_blocks(blocks, occluded)
}

/// Per node: inside the closed surface (Alg. 4.1 steps 1-4).
pub fn projection_inside(mesh: &Mesh, adjacency: &NodeEdges, at: SurfaceAt<'_>) -> Vec<bool> {
    let all: Vec<u32> = (0..mesh.n_nodes() as u32).collect();
    inside_among(mesh, adjacency, at, &all)
}

/// [`projection_inside`] with steps 1-3 run only at `candidates` (ascending; a node whose box
/// meets no triangle box is not near and is left to the flood fill).
fn inside_among(
    mesh: &Mesh,
    adjacency: &NodeEdges,
    at: SurfaceAt<'_>,
    candidates: &[u32],
) -> Vec<bool> {
    debug_assert_eq!(adjacency.h_min.len(), mesh.n_nodes(), "adjacency of another mesh");
    let normals = PseudoNormals::new(at);
    // Steps 1-3: the near nodes, decided by their closest point.
    let decided: Vec<Option<bool>> = candidates
        .par_iter()
        .map(|&i| {
            let i = i as usize;
            let p = mesh.coords[i];
            let (lo, hi) = adjacency.node_box(mesh, i);
            let mut best: Option<(u32, Closest)> = None;
            at.bvh.for_each_overlap(&lo, &hi, |t| {
                let [a, b, c] = at.corners(t);
                let cp = closest_point(p, a, b, c);
                if best.is_none_or(|(bt, bc)| (cp.dist2, t) < (bc.dist2, bt)) {
                    best = Some((t, cp));
                }
            });
            let (mut t, mut cp) = best?;
            // The nearest triangle lies within that distance; unless the ball of that radius is
            // inside b_i, look for it beyond b_i.
            let r = cp.dist2.sqrt();
            if (0..3).any(|d| p[d] - r < lo[d] || p[d] + r > hi[d]) {
                (t, cp) = at.nearest_point(p, r * (1.0 + 1e-12) + f64::MIN_POSITIVE, false)?;
            }
            let [a, b, c] = at.corners(t);
            let x = add(add(scale(a, cp.bary[0]), scale(b, cp.bary[1])), scale(c, cp.bary[2]));
            Some(dot(sub(p, x), normals.at(t, cp.feature)) <= 0.0)
        })
        .collect();
    let mut inside: Vec<Option<bool>> = vec![None; mesh.n_nodes()];
    for (&i, d) in candidates.iter().zip(decided) {
        inside[i as usize] = d;
    }
    // Step 4: flood fill from the decided nodes, in node order.
    let mut queue: Vec<usize> = (0..mesh.n_nodes()).filter(|&i| inside[i].is_some()).collect();
    let mut head = 0;
    while head < queue.len() {
        let i = queue[head];
        head += 1;
        for (j, _) in adjacency.neighbours(mesh, i) {
            if inside[j].is_none() {
                inside[j] = inside[i];
                queue.push(j);
            }
        }
    }
    inside.into_iter().map(|s| s.unwrap_or(false)).collect()
}

/// Face, edge and vertex normals of the surface at one set of positions.
struct PseudoNormals<'a> {
    face: Vec<[f64; 3]>,
    /// Per triangle, the normal of its edge opposite each corner.
    edge: Vec<[[f64; 3]; 3]>,
    vertex: Vec<[f64; 3]>,
    triangles: &'a [[u32; 3]],
}

impl<'a> PseudoNormals<'a> {
    fn new(at: SurfaceAt<'a>) -> PseudoNormals<'a> {
        let tris = &at.surface.triangles;
        let face: Vec<[f64; 3]> = (0..tris.len() as u32)
            .map(|t| {
                let [a, b, c] = at.corners(t);
                unit_normal(a, b, c)
            })
            .collect();
        let mut vertex = vec![[0.0; 3]; at.x.len()];
        for (t, tri) in tris.iter().enumerate() {
            let c = at.corners(t as u32);
            for k in 0..3 {
                let (u, w) = (sub(c[(k + 1) % 3], c[k]), sub(c[(k + 2) % 3], c[k]));
                let angle = norm(cross(u, w)).atan2(dot(u, w));
                let v = tri[k] as usize;
                vertex[v] = add(vertex[v], scale(face[t], angle));
            }
        }
        // Edge normals: the faces sharing each (sorted) node pair, summed.
        let mut keys: Vec<(u32, u32, u32, u8)> = Vec::with_capacity(3 * tris.len());
        for (t, tri) in tris.iter().enumerate() {
            for k in 0..3u8 {
                let (a, b) = (tri[(k as usize + 1) % 3], tri[(k as usize + 2) % 3]);
                keys.push((a.min(b), a.max(b), t as u32, k));
            }
        }
        keys.sort_unstable();
        let mut edge = vec![[[0.0; 3]; 3]; tris.len()];
        for run in keys.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
            let n = run.iter().fold([0.0; 3], |s, r| add(s, face[r.2 as usize]));
            for r in run {
                edge[r.2 as usize][r.3 as usize] = n;
            }
        }
        PseudoNormals { face, edge, vertex, triangles: tris }
    }

    #[inline]
    fn at(&self, t: u32, feature: Feature) -> [f64; 3] {
        let t = t as usize;
        match feature {
            Feature::Face => self.face[t],
            Feature::Edge(k) => self.edge[t][k as usize],
            Feature::Vertex(k) => self.vertex[self.triangles[t][k as usize] as usize],
        }
    }
}
