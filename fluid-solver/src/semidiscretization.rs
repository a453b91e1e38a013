//! The residual of the semi-discrete Euler equations (thesis Eq. 3.6-3.7):
//! `|C_i| dW_i/dt + R_i(W) = 0`, `R_i = Σ_{j ∈ K(i)} F_ij(W_ij, W_ji, EOS, ν_ij) + Σ_b F_b(W_i, n_i)`.
//!
//! Evaluated in a deterministic two-pass form, so the result is bitwise the same for any number
//! of threads:
//! 1. per edge (rayon over blocks of consecutive edges, sorted by `(i, j)` so the gathers of a
//!    block touch nearby nodes): MUSCL states at the edge midpoint from the nodal least-squares
//!    gradients of the primitive variables, limited ([`crate::reconstruct`]), then the numerical
//!    flux into the edge buffer;
//! 2. per node (rayon over nodes): the sum of the fluxes of its edges in ascending edge order over
//!    the node-to-edge CSR (`+F` where the node is `i`, `-F` where it is `j`), then the boundary
//!    fluxes of its boundary facets, patch by patch in a fixed order.
//!
//! Extension points:
//! - Embedded boundary (thesis Ch. 4-5): a cut edge gets two one-sided fluxes (Alg. 5.1 for each
//!   active end node). Pass 1 then writes `F_ij` for node `i` into `edge_flux` and `F_ji` for node
//!   `j` into a per-cut-edge side buffer indexed by the edge; pass 2 reads that buffer for `j` on
//!   cut edges. Inactive nodes are masked in pass 2 (zero residual, state frozen), and the gradient
//!   operator is rebuilt with the cut edges masked out ([`LsqGradient::with_mask`]).
//! - Two-phase (thesis Ch. 3): a per-node material id selects the EOS of each end; an edge whose
//!   ends hold different fluids takes [`crate::flux::two_phase_flux`] (again two one-sided fluxes,
//!   stored as for cut edges); the level set is one more nodal array advected by the same loop.
//! - MPI (DESIGN §10): with owned nodes first and ghosts after, pass 1 runs over edges touching an
//!   owned node, pass 2 over owned nodes only, and a ghost exchange precedes each stage.

use crate::bc::BoundaryCondition;
use crate::eos::{Eos, StateError};
use crate::flux::{numerical_flux, FluxScheme};
use crate::mesh::geometry::{dot, norm, sub};
use crate::mesh::{Mesh, MeshError};
use crate::reconstruct::gradient::LsqGradient;
use crate::reconstruct::limiter::Limiter;
use crate::reconstruct::muscl;
use crate::riemann::RiemannError;
use crate::state::Workspace;
use rayon::prelude::*;

/// Edges per parallel block of pass 1.
const EDGE_BLOCK: usize = 2048;
/// Nodes per parallel block of pass 2.
const NODE_BLOCK: usize = 1024;

/// Spatial scheme settings.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Numerics {
    pub flux: FluxScheme,
    /// MUSCL slope limiter; [`Limiter::FirstOrder`] gives the first-order scheme (no gradients).
    pub limiter: Limiter,
}

impl Numerics {
    /// True when the scheme needs nodal gradients.
    pub fn second_order(&self) -> bool {
        self.limiter != Limiter::FirstOrder
    }
}

/// A failure of a residual evaluation, naming the node.
#[derive(Debug, Clone, thiserror::Error)]
pub enum FluidError {
    #[error("invalid fluid state at node {node} (x = {position:?}): {error}; primitive [ρ, u, v, w, p] = {prim:?}")]
    InvalidState { node: usize, position: [f64; 3], prim: [f64; 5], error: StateError },
    #[error("boundary `{boundary}` at node {node} (x = {position:?}): {error}")]
    Boundary { boundary: String, node: usize, position: [f64; 3], error: RiemannError },
}

