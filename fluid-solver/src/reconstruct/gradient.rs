//! Nodal least-squares gradients (thesis §3.3.1 reconstruction; the weighted least-squares
//! gradient of the vertex-centred schemes, e.g. SU2's `WEIGHTED_LEAST_SQUARES`).
//!
//! At node `i`, `∇u_i` minimises `Σ_j w_ij (∇u_i · d_ij - (u_j - u_i))²` over its neighbours
//! through edges, `d_ij = x_j - x_i`, `w_ij = 1/|d_ij|²`, so `∇u_i = M_i⁻¹ Σ_j w_ij d_ij (u_j - u_i)`
//! with `M_i = Σ_j w_ij d_ij d_ijᵀ`. The 3x3 matrices depend on the mesh only: they are inverted
//! once, and each edge stores its two coefficient vectors `c_ij = w_ij M_i⁻¹ d_ij` (for node `i`)
//! and `c_ji = w_ij M_j⁻¹ d_ji` (for node `j`). A gradient is then one gather per node over the
//! node-to-edge CSR, `∇u_i = Σ_e c_e,i (u_j - u_i)`: deterministic, no edge visited twice per node,
//! no matrix built in the time loop.
//!
//! Edge masks: [`LsqGradient::with_mask`] drops edges (edges cut by the embedded structure, or
//! joining different fluids, DESIGN §5); the coefficient vectors of the dropped edges are zero and
//! the matrices of their end nodes are rebuilt from the remaining edges. A node whose remaining
//! neighbours do not span 3D gets a zero gradient (first-order reconstruction there).

use crate::mesh::geometry::{dot, scale, sub};
use crate::mesh::Mesh;
use rayon::prelude::*;

/// Precomputed least-squares gradient operator of a mesh.
#[derive(Debug, Clone)]
pub struct LsqGradient {
    /// Per edge `(i, j)`: `[c_ij, c_ji]`.
    coef: Vec<[[f64; 3]; 2]>,
}

/// Inverse of a symmetric 3x3 matrix, or `None` if it is singular relative to its size.
fn invert_sym3(m: &[[f64; 3]; 3]) -> Option<[[f64; 3]; 3]> {
    let c00 = m[1][1] * m[2][2] - m[1][2] * m[2][1];
    let c01 = m[1][2] * m[2][0] - m[1][0] * m[2][2];
    let c02 = m[1][0] * m[2][1] - m[1][1] * m[2][0];
    let det = m[0][0] * c00 + m[0][1] * c01 + m[0][2] * c02;
    let trace = m[0][0] + m[1][1] + m[2][2];
    if det.abs().partial_cmp(&(1e-10 * trace * trace * trace)).is_none_or(|o| o.is_le()) {
        return None;
    }
    let inv = 1.0 / det;
    let c11 = m[0][0] * m[2][2] - m[0][2] * m[2][0];
    let c12 = m[0][1] * m[2][0] - m[0][0] * m[2][1];
    let c22 = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    Some([
        [c00 * inv, c01 * inv, c02 * inv],
        [c01 * inv, c11 * inv, c12 * inv],
        [c02 * inv, c12 * inv, c22 * inv],
    ])
}

fn mat_vec(m: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    [dot(m[0], v), dot(m[1], v), dot(m[2], v)]
}

impl LsqGradient {
    /// The operator using every edge.
    pub fn new(mesh: &Mesh) -> LsqGradient {
        Self::with_mask(mesh, None)
    }

    /// The operator using only the edges `e` with `mask[e] == true` (all when `None`).
    pub fn with_mask(mesh: &Mesh, mask: Option<&[bool]>) -> LsqGradient {
        let usable = |e: usize| mask.is_none_or(|m| m[e]);
        let d_of = |e: usize| {
            let [i, j] = mesh.edges[e];
            sub(mesh.coords[j as usize], mesh.coords[i as usize])
        };
        let inverses: Vec<Option<[[f64; 3]; 3]>> = (0..mesh.n_nodes())
            .into_par_iter()
            .map(|i| {
                let mut m = [[0.0; 3]; 3];
                for &e in mesh.edges_of(i) {
                    let e = e as usize;
                    if !usable(e) {
                        continue;
                    }
                    let d = d_of(e);
                    let w = 1.0 / dot(d, d);
                    for a in 0..3 {
                        for b in 0..3 {
                            m[a][b] += w * d[a] * d[b];
                        }
                    }
                }
                invert_sym3(&m)
            })
            .collect();
        let coef = (0..mesh.n_edges())
            .into_par_iter()
            .map(|e| {
                if !usable(e) {
                    return [[0.0; 3]; 2];
                }
                let [i, j] = mesh.edges[e];
                let d = d_of(e);
                let w = 1.0 / dot(d, d);
                let side = |node: u32, d: [f64; 3]| {
                    inverses[node as usize].map_or([0.0; 3], |inv| scale(mat_vec(&inv, d), w))
                };
                [side(i, d), side(j, scale(d, -1.0))]
            })
            .collect();
        LsqGradient { coef }
    }

    /// Coefficient vector of edge `e` seen from its end `side` (0: `i`, 1: `j`).
    #[inline(always)]
    pub fn coefficient(&self, e: usize, side: usize) -> [f64; 3] {
        self.coef[e][side]
    }

    /// Gradients of `N`-component nodal fields: `grad[i][k] = ∇ values[i][k]`.
    pub fn compute<const N: usize>(
        &self,
        mesh: &Mesh,
        values: &[[f64; N]],
        grad: &mut [[[f64; 3]; N]],
    ) {
        grad.par_iter_mut().enumerate().with_min_len(256).for_each(|(i, g)| {
            *g = self.node_gradient(mesh, values, i);
        });
    }

    /// Gradient at one node.
    #[inline(always)]
    pub fn node_gradient<const N: usize>(
        &self,
        mesh: &Mesh,
        values: &[[f64; N]],
        i: usize,
    ) -> [[f64; 3]; N] {
        let mut g = [[0.0; 3]; N];
        let ui = values[i];
        for &e in mesh.edges_of(i) {
            let e = e as usize;
            let [a, b] = mesh.edges[e];
            let (side, j) = if a as usize == i { (0, b) } else { (1, a) };
            let c = self.coef[e][side];
            let uj = &values[j as usize];
            for k in 0..N {
                let du = uj[k] - ui[k];
                g[k][0] += c[0] * du;
                g[k][1] += c[1] * du;
                g[k][2] += c[2] * du;
            }
        }
        g
    }

    /// Memory in bytes.
    pub fn memory_bytes(&self) -> usize {
        self.coef.len() * std::mem::size_of::<[[f64; 3]; 2]>()
    }
}
