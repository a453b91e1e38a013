//! The residual of the semi-discrete Euler equations (thesis Eq. 3.6-3.7):
//! `|C_i| dW_i/dt + R_i(W) = 0`, `R_i = Σ_{j ∈ K(i)} F_ij(W_ij, W_ji, EOS, ν_ij) + Σ_b F_b(W_i, n_i)`.
//!
//! Evaluated in one deterministic pass over the edges, in the blocks of [`crate::mesh::EdgeBlocks`]
//! (even blocks in parallel, then odd blocks): per edge, the MUSCL states at the edge midpoint from
//! the nodal least-squares gradients of the primitive variables, limited ([`crate::reconstruct`];
//! mirror-symmetric at the nodes on symmetry planes and plane slip walls,
//! [`crate::reconstruct::gradient`]), then the numerical flux, added at once to `R_i` (`+F`) and
//! `R_j` (`-F`); per block, the boundary fluxes of its nodes, patch by patch in a fixed order, and
//! at the nodes on symmetry planes the momentum residual along their normals removed
//! ([`crate::symmetry`]).
//! Every node hears from its edges in an order fixed by the mesh, so the result is bitwise the same
//! for any number of threads, and no per-edge flux buffer or gather pass is needed. A node's
//! residual is complete inside the same pass, so the time integrator applies its update there
//! ([`Semidiscretization::residual_and_update`]) while the node is still in cache.
//!
//! Materials (thesis Ch. 3, DESIGN §5.1): the operator holds the EOS table and is built for a
//! material layout, the material id of every node ([`Semidiscretization::with_materials`]; the
//! state holds the same ids). A run of one material (the same id at every node) runs the loop
//! specialised for its EOS, limiter and flux over whole blocks. Otherwise each block runs the
//! ordinary loop over the gaps between its special edges ([`crate::special_edges`]) with each
//! edge's EOS looked up from the table, then its special edges: an edge whose ends hold different
//! fluids takes the two-phase ghost-fluid flux ([`crate::two_phase`]). The least-squares
//! gradients then use only neighbours of the same fluid (the two-material edges masked out).
//!
//! Extension points:
//! - Embedded boundary (thesis Ch. 4-5): a cut edge gets two one-sided fluxes (Alg. 5.1 for each
//!   active end node): the edge loop adds `F_ij` to `R_i` and `F_ji` to `R_j`. Inactive nodes are
//!   masked when their residual completes (zero residual, state frozen), and the gradient
//!   operator is rebuilt with the cut edges masked out and the same mirror planes
//!   ([`LsqGradient::with_planes`]).
//! - Moving interfaces: a level set (one more nodal array advected by the same loop) changes node
//!   materials between steps; the layout is then rebuilt ([`Semidiscretization::set_materials`]:
//!   one pass over the edges for the special-edge lists, and the masked gradient operator).
//! - MPI (DESIGN §10): with owned nodes first and ghosts after, the edge loop runs over edges
//!   touching an owned node, the update over owned nodes only, and a ghost exchange precedes each
//!   stage.

pub use crate::error::FluidError;

use crate::bc::BoundaryCondition;
use crate::embedded::step::Wall;
use crate::eos::Eos;
use crate::flux::{numerical_flux, FluxScheme};
use crate::mesh::blocks::Window;
use crate::mesh::geometry::{dot, sub};
use crate::mesh::{Mesh, MeshError};
use crate::reconstruct::gradient::{LsqGradient, MirrorPlanes};
use crate::reconstruct::limiter::Limiter;
use crate::reconstruct::muscl;
use crate::special_edges::{SpecialEdges, SpecialKind};
use crate::state::{MaterialId, Workspace};
use crate::symmetry::SymmetryPlanes;
use rayon::prelude::*;
use std::ops::Range;

/// Nodes per parallel block of the node loops.
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