/// The spatial operator: mesh, EOS, scheme, gradient operator and boundary conditions.
#[derive(Debug, Clone)]
pub struct Semidiscretization {
    pub mesh: Mesh,
    pub eos: Eos,
    pub numerics: Numerics,
    pub gradient: LsqGradient,
    /// `(index in mesh.boundaries, condition)`, applied in this order.
    pub patches: Vec<(usize, BoundaryCondition)>,
}

impl Semidiscretization {
    /// Builds the operator; every boundary of the mesh needs a condition, given by name.
    pub fn new(
        mesh: Mesh,
        eos: Eos,
        numerics: Numerics,
        conditions: &[(String, BoundaryCondition)],
    ) -> Result<Semidiscretization, MeshError> {
        let mut patches = Vec::new();
        for (name, bc) in conditions {
            let index = mesh.boundaries.iter().position(|b| &b.name == name).ok_or_else(|| {
                MeshError::UnknownBoundary {
                    name: name.clone(),
                    known: mesh.boundary_names().join(", "),
                }
            })?;
            patches.push((index, *bc));
        }
        for (k, b) in mesh.boundaries.iter().enumerate() {
            if !b.nodes.is_empty() && !patches.iter().any(|p| p.0 == k) {
                return Err(MeshError::Input(format!(
                    "boundary `{}` has no boundary condition; give one for each of: {}",
                    b.name,
                    mesh.boundary_names().join(", ")
                )));
            }
        }
        let gradient = LsqGradient::new(&mesh);
        Ok(Semidiscretization { mesh, eos, numerics, gradient, patches })
    }

    /// Primitive variables of every node into `ws.prim`, checked against the EOS.
    pub fn primitives(&self, cons: &[[f64; 5]], ws: &mut Workspace) -> Result<(), FluidError> {
        let eos = self.eos;
        ws.prim.par_iter_mut().zip(cons.par_iter()).with_min_len(NODE_BLOCK).for_each(|(w, q)| {
            *w = eos.cons_to_prim(q);
        });
        if let Some(node) = ws.prim.par_iter().position_first(|w| eos.check(w).is_err()) {
            let prim = ws.prim[node];
            let error = eos.check(&prim).expect_err("found invalid above");
            return Err(FluidError::InvalidState {
                node,
                position: self.mesh.coords[node],
                prim,
                error,
            });
        }
        Ok(())
    }

    /// The residual `R(W)` into `ws.residual` (see the module docs).
    pub fn residual(&self, cons: &[[f64; 5]], ws: &mut Workspace) -> Result<(), FluidError> {
        self.primitives(cons, ws)?;
        self.residual_from_primitives(ws)
    }

    /// The residual from the primitive variables already in `ws.prim`.
    pub fn residual_from_primitives(&self, ws: &mut Workspace) -> Result<(), FluidError> {
        let mesh = &self.mesh;
        let eos = self.eos;
        let numerics = self.numerics;
        let second_order = numerics.second_order();
        if second_order {
            self.gradient.compute(mesh, &ws.prim, &mut ws.grad);
        }
        // Pass 1: edge fluxes.
        let prim = &ws.prim;
        let grad = &ws.grad;
        ws.edge_flux.par_chunks_mut(EDGE_BLOCK).enumerate().for_each(|(b, block)| {
            let first = b * EDGE_BLOCK;
            for (k, f) in block.iter_mut().enumerate() {
                let e = first + k;
                let [i, j] = mesh.edges[e];
                let (i, j) = (i as usize, j as usize);
                let n = &mesh.edge_normals[e];
                *f = if second_order {
                    let d = sub(mesh.coords[j], mesh.coords[i]);
                    let (wl, wr) = muscl::reconstruct(
                        numerics.limiter,
                        &eos,
                        &prim[i],
                        &grad[i],
                        &eos,
                        &prim[j],
                        &grad[j],
                        &d,
                    );
                    numerical_flux(numerics.flux, &eos, &wl, &wr, n)
                } else {
                    numerical_flux(numerics.flux, &eos, &prim[i], &prim[j], n)
                };
            }
        });
        // Pass 2: per-node gather in ascending edge order.
        let edge_flux = &ws.edge_flux;
        ws.residual.par_iter_mut().enumerate().with_min_len(NODE_BLOCK).for_each(|(i, r)| {
            let mut s = [0.0; 5];
            for &e in mesh.edges_of(i) {
                let f = &edge_flux[e as usize];
                if mesh.edges[e as usize][0] as usize == i {
                    for k in 0..5 {
                        s[k] += f[k];
                    }
                } else {
                    for k in 0..5 {
                        s[k] -= f[k];
                    }
                }
            }
            *r = s;
        });
        self.add_boundary_fluxes(&ws.prim, &mut ws.residual)
    }

