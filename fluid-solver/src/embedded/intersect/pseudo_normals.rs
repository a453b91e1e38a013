//! The normals of Alg. 4.1's inside test (steps 1-3): the face normal inside a face, and on an
//! edge or a vertex the angle-weighted pseudo-normal (Bærentzen & Aanæs, IEEE TVCG 2005): the sum
//! of the face normals of the triangles holding the edge, and the sum over the triangles around
//! the vertex of the face normal times the corner angle.
//!
//! A step decides a few hundred nodes, whose closest points lie on as many features, while the
//! surface has tens of thousands: [`PseudoNormals::of`] computes the normals of the features
//! asked for only (the corner angles, one `atan2` each, were most of the cost), each from the
//! same terms summed in the same order (triangle order on a vertex, the edge's sides in order on
//! an edge) as the normals of every feature would be: the same values bitwise.

use super::SurfaceAt;
use crate::embedded::predicates::{unit_normal, Feature};
use crate::mesh::geometry::{add, cross, dot, norm, scale, sub};

/// The normals of some features of the surface at one set of positions.
pub(super) struct PseudoNormals<'a> {
    at: SurfaceAt<'a>,
    /// Face normals of the triangles the features asked for need (zero elsewhere).
    face: Vec<[f64; 3]>,
    /// Vertex normals of the vertices asked for (zero elsewhere).
    vertex: Vec<[f64; 3]>,
    /// The edge normals asked for, by triangle side `(t, k)` (the edge opposite corner `k`),
    /// ascending.
    edge: Vec<((u32, u8), [f64; 3])>,
}

/// The angle of the triangle `c` at corner `k`, the weight of its face normal in the vertex's.
#[inline]
pub(super) fn corner_angle(c: &[[f64; 3]; 3], k: usize) -> f64 {
    let (u, w) = (sub(c[(k + 1) % 3], c[k]), sub(c[(k + 2) % 3], c[k]));
    norm(cross(u, w)).atan2(dot(u, w))
}

impl<'a> PseudoNormals<'a> {
    /// The normals of the features `wanted` (triangle, feature) of the surface `at`.
    pub fn of(
        at: SurfaceAt<'a>,
        wanted: impl Iterator<Item = (u32, Feature)>,
    ) -> PseudoNormals<'a> {
        let tris = &at.surface.triangles;
        let mut face_wanted = vec![false; tris.len()];
        let mut vertex_wanted = vec![false; at.x.len()];
        let mut sides_wanted = Vec::new();
        for (t, feature) in wanted {
            match feature {
                Feature::Face => face_wanted[t as usize] = true,
                Feature::Edge(k) => sides_wanted.push((t, k)),
                Feature::Vertex(k) => vertex_wanted[tris[t as usize][k as usize] as usize] = true,
            }
        }
        sides_wanted.sort_unstable();
        sides_wanted.dedup();
        // The edges holding a wanted side, and the triangles around the wanted vertices.
        let runs: Vec<&[(u32, u8)]> = at
            .surface
            .edges
            .runs()
            .filter(|run| run.iter().any(|side| sides_wanted.binary_search(side).is_ok()))
            .collect();
        for &(t, _) in runs.iter().copied().flatten() {
            face_wanted[t as usize] = true;
        }
        for (t, tri) in tris.iter().enumerate() {
            if tri.iter().any(|&v| vertex_wanted[v as usize]) {
                face_wanted[t] = true;
            }
        }
        let mut face = vec![[0.0; 3]; tris.len()];
        for (t, n) in face.iter_mut().enumerate().filter(|(t, _)| face_wanted[*t]) {
            let [a, b, c] = at.corners(t as u32);
            *n = unit_normal(a, b, c);
        }
        let mut vertex = vec![[0.0; 3]; at.x.len()];
        for (t, tri) in tris.iter().enumerate() {
            for k in 0..3 {
                let v = tri[k] as usize;
                if vertex_wanted[v] {
                    let share = scale(face[t], corner_angle(&at.corners(t as u32), k));
                    vertex[v] = add(vertex[v], share);
                }
            }
        }
        let mut edge = Vec::new();
        for run in runs {
            let n = run.iter().fold([0.0; 3], |s, &(t, _)| add(s, face[t as usize]));
            edge.extend(run.iter().map(|&side| (side, n)));
        }
        edge.sort_unstable_by_key(|&(side, _)| side);
        PseudoNormals { at, face, vertex, edge }
    }

    /// The normal of `feature` of triangle `t`, one of those asked for.
    #[inline]
    pub fn at(&self, t: u32, feature: Feature) -> [f64; 3] {
        match feature {
            Feature::Face => self.face[t as usize],
            Feature::Edge(k) => {
                let found = self.edge.binary_search_by_key(&(t, k), |&(side, _)| side);
                found.map_or([0.0; 3], |m| self.edge[m].1)
            }
            Feature::Vertex(k) => {
                self.vertex[self.at.surface.triangles[t as usize][k as usize] as usize]
            }
        }
    }
}