/// The spatial operator: mesh, EOS table, material layout, scheme, gradient operator and
/// boundary conditions.
#[derive(Debug, Clone)]
pub struct Semidiscretization {
    pub mesh: Mesh,
    /// The EOS table: material id `m` has the EOS `eos[m]`.
    pub eos: Vec<Eos>,
    /// The material id of every node (the layout the operator is built for).
    material: Vec<MaterialId>,
    /// The one material of every node, if there is one.
    uniform: Option<MaterialId>,
    /// Per edge block, its special edges (here the two-material edges).
    special: SpecialEdges,
    pub numerics: Numerics,
    /// Least-squares gradients (with mirror planes; two-material edges masked out).
    pub gradient: LsqGradient,
    /// `(index in mesh.boundaries, condition)`, applied in this order.
    pub patches: Vec<(usize, BoundaryCondition)>,
    /// The normals of the symmetry planes, along which no node on them has a momentum residual
    /// ([`crate::symmetry`]).
    pub symmetry: SymmetryPlanes,
    /// The interface normals of a level set, if one moves the materials: the two-phase problems
    /// of the edges between two fluids are then solved along them ([`crate::two_phase`]).
    pub interface: Option<InterfaceNormals>,
}

/// The gradient of a level set at every node (at the start of the step), and the material on the
/// side it points to.
#[derive(Debug, Clone, PartialEq)]
pub struct InterfaceNormals {
    pub grad_phi: Vec<[f64; 3]>,
    pub toward: MaterialId,
}

impl Semidiscretization {
    /// The operator of one fluid: every node material 0 of the table `[eos]`; every boundary of
    /// the mesh needs a condition, given by name.
    pub fn new(
        mesh: Mesh,
        eos: Eos,
        numerics: Numerics,
        conditions: &[(String, BoundaryCondition)],
    ) -> Result<Semidiscretization, MeshError> {
        let material = vec![0; mesh.n_nodes()];
        Self::with_materials(mesh, vec![eos], material, numerics, conditions)
    }

    /// The operator of the EOS table `eos` for the node materials `material` (ids into `eos`,
    /// one per node); every boundary of the mesh needs a condition, given by name.
    pub fn with_materials(
        mesh: Mesh,
        eos: Vec<Eos>,
        material: Vec<MaterialId>,
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
        // Symmetry planes and plane slip walls: mirror-symmetric gradients there.
        let mirrors: Vec<usize> = patches
            .iter()
            .filter(|p| matches!(p.1, BoundaryCondition::Symmetry | BoundaryCondition::SlipWall))
            .map(|p| p.0)
            .collect();
        let planes = MirrorPlanes::new(&mesh, &mirrors);
        if eos.is_empty() {
            return Err(MeshError::Input("the EOS table is empty: give at least one fluid".into()));
        }
        let gradient = LsqGradient::with_planes(&mesh, None, planes);
        let symmetric: Vec<usize> = patches
            .iter()
            .filter(|p| matches!(p.1, BoundaryCondition::Symmetry))
            .map(|p| p.0)
            .collect();
        let symmetry = SymmetryPlanes::new(&mesh, &symmetric);
        let mut semi = Semidiscretization {
            mesh,
            eos,
            material: Vec::new(),
            uniform: None,
            special: SpecialEdges::none(),
            numerics,
            gradient,
            patches,
            symmetry,
            interface: None,
        };
        semi.set_materials(material)?;
        Ok(semi)
    }

    /// Rebuilds the material layout for the node materials `material`: the special-edge lists
    /// (one pass over the edges) and, when more than one material is present, the gradient
    /// operator with the two-material edges masked out (same mirror planes).
    pub fn set_materials(&mut self, material: Vec<MaterialId>) -> Result<(), MeshError> {
        let n = self.mesh.n_nodes();
        if material.len() != n {
            return Err(MeshError::Input(format!(
                "{} material ids for a mesh of {n} nodes",
                material.len()
            )));
        }
        if let Some(i) = material.iter().position(|&m| m as usize >= self.eos.len()) {
            return Err(MeshError::Input(format!(
                "node {i} (x = {:?}) has material {}, but the EOS table has {} fluids",
                self.mesh.coords[i],
                material[i],
                self.eos.len()
            )));
        }
        let first = material.first().copied().unwrap_or(0);
        let uniform = material.iter().all(|&m| m == first).then_some(first);
        let was_masked = self.uniform.is_none() && !self.material.is_empty();
        self.special = match uniform {
            Some(_) => SpecialEdges::none(),
            None => SpecialEdges::two_material(&self.mesh, &material),
        };
        if uniform.is_none() || was_masked {
            let mask: Option<Vec<bool>> = uniform.is_none().then(|| {
                let m = &material;
                self.mesh.edges.iter().map(|&[i, j]| m[i as usize] == m[j as usize]).collect()
            });
            let planes = self.gradient.planes().clone();
            self.gradient = LsqGradient::with_planes(&self.mesh, mask.as_deref(), planes);
        }
        self.material = material;
        self.uniform = uniform;
        Ok(())
    }

