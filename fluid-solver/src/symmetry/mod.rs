//! Symmetry planes imposed strongly: no momentum residual normal to any symmetry plane a node
//! lies on.
//!
//! The flux of a symmetry plane ([`crate::bc`], the wall flux of thesis Alg. 5.1) imposes
//! `u·n = 0` only weakly: at a node on the plane the edges into the domain carry the momentum of
//! the pressure between the node and its neighbours, the plane the node's own wall pressure `p*`,
//! and the difference accelerates the node across the plane. The flow the plane stands for is the
//! restriction of a flow symmetric under the reflection `R = I - 2nnᵀ`
//! ([`crate::reconstruct::gradient`], mirror planes): on the mirrored mesh the node's edges to
//! `x_j` and to `R x_j` carry mirrored fluxes whose normal momenta cancel, so there the node's
//! normal momentum residual is exactly zero and `u·n` stays zero, while its mass, energy and
//! tangential momentum residuals are twice those of the half cell here. Removing the normal
//! momentum residual therefore makes the half-domain scheme the whole-domain one (with the
//! mirror-symmetric gradients of the reconstruction and the rotation-equivariant edge fluxes);
//! the weak condition instead lets the pressure's curvature across the plane drive a velocity
//! through it. In the octant of the underwater bubble (uniform hexes of R0/3.25) that reached
//! 4 m/s on the axes within 0.12 ms, where the gas moves out at 20-40 m/s.
//!
//! A node on several planes loses the momentum residual along every one of their normals: the
//! normals are orthonormalised (Gram-Schmidt, in patch order; a normal within `1e-6` of the span
//! of the previous ones adds nothing), and the residual is projected onto their orthogonal
//! complement, a line on an axis where two planes meet and zero at a corner of three (not onto an
//! averaged normal, which would leave a normal component along each plane). The planes are those
//! of [`MirrorPlanes`]: nodes of symmetry patches whose in-patch neighbours lie in their dual
//! normal's plane; nodes on curved parts of a symmetry patch keep the weak condition alone.
//! The state itself is not projected: a flow that starts with `u·n = 0` on the planes keeps it
//! exactly, since no stage changes the normal momentum of those nodes.

use crate::mesh::geometry::{dot, norm, scale, sub};
use crate::mesh::Mesh;
use crate::reconstruct::gradient::MirrorPlanes;
use std::ops::{IndexMut, Range};

/// A normal closer than this (relative) to the span of a node's previous normals adds no
/// direction.
const INDEPENDENCE: f64 = 1e-6;

/// The constrained directions of the nodes on symmetry planes (module docs).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SymmetryPlanes {
    /// Nodes with at least one constrained direction, ascending; a node with `k` directions
    /// appears `k` times.
    nodes: Vec<u32>,
    /// Orthonormal across the entries of one node.
    directions: Vec<[f64; 3]>,
}

impl SymmetryPlanes {
    /// The constrained directions of the nodes on the planar parts of the boundaries `patches`
    /// (indices in `mesh.boundaries`).
    pub fn new(mesh: &Mesh, patches: &[usize]) -> SymmetryPlanes {
        let mut planes = SymmetryPlanes::default();
        for (i, normals) in MirrorPlanes::new(mesh, patches).by_node() {
            let mut basis: Vec<[f64; 3]> = Vec::with_capacity(normals.len());
            for &n in normals {
                let v = basis.iter().fold(n, |v, b| sub(v, scale(*b, dot(v, *b))));
                let length = norm(v);
                if length > INDEPENDENCE {
                    basis.push(scale(v, 1.0 / length));
                }
            }
            for b in basis {
                planes.nodes.push(i as u32);
                planes.directions.push(b);
            }
        }
        planes
    }

    /// Number of (node, direction) pairs.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// The orthonormal constrained directions of node `i` (none off the planes).
    pub fn of_node(&self, i: usize) -> &[[f64; 3]] {
        &self.directions[self.entries(&(i..i + 1))]
    }

    /// The number of images of a neighbour at `d = x_j - x_i` of node `i` on the mirrored mesh:
    /// 2 for each constrained direction of `i` that `d` has a component along (beyond `1e-6 |d|`),
    /// so that a mean over the half stencil weighted by it is the mean over the whole mirrored
    /// stencil, as the mirror images of `j` contribute (with perpendicular planes, exactly).
    pub fn images(&self, i: usize, d: [f64; 3]) -> f64 {
        let tol = INDEPENDENCE * norm(d);
        self.of_node(i).iter().filter(|&&n| dot(d, n).abs() > tol).fold(1.0, |w, _| 2.0 * w)
    }

    /// Removes the momentum components `r[i][1..4]` along the constrained directions of every
    /// node `i` in `nodes`.
    #[inline]
    pub fn project(&self, nodes: Range<usize>, r: &mut impl IndexMut<usize, Output = [f64; 5]>) {
        for e in self.entries(&nodes) {
            let ri = &mut r[self.nodes[e] as usize];
            let d = self.directions[e];
            let along = dot([ri[1], ri[2], ri[3]], d);
            for k in 0..3 {
                ri[1 + k] -= along * d[k];
            }
        }
    }

    /// The entries of the nodes in `nodes`.
    fn entries(&self, nodes: &Range<usize>) -> Range<usize> {
        self.nodes.partition_point(|&v| (v as usize) < nodes.start)
            ..self.nodes.partition_point(|&v| (v as usize) < nodes.end)
    }

    /// Memory in bytes.
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(&self.nodes[..]) + std::mem::size_of_val(&self.directions[..])
    }
}

#[cfg(test)]
mod tests;
