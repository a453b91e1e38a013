//! The normals of Alg. 4.1's inside test (steps 1-3): the face normal inside a face, and on an
//! edge or a vertex the angle-weighted pseudo-normal (Bærentzen & Aanæs, IEEE TVCG 2005): the sum
//! of the face normals of the triangles holding the edge, and the sum over the triangles around
//! the vertex of the face normal times the corner angle.
//!
//! A step decides a few hundred nodes, whose closest points lie on as many features, while the
//! surface has tens of thousands: [`PseudoNormals::of`] computes the normals of the features
//! asked for only, from the triangles around them (the surface's edges and the triangles around
//! each node, [`crate::embedded::surface::SurfaceEdges`]), each from the same terms summed in the
//! same order (triangle order on a vertex, the edge's sides in order on an edge) as the normals
//! of every feature would be: the same values bitwise.

use super::SurfaceAt;
use crate::embedded::predicates::{unit_normal, Feature};
use crate::mesh::geometry::{add, cross, dot, norm, scale, sub};

/// The normals of some features of the surface at one set of positions.
pub(super) struct PseudoNormals<'a> {
    at: SurfaceAt<'a>,
    /// Face normals of the triangles the features asked for need, by triangle, ascending.
    face: Vec<(u32, [f64; 3])>,
    /// Vertex normals of the vertices asked for, by node, ascending.
    vertex: Vec<(u32, [f64; 3])>,
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
    /// The normals of the features `wanted` (triangle, feature) of the surface `at`: the face
    /// normals of the triangles they touch (through the surface's edges and the triangles
    /// around each node), summed.
    pub fn of(
        at: SurfaceAt<'a>,
        wanted: impl Iterator<Item = (u32, Feature)>,
    ) -> PseudoNormals<'a> {
        let (tris, edges) = (&at.surface.triangles, &at.surface.edges);
        let (mut faces, mut vertices, mut runs) = (Vec::new(), Vec::new(), Vec::new());
        for (t, feature) in wanted {
            match feature {
                Feature::Face => faces.push(t),
                Feature::Edge(k) => runs.push(edges.edge_of(t, k)),
                Feature::Vertex(k) => vertices.push(tris[t as usize][k as usize]),
            }
        }
        for v in [&mut runs, &mut vertices] {
            v.sort_unstable();
            v.dedup();
        }
        faces.extend(runs.iter().flat_map(|&m| edges.run(m).iter().map(|&(t, _)| t)));
        faces.extend(vertices.iter().flat_map(|&v| edges.around(v).iter().copied()));
        faces.sort_unstable();
        faces.dedup();
        let face: Vec<(u32, [f64; 3])> = faces
            .into_iter()
            .map(|t| {
                let [a, b, c] = at.corners(t);
                (t, unit_normal(a, b, c))
            })
            .collect();
        let face_of = |t: u32| face[face.partition_point(|&(u, _)| u < t)].1;
        // Each sum over the triangles in ascending order, corners in order.
        let vertex = vertices
            .into_iter()
            .map(|v| {
                let mut n = [0.0; 3];
                for &t in edges.around(v) {
                    let tri = tris[t as usize];
                    for k in (0..3).filter(|&k| tri[k] == v) {
                        n = add(n, scale(face_of(t), corner_angle(&at.corners(t), k)));
                    }
                }
                (v, n)
            })
            .collect();
        let mut edge = Vec::new();
        for m in runs {
            let run = edges.run(m);
            let n = run.iter().fold([0.0; 3], |s, &(t, _)| add(s, face_of(t)));
            edge.extend(run.iter().map(|&side| (side, n)));
        }
        edge.sort_unstable_by_key(|&(side, _)| side);
        PseudoNormals { at, face, vertex, edge }
    }

    /// The normal of `feature` of triangle `t`, one of those asked for.
    #[inline]
    pub fn at(&self, t: u32, feature: Feature) -> [f64; 3] {
        let find = |list: &[(u32, [f64; 3])], key: u32| {
            list.binary_search_by_key(&key, |&(k, _)| k).map_or([0.0; 3], |m| list[m].1)
        };
        match feature {
            Feature::Face => find(&self.face, t),
            Feature::Edge(k) => {
                let found = self.edge.binary_search_by_key(&(t, k), |&(side, _)| side);
                found.map_or([0.0; 3], |m| self.edge[m].1)
            }
            Feature::Vertex(k) => {
                find(&self.vertex, self.at.surface.triangles[t as usize][k as usize])
            }
        }
    }
}
