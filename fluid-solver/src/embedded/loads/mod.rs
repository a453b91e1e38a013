//! Flow-induced loads on the embedded surface (thesis §5.3): the pressure `p*` of Alg. 5.1 on each
//! side of each cut edge, integrated over a discrete interface and distributed to the surface
//! nodes by virtual work. Two interfaces:
//!
//! - [`LoadAlgorithm::Reconstructed`], Alg. 5.3 (Eq. 5.18) with the reconstruction of Alg. 5.2:
//!   inside every cut cell the polygon through the intersection points of its cut edges, each
//!   triangle of it with its own normal, `p*` interpolated linearly, each point's share of the
//!   load distributed with the shape functions of the structure triangle at that point (on a
//!   one-fluid shell every cut edge joins, its ends' sides by the orientation contract)
//!   ([`reconstructed`]);
//! - [`LoadAlgorithm::Facets`], Alg. 5.4 (Eq. 5.51): the surrogate interface of the dual facets of
//!   the cut edges, `p*` times the full facet area vector `ν_ij` at the intersection point,
//!   distributed with its barycentric coordinates ([`facets`]).
//!
//! Both conserve the resultant (partition of unity, Eq. 5.19, 5.52), and both give zero net force
//! for a constant pressure on a closed surface; Alg. 5.3 also zero moment. Output: one `[f64; 3]` per surface node in the
//! surface's (the protocol's) node order, the loads of both sides of a shell summed. The force on
//! the structure from the fluid at node `i` of a cut edge points from `i` towards the wall.

pub mod facets;
pub mod reconstructed;

use super::adjacency::NodeEdges;
use super::riemann_fs::WallPressures;
use super::{CutEdge, Surface};
use crate::mesh::Mesh;

/// The load algorithm of a case (`[fluid.embedded] loads`): Alg. 5.3 `Reconstructed`, second
/// order on arbitrary meshes, or Alg. 5.4 `Facets`, first order on arbitrary meshes and second on
/// meshes whose facets lie on the surface.
pub use interface_protocol::case::LoadAlgorithm;

/// What the loads read: the mesh, the surface at the load time `t`, the side of every node (any
/// two values for the two sides of the surface, as the node status gives them), the cut edges
/// (sorted by edge) and the `p*` of each side of each cut edge (`NaN` where the side holds no
/// fluid), with the mesh's adjacency (whose node-to-cell rows give the cells around the cuts).
#[derive(Clone, Copy)]
pub struct LoadView<'a> {
    pub mesh: &'a Mesh,
    pub adjacency: &'a NodeEdges,
    pub surface: &'a Surface,
    pub t: f64,
    pub side: &'a [u32],
    pub cuts: &'a [CutEdge],
    pub p_star: &'a [WallPressures],
}

/// Inputs the loads cannot use, named.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LoadError {
    #[error("loads: {what} has {got} entries, expected {expected}")]
    Length { what: &'static str, got: usize, expected: usize },
    #[error("loads: cut edge {index} refers to edge {edge} / surface triangle {triangle}, but the mesh has {n_edges} edges and the surface {n_triangles} triangles")]
    BadCut { index: usize, edge: u32, triangle: u32, n_edges: usize, n_triangles: usize },
}

/// Nodal loads by `algorithm` into `out` (one entry per surface node, overwritten).
pub fn nodal_loads(
    algorithm: LoadAlgorithm,
    view: &LoadView,
    out: &mut [[f64; 3]],
) -> Result<(), LoadError> {
    check(view, out.len())?;
    out.iter_mut().for_each(|f| *f = [0.0; 3]);
    match algorithm {
        LoadAlgorithm::Reconstructed => reconstructed::loads(view, out),
        LoadAlgorithm::Facets => facets::loads(view, out),
    }
    Ok(())
}

fn check(view: &LoadView, n_out: usize) -> Result<(), LoadError> {
    if view.side.len() != view.mesh.n_nodes() {
        return Err(LoadError::Length {
            what: "the node sides",
            got: view.side.len(),
            expected: view.mesh.n_nodes(),
        });
    }
    let expected = view.surface.n_nodes();
    if n_out != expected {
        return Err(LoadError::Length { what: "the loads buffer", got: n_out, expected });
    }
    if view.p_star.len() != view.cuts.len() {
        return Err(LoadError::Length {
            what: "p* (one pair per cut edge)",
            got: view.p_star.len(),
            expected: view.cuts.len(),
        });
    }
    let (n_edges, n_triangles) = (view.mesh.n_edges(), view.surface.triangles.len());
    for (index, c) in view.cuts.iter().enumerate() {
        if c.edge as usize >= n_edges || c.triangle as usize >= n_triangles {
            return Err(LoadError::BadCut {
                index,
                edge: c.edge,
                triangle: c.triangle,
                n_edges,
                n_triangles,
            });
        }
    }
    Ok(())
}

/// A side's pressure, `0` where it holds no fluid (`NaN`).
#[inline]
fn or_zero(p: f64) -> f64 {
    if p.is_nan() {
        0.0
    } else {
        p
    }
}

/// Adds `f` to the corners of surface triangle `tri` with weights `w` (shape-function values).
#[inline]
fn distribute(surface: &Surface, tri: u32, w: [f64; 3], f: [f64; 3], out: &mut [[f64; 3]]) {
    for (m, &node) in surface.triangles[tri as usize].iter().enumerate() {
        for k in 0..3 {
            out[node as usize][k] += w[m] * f[k];
        }
    }
}

#[cfg(test)]
mod tests;