    /// The material id of every node.
    pub fn material(&self) -> &[MaterialId] {
        &self.material
    }

    /// The special edges of every edge block.
    pub fn special_edges(&self) -> &SpecialEdges {
        &self.special
    }

    /// The EOS of node `i`.
    #[inline(always)]
    pub fn eos_at(&self, i: usize) -> &Eos {
        &self.eos[self.material[i] as usize]
    }

    /// The EOS of every node when all hold one material.
    #[inline]
    pub fn uniform_eos(&self) -> Option<Eos> {
        self.uniform.map(|m| self.eos[m as usize])
    }

    /// Primitive variables of every node into `ws.prim`, each checked against its node's EOS.
    pub fn primitives(&self, cons: &[[f64; 5]], ws: &mut Workspace) -> Result<(), FluidError> {
        match self.uniform_eos() {
            Some(eos) => self.primitives_with(cons, ws, |_| eos),
            None => self.primitives_with(cons, ws, |i| *self.eos_at(i)),
        }
    }

    #[inline(always)]
    fn primitives_with(
        &self,
        cons: &[[f64; 5]],
        ws: &mut Workspace,
        eos_of: impl Fn(usize) -> Eos + Sync,
    ) -> Result<(), FluidError> {
        let first_bad = ws
            .prim
            .par_chunks_mut(NODE_BLOCK)
            .zip(cons.par_chunks(NODE_BLOCK))
            .enumerate()
            .filter_map(|(b, (prim, cons))| {
                let mut bad = None;
                for (k, (w, q)) in prim.iter_mut().zip(cons).enumerate() {
                    let eos = eos_of(b * NODE_BLOCK + k);
                    *w = eos.cons_to_prim(q);
                    if bad.is_none() && eos.check(w).is_err() {
                        bad = Some(b * NODE_BLOCK + k);
                    }
                }
                bad
            })
            .min();
        if let Some(node) = first_bad {
            let prim = ws.prim[node];
            let error = eos_of(node).check(&prim).expect_err("found invalid above");
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
        let mut none = vec![(); self.mesh.n_nodes()];
        self.residual_and_update(ws, &mut none, |_, _, _| {})
    }

    /// The residual from `ws.prim` into `ws.residual`, calling `update(i, R_i, &mut out[i])` for
    /// every node as soon as its residual is complete (within the same pass over the edges, in
    /// parallel). On error `out` may be partly updated.
    pub fn residual_and_update<U: Send>(
        &self,
        ws: &mut Workspace,
        out: &mut [U],
        update: impl Fn(usize, &[f64; 5], &mut U) + Sync,
    ) -> Result<(), FluidError> {
        self.residual_and_update_with(ws, out, update, None)
    }

    /// [`Semidiscretization::residual_and_update`] with an embedded boundary at a stage time
    /// (thesis Ch. 4-5): its cut and frozen edges join the special edges of every block, and the
    /// gradients skip them ([`crate::embedded::step`]). Nodes that are not active get a residual
    /// too (from the edges they share with active nodes' blocks); the caller freezes them.
    pub fn residual_and_update_with<U: Send>(
        &self,
        ws: &mut Workspace,
        out: &mut [U],
        update: impl Fn(usize, &[f64; 5], &mut U) + Sync,
        wall: Option<Wall<'_>>,
    ) -> Result<(), FluidError> {
        let mesh = &self.mesh;
        if self.numerics.second_order() {
            let gradient = wall.map_or(&self.gradient, |w| &w.step.gradient);
            gradient.compute(mesh, &ws.prim, &mut ws.grad);
        }
        let Workspace { prim, grad, residual, .. } = ws;
        let (prim, grad) = (&prim[..], &grad[..]);
        let blocks = &mesh.blocks;
        blocks.scatter2(residual, out, |b, r, o| {
            for i in blocks.fresh(b) {
                r[i] = [0.0; 5];
            }
            self.block_fluxes(b, prim, grad, r, wall.as_ref())?;
            self.boundary_fluxes(blocks.nodes(b), prim, r)?;
            self.symmetry.project(blocks.completed(b), r);
            for i in blocks.completed(b) {
                update(i, &r[i], &mut o[i]);
            }
            Ok(())
        })
    }

    /// Only the edge part of the residual, `Σ_j F_ij` without boundary fluxes, from `ws.prim` and
    /// the gradients already in `ws.grad` (the hot loop alone, for benchmarks and for checking the
    /// C reference loop of `fluid-solver/bench/`; special edges included).
    pub fn edge_residual(&self, ws: &mut Workspace) -> Result<(), FluidError> {
        let Workspace { prim, grad, residual, .. } = ws;
        let (prim, grad) = (&prim[..], &grad[..]);
        let blocks = &self.mesh.blocks;
        blocks.scatter(residual, |b, r| {
            for i in blocks.fresh(b) {
                r[i] = [0.0; 5];
            }
            self.block_fluxes(b, prim, grad, r, None)
        })
    }

    /// Adds the fluxes of the edges of block `b`: with one material, the specialised loop over
    /// the whole block; otherwise the ordinary loop over the gaps between the block's special
    /// edges, then the special edges.
    #[inline]
    fn block_fluxes(
        &self,
        b: usize,
        prim: &[[f64; 5]],
        grad: &[[[f64; 3]; 5]],
        r: &mut Window<'_, [f64; 5]>,
        wall: Option<&Wall<'_>>,
    ) -> Result<(), FluidError> {
        let edges = self.mesh.blocks.edges(b);
        let special = wall.map_or(&self.special, |w| w.step.special());
        let uniform = self.uniform_eos();
        if let (Some(eos), true) = (uniform, special.block(b).is_empty()) {
            self.edge_fluxes(eos, edges, prim, grad, r);
            return Ok(());
        }
        let (table, material) = (&self.eos[..], &self.material[..]);
        let limiter = self.numerics.limiter;
        for gap in special.gaps(b, edges) {
            match uniform {
                Some(eos) => self.edge_fluxes(eos, gap, prim, grad, r),
                None => {
                    self.edge_loop(|i| table[material[i] as usize], limiter, gap, prim, grad, r)
                }
            }
        }
        // The special edges of a block with a wall are timed as one (their wall fluxes).
        let start = wall.map(|_| std::time::Instant::now());
        for &s in special.block(b) {
            match (s.kind, wall) {
                (SpecialKind::TwoMaterial, _) => {
                    crate::two_phase::edge_flux(self, s.edge as usize, prim, r)?
                }
                (SpecialKind::Dead, _) => {}
                (_, Some(w)) => w.edge_flux(self, s, prim, grad, r)?,
                (_, None) => unreachable!("cut and frozen edges come with their wall"),
            }
        }
        if let (Some(w), Some(start)) = (wall, start) {
            w.step.wall_flux_clock.add(start.elapsed());
        }
        Ok(())
    }

    /// Adds the fluxes of `edges` to the residuals of their end nodes, with the scheme's limiter,
    /// flux and the one EOS fixed outside the edge loop (so each combination is its own tight
    /// loop).
    fn edge_fluxes(
        &self,
        eos: Eos,
        edges: Range<usize>,
        prim: &[[f64; 5]],
        grad: &[[[f64; 3]; 5]],
        r: &mut Window<'_, [f64; 5]>,
    ) {
        let limiter = self.numerics.limiter;
        match eos {
            Eos::PerfectGas { gamma } => {
                self.edge_loop(|_| Eos::PerfectGas { gamma }, limiter, edges, prim, grad, r)
            }
            Eos::StiffenedGas { gamma, p_c } => {
                self.edge_loop(|_| Eos::StiffenedGas { gamma, p_c }, limiter, edges, prim, grad, r)
            }
            Eos::Tait { p0, rho0, alpha, beta } => self.edge_loop(
                |_| Eos::Tait { p0, rho0, alpha, beta },
                limiter,
                edges,
                prim,
                grad,
                r,
            ),
        }
    }

    /// The loop of the scheme's flux and limiter; `eos_of(i)` is the EOS of an edge whose first
    /// node is `i` (both ends share it).
    #[inline(always)]
    fn edge_loop(
        &self,
        eos: impl Fn(usize) -> Eos + Copy,
        limiter: Limiter,
        edges: Range<usize>,
        prim: &[[f64; 5]],
        grad: &[[[f64; 3]; 5]],
        r: &mut Window<'_, [f64; 5]>,
    ) {
        match (self.numerics.flux, limiter) {
            (FluxScheme::Roe, Limiter::FirstOrder) => {
                self.edge_loop_with(eos, Limiter::FirstOrder, FluxScheme::Roe, edges, prim, grad, r)
            }
            (FluxScheme::Roe, Limiter::Unlimited) => {
                self.edge_loop_with(eos, Limiter::Unlimited, FluxScheme::Roe, edges, prim, grad, r)
            }
            (FluxScheme::Roe, Limiter::Minmod) => {
                self.edge_loop_with(eos, Limiter::Minmod, FluxScheme::Roe, edges, prim, grad, r)
            }
            (FluxScheme::Roe, Limiter::VanAlbada) => {
                self.edge_loop_with(eos, Limiter::VanAlbada, FluxScheme::Roe, edges, prim, grad, r)
            }
            (FluxScheme::Hllc, Limiter::FirstOrder) => self.edge_loop_with(
                eos,
                Limiter::FirstOrder,
                FluxScheme::Hllc,
                edges,
                prim,
                grad,
                r,
            ),
            (FluxScheme::Hllc, Limiter::Unlimited) => {
                self.edge_loop_with(eos, Limiter::Unlimited, FluxScheme::Hllc, edges, prim, grad, r)
            }
            (FluxScheme::Hllc, Limiter::Minmod) => {
                self.edge_loop_with(eos, Limiter::Minmod, FluxScheme::Hllc, edges, prim, grad, r)
            }
            (FluxScheme::Hllc, Limiter::VanAlbada) => {
                self.edge_loop_with(eos, Limiter::VanAlbada, FluxScheme::Hllc, edges, prim, grad, r)
            }
        }
    }

    /// The edge loop of one scheme: MUSCL states, flux, `R_i += F`, `R_j -= F`.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn edge_loop_with(
        &self,
        eos_of: impl Fn(usize) -> Eos,
        limiter: Limiter,
        flux: FluxScheme,
        edges: Range<usize>,
        prim: &[[f64; 5]],
        grad: &[[[f64; 3]; 5]],
        r: &mut Window<'_, [f64; 5]>,
    ) {
        let mesh = &self.mesh;
        for e in edges {
            let [i, j] = mesh.edges[e];
            let (i, j) = (i as usize, j as usize);
            let n = &mesh.edge_normals[e];
            let eos = eos_of(i);
            let f = if limiter == Limiter::FirstOrder {
                numerical_flux(flux, &eos, &prim[i], &prim[j], n)
            } else {
                let d = sub(mesh.coords[j], mesh.coords[i]);
                let (wl, wr) = muscl::reconstruct(
                    limiter, &eos, &prim[i], &grad[i], &eos, &prim[j], &grad[j], &d,
                );
                numerical_flux(flux, &eos, &wl, &wr, n)
            };
            for k in 0..5 {
                r[i][k] += f[k];
            }
            for k in 0..5 {
                r[j][k] -= f[k];
            }
        }
    }