    /// Adds the boundary fluxes, patch by patch (sequential: a fixed order, few nodes).
    fn add_boundary_fluxes(
        &self,
        prim: &[[f64; 5]],
        residual: &mut [[f64; 5]],
    ) -> Result<(), FluidError> {
        for &(b, bc) in &self.patches {
            let boundary = &self.mesh.boundaries[b];
            for (&node, n) in boundary.nodes.iter().zip(&boundary.normals) {
                let node = node as usize;
                let f =
                    bc.flux(self.numerics.flux, &self.eos, &prim[node], n).map_err(|error| {
                        FluidError::Boundary {
                            boundary: boundary.name.clone(),
                            node,
                            position: self.mesh.coords[node],
                            error,
                        }
                    })?;
                for k in 0..5 {
                    residual[node][k] += f[k];
                }
            }
        }
        Ok(())
    }

    /// Time-step limit of each node for CFL 1 into `ws.dt_node`, from `ws.prim`:
    /// `2 |C_i| / (Σ_edges (|u_i·ν| + c_i|ν|) + Σ_boundary (|u_i·n| + c_i|n|))`. The factor 2 makes
    /// CFL the Courant number `(|u| + c) Δt / Δx` on a 1D grid (each direction's flux enters
    /// through two facets); on 3D grids the sum over all facets makes the same CFL about 1/3 of
    /// that per direction, and on one-cell-thick tubes the lateral and symmetry facets (which carry
    /// no waves) make it smaller still.
    pub fn node_time_steps(&self, ws: &mut Workspace) {
        let mesh = &self.mesh;
        let eos = self.eos;
        let prim = &ws.prim;
        ws.dt_node.par_iter_mut().enumerate().with_min_len(NODE_BLOCK).for_each(|(i, dt)| {
            let w = &prim[i];
            let u = [w[1], w[2], w[3]];
            let c = eos.sound_speed(w[0], w[4]);
            let mut lambda = 0.0;
            for &e in mesh.edges_of(i) {
                let n = mesh.edge_normals[e as usize];
                lambda += dot(u, n).abs() + c * norm(n);
            }
            *dt = 2.0 * mesh.volumes[i] / lambda;
        });
        for b in &mesh.boundaries {
            for (&node, n) in b.nodes.iter().zip(&b.normals) {
                let i = node as usize;
                let w = &prim[i];
                let c = eos.sound_speed(w[0], w[4]);
                let extra = dot([w[1], w[2], w[3]], *n).abs() + c * norm(*n);
                // dt = 2V / λ  ->  2V / (λ + extra).
                let lambda = 2.0 * mesh.volumes[i] / ws.dt_node[i];
                ws.dt_node[i] = 2.0 * mesh.volumes[i] / (lambda + extra);
            }
        }
    }

    /// `Σ_i R_i` and the total boundary flux `Σ_b F_b`, for conservation checks.
    pub fn boundary_flux_total(&self, prim: &[[f64; 5]]) -> Result<[f64; 5], FluidError> {
        let mut total = vec![[0.0; 5]; prim.len()];
        self.add_boundary_fluxes(prim, &mut total)?;
        let mut s = [0.0; 5];
        for r in &total {
            for k in 0..5 {
                s[k] += r[k];
            }
        }
        Ok(s)
    }
}
