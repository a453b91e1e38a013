//! Thesis Alg. 5.1 at the cut edges (Eq. 5.2-5.8, DESIGN §5 and §5.1 "Signs and sides"): for
//! each cut edge and each of its end nodes that is an active fluid node, the one-sided
//! fluid-structure Riemann problem along the wall normal oriented from that node, with the node's
//! own EOS and cavitation cut-off, gives the wall state `W* = (ρ*, w_n n + v_i - (v_i·n) n, p*)`
//! and the flux `F(W_i, W*, EOS_i, ±ν_ij)` through the scheme of the ordinary edges. That is the
//! thesis' first-order form (`interface = "first_order"`); the default second-order form
//! ([`interface`], after Main, Zeng, Avery & Farhat 2017) solves the problem at the intersection
//! point from the node state reconstructed there and takes the flux from states on the line
//! through the star state, evaluated at the facet.
//!
//! Signs: the ordinary loop adds `F_ij` to `R_i` and subtracts it from `R_j`. Here each end gets
//! the flux *leaving its own dual cell*: node `i` through `+ν_ij`, node `j` through `-ν_ij`, and
//! both are **added** (`R_i += F_i`, `R_j += F_j`). The wall normal of `j` is minus that of `i`.
//! The `p*` of each side is kept per cut edge for the loads (Alg. 5.3, 5.4).

use super::{CutEdge, Surface};
use crate::eos::Eos;
use crate::flux::{numerical_flux, FluxScheme};
use crate::mesh::blocks::Window;
use crate::mesh::geometry::{dot, norm, sub};
use crate::mesh::Mesh;
use crate::reconstruct::limiter::Limiter;
use crate::riemann::{fluid_structure_with_cutoff, PressureCutoff, RiemannError};
use std::ops::Range;

/// Below this `|n_E · d̂_ij|` (the sine of the angle between edge and surface) an edge counts as
/// parallel to the surface and its orientation falls back on the facet normal (see
/// [`wall_normal_from_i`]).
pub const PARALLEL_TOLERANCE: f64 = 1e-8;

/// The fluid of a material as the wall flux needs it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WallMaterial {
    pub eos: Eos,
    pub cutoff: PressureCutoff,
}

/// What the wall fluxes read (all read-only): the mesh, the surface at the stage time `t`, the
/// node status, each node's material, and the primitive states `[ρ, u, v, w, p]`.
#[derive(Clone, Copy)]
pub struct WallFluxView<'a> {
    pub mesh: &'a Mesh,
    pub surface: &'a Surface,
    /// Stage time at which the wall velocity is evaluated ([`Surface::point_at`]).
    pub t: f64,
    pub scheme: FluxScheme,
    /// Active fluid nodes; inactive (and occluded) ends get no flux.
    pub active: &'a [bool],
    /// Material index of each node into `materials`.
    pub material: &'a [u8],
    pub materials: &'a [WallMaterial],
    pub prim: &'a [[f64; 5]],
    /// The nodal gradients of `prim` through same-side, same-fluid edges: `Some` selects the
    /// second-order interface of [`interface`], `None` the thesis' first-order form.
    pub grad: Option<&'a [[[f64; 3]; 5]]>,
    /// The limiter of the ordinary edges (the second-order form limits its node-side state).
    pub limiter: Limiter,
}

/// `p*` on the two sides of a cut edge: `[side of i, side of j]`, `NaN` where the end is inactive.
pub type WallPressures = [f64; 2];

/// An end of a cut edge.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum End {
    I,
    J,
}

/// A one-sided Riemann problem that has no wall state, with the cut edge, node and surface
/// element it came from.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error(
    "wall flux at cut edge {edge} (nodes {i}-{j}), node {node} at {position:?}, surface triangle \
     {triangle} of structure element {element}: {error}"
)]
pub struct WallFluxError {
    pub edge: u32,
    pub i: u32,
    pub j: u32,
    pub node: u32,
    pub position: [f64; 3],
    pub triangle: u32,
    pub element: u32,
    pub error: RiemannError,
}

/// The flux of one end and its wall state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OneSided {
    /// Flux leaving the node's dual cell through its facet: add it to the node's residual.
    pub flux: [f64; 5],
    pub rho: f64,
    pub p: f64,
    /// The cavitation cut-off set `p* = p_cut`.
    pub clipped: bool,
}

/// The unit wall normal seen from node `i` of an edge `d_ij = x_j - x_i` with facet normal
/// `ν_ij`: `n_E` turned to point from `i` towards the wall, i.e. `sign(n_E · d_ij) n_E`. For an
/// edge nearly parallel to the surface (`|n_E · d̂_ij| < PARALLEL_TOLERANCE`) the sign of
/// `n_E · ν_ij` decides instead (the facet the flux crosses), and `+n_E` if both vanish. The
/// normal from `j` is always the negative of this one, so the two sides never disagree.
#[inline]
pub fn wall_normal_from_i(n_e: [f64; 3], d_ij: [f64; 3], nu_ij: [f64; 3]) -> [f64; 3] {
    let s = dot(n_e, d_ij);
    let sign = if s.abs() >= PARALLEL_TOLERANCE * norm(d_ij) {
        s.signum()
    } else {
        let f = dot(n_e, nu_ij);
        if f.abs() >= PARALLEL_TOLERANCE * norm(nu_ij) {
            f.signum()
        } else {
            1.0
        }
    };
    n_e.map(|c| sign * c)
}