    /// Adds the boundary fluxes of the boundary nodes in `nodes`, patch by patch.
    fn boundary_fluxes(
        &self,
        nodes: Range<usize>,
        prim: &[[f64; 5]],
        r: &mut Window<'_, [f64; 5]>,
    ) -> Result<(), FluidError> {
        for &(b, bc) in &self.patches {
            let boundary = &self.mesh.boundaries[b];
            for k in node_range(&boundary.nodes, &nodes) {
                let node = boundary.nodes[k] as usize;
                let f = self.boundary_flux(b, bc, k, prim)?;
                for c in 0..5 {
                    r[node][c] += f[c];
                }
            }
        }
        Ok(())
    }

    /// The flux of condition `bc` at the `k`-th node of boundary `b`.
    #[inline]
    fn boundary_flux(
        &self,
        b: usize,
        bc: BoundaryCondition,
        k: usize,
        prim: &[[f64; 5]],
    ) -> Result<[f64; 5], FluidError> {
        let boundary = &self.mesh.boundaries[b];
        let node = boundary.nodes[k] as usize;
        bc.flux(self.numerics.flux, self.eos_at(node), &prim[node], &boundary.normals[k]).map_err(
            |error| FluidError::Boundary {
                boundary: boundary.name.clone(),
                node,
                position: self.mesh.coords[node],
                error,
            },
        )
    }