/// Alg. 5.1 for one end of one cut edge (the end must be an active node): with gradients in the
/// view, the second-order form of [`interface`]; without, the thesis' form, `F(W_i, W*(W_i), ν)`.
pub fn one_sided(view: &WallFluxView, cut: &CutEdge, end: End) -> Result<OneSided, WallFluxError> {
    let s = wall_states(view, cut, end)?;
    // Step 4: the numerical flux of the ordinary edges (Eq. 5.8), from the node side's state and
    // the wall side's.
    let flux = numerical_flux(view.scheme, &s.eos, &s.left, &s.right, &s.facet);
    Ok(OneSided { flux, rho: s.star.w[0], p: s.star.w[4], clipped: s.star.clipped })
}

/// The two states of the facet flux of [`one_sided`] (the node side's and the wall side's), its
/// facet normal and EOS, and the wall state `W*` (the loads read its pressure).
#[derive(Debug, Clone, Copy)]
pub struct WallStates {
    pub left: [f64; 5],
    pub right: [f64; 5],
    pub facet: [f64; 3],
    pub eos: Eos,
    pub star: Star,
}

/// Steps 1-3 of Alg. 5.1 for one end of one cut edge (the end must be an active node): the states
/// [`one_sided`] takes the flux between.
pub fn wall_states(
    view: &WallFluxView,
    cut: &CutEdge,
    end: End,
) -> Result<WallStates, WallFluxError> {
    let mesh = view.mesh;
    let e = cut.edge as usize;
    let [i, j] = mesh.edges[e];
    let d = sub(mesh.coords[j as usize], mesh.coords[i as usize]);
    let nu = mesh.edge_normals[e];
    let n_i = wall_normal_from_i(cut.normal, d, nu);
    let (node, n_wall, facet, towards) = match end {
        End::I => (i, n_i, nu, d),
        End::J => (j, n_i.map(|c| -c), nu.map(|c| -c), d.map(|c| -c)),
    };
    // Step 1: the wall's point and velocity at the intersection at the stage time.
    let (x_wall, w) = view.surface.point_at(cut.triangle as usize, cut.bary, view.t);
    let mat = &view.materials[view.material[node as usize] as usize];
    let wi = &view.prim[node as usize];
    let w_n = dot(w, n_wall);
    // Steps 2-3: the one-sided problem (Eq. 5.2-5.7) from a state `W` with the node's EOS and
    // cut-off; `W*` keeps the tangential velocity of `W`, its normal velocity is the wall's.
    let star = |w_in: &[f64; 5]| -> Result<Star, WallFluxError> {
        let u_n = w_in[1] * n_wall[0] + w_in[2] * n_wall[1] + w_in[3] * n_wall[2];
        let s = fluid_structure_with_cutoff(&mat.eos, w_in[0], u_n, w_in[4], w_n, mat.cutoff)
            .map_err(|error| WallFluxError {
                edge: cut.edge,
                i,
                j,
                node,
                position: mesh.coords[node as usize],
                triangle: cut.triangle,
                element: view.surface.element_of[cut.triangle as usize],
                error,
            })?;
        let dv = w_n - u_n;
        let (rho, p) = (s.state.rho, s.state.p);
        let w =
            [rho, w_in[1] + dv * n_wall[0], w_in[2] + dv * n_wall[1], w_in[3] + dv * n_wall[2], p];
        Ok(Star { w, clipped: s.clipped })
    };
    let (left, right, star) = match view.grad {
        None => {
            let s = star(wi)?;
            (*wi, s.w, s)
        }
        Some(grad) => {
            let x_node = mesh.coords[node as usize];
            let alpha = interface::wall_fraction(x_node, towards, n_wall, x_wall, cut, end);
            let g = &grad[node as usize];
            interface::facet_states(view.limiter, &mat.eos, wi, g, towards, alpha, star)?
        }
    };
    Ok(WallStates { left, right, facet, eos: mat.eos, star })
}

/// A wall state of the one-sided problem.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Star {
    /// `W* = [ρ*, v + (w_n - v·n) n, p*]`.
    pub w: [f64; 5],
    /// The cavitation cut-off set `p* = p_cut`.
    pub clipped: bool,
}

/// The cut edges (indices into `cuts`, sorted by edge) whose edges lie in `edges` (a block's).
pub fn cuts_in(cuts: &[CutEdge], edges: Range<usize>) -> Range<usize> {
    let lo = cuts.partition_point(|c| (c.edge as usize) < edges.start);
    let hi = cuts.partition_point(|c| (c.edge as usize) < edges.end);
    lo..hi
}

/// Adds the wall fluxes of a block's cut edges `cuts` to its residual window `r` (both active
/// ends, each flux added: see the module docs) and writes each edge's [`WallPressures`] into
/// `p_star` (same length as `cuts`). Returns the number of cut-off clips. The first failing end
/// stops the block with its error.
pub fn add_wall_fluxes(
    view: &WallFluxView,
    cuts: &[CutEdge],
    r: &mut Window<'_, [f64; 5]>,
    p_star: &mut [WallPressures],
) -> Result<usize, WallFluxError> {
    debug_assert_eq!(cuts.len(), p_star.len());
    let mut clips = 0;
    for (cut, ps) in cuts.iter().zip(p_star.iter_mut()) {
        let [i, j] = view.mesh.edges[cut.edge as usize];
        for (k, (end, node)) in [(End::I, i), (End::J, j)].into_iter().enumerate() {
            let node = node as usize;
            if !view.active[node] {
                ps[k] = f64::NAN;
                continue;
            }
            let s = one_sided(view, cut, end)?;
            for c in 0..5 {
                r[node][c] += s.flux[c];
            }
            ps[k] = s.p;
            clips += s.clipped as usize;
        }
    }
    Ok(clips)
}

pub mod interface;
#[cfg(test)]
mod tests;