    /// Time-step limit of each node for CFL 1 into `ws.dt_node`, from `ws.prim`:
    /// `2 |C_i| / (Σ_edges (|u_i·ν| + c_i|ν|) + Σ_boundary (|u_i·n| + c_i|n|))`. The factor 2 makes
    /// CFL the Courant number `(|u| + c) Δt / Δx` on a 1D grid (each direction's flux enters
    /// through two facets); on 3D grids the sum over all facets makes the same CFL about 1/3 of
    /// that per direction, and on one-cell-thick tubes the lateral and symmetry facets (which carry
    /// no waves) make it smaller still. The sound speed term is `c_i` times the dual cell's area
    /// ([`Mesh::dual_areas`]); the convective sums take one pass over the edge blocks, like the
    /// residual.
    pub fn node_time_steps(&self, ws: &mut Workspace) {
        let mesh = &self.mesh;
        let prim = &ws.prim[..];
        let blocks = &mesh.blocks;
        let u_dot = |w: &[f64; 5], n: &[f64; 3]| dot([w[1], w[2], w[3]], *n).abs();
        let result = blocks.scatter(&mut ws.dt_node, |b, lambda| {
            for i in blocks.fresh(b) {
                lambda[i] = 0.0;
            }
            for e in blocks.edges(b) {
                let [i, j] = mesh.edges[e];
                let (i, j) = (i as usize, j as usize);
                let n = &mesh.edge_normals[e];
                lambda[i] += u_dot(&prim[i], n);
                lambda[j] += u_dot(&prim[j], n);
            }
            for boundary in &mesh.boundaries {
                for k in node_range(&boundary.nodes, &blocks.nodes(b)) {
                    let i = boundary.nodes[k] as usize;
                    lambda[i] += u_dot(&prim[i], &boundary.normals[k]);
                }
            }
            for i in blocks.completed(b) {
                let w = &prim[i];
                let c = self.eos_at(i).sound_speed(w[0], w[4]);
                lambda[i] = 2.0 * mesh.volumes[i] / (lambda[i] + c * mesh.dual_areas[i]);
            }
            Ok::<(), std::convert::Infallible>(())
        });
        let Ok(()) = result;
    }

    /// The mass leaving through the domain's boundary per unit time from the states `prim`: the
    /// mass component of the boundary fluxes, summed over the boundary nodes `i` with
    /// `include(i)` (an embedded run's active nodes).
    pub fn boundary_mass_outflow(
        &self,
        prim: &[[f64; 5]],
        include: impl Fn(usize) -> bool,
    ) -> Result<f64, FluidError> {
        let mut total = 0.0;
        for &(b, bc) in &self.patches {
            let boundary = &self.mesh.boundaries[b];
            for k in 0..boundary.nodes.len() {
                if include(boundary.nodes[k] as usize) {
                    total += self.boundary_flux(b, bc, k, prim)?[0];
                }
            }
        }
        Ok(total)
    }

    /// `Σ_i R_i` and the total boundary flux `Σ_b F_b`, for conservation checks.
    pub fn boundary_flux_total(&self, prim: &[[f64; 5]]) -> Result<[f64; 5], FluidError> {
        let mut total = vec![[0.0; 5]; prim.len()];
        let nodes = 0..prim.len();
        self.boundary_fluxes(nodes.clone(), prim, &mut Window::new(nodes.start, &mut total))?;
        let mut s = [0.0; 5];
        for r in &total {
            for k in 0..5 {
                s[k] += r[k];
            }
        }
        Ok(s)
    }
}

/// The positions in the ascending node list `list` of the nodes in `nodes`.
fn node_range(list: &[u32], nodes: &Range<usize>) -> Range<usize> {
    list.partition_point(|&v| (v as usize) < nodes.start)
        ..list.partition_point(|&v| (v as usize) < nodes.end)
}
