//! Edges between two fluids (thesis §3.3.2, Eq. 3.9; DESIGN §5): the two-phase ghost-fluid flux.
//!
//! At an edge `i -> j` whose end nodes hold different materials, the exact two-phase Riemann
//! problem along a direction `n̂` between the nodal states `W_i` (EOS_i) and `W_j` (EOS_j)
//! gives the star states on each side of the contact, `W*_i = (ρ*_i, v_i + (u* - v_i·n̂) n̂, p*)`
//! and likewise `W*_j`; each node then takes the single-material flux of the scheme between its
//! own state and its side's star state through the edge's facet, with its own EOS
//! ([`crate::flux::two_phase_flux_along`]): `R_i += F(W_i, W*_i, EOS_i, ν_ij)` and
//! `R_j -= F(W*_j, W_j, EOS_j, ν_ij)` (the j-side flux is along `+ν`, so it is subtracted as in
//! the ordinary loop). No flux mixes the two EOS.
//!
//! The direction ([`direction`]): with a level set, the interface normal
//! `(∇φ_i + ∇φ_j)/|∇φ_i + ∇φ_j|` of the step's `φⁿ` ([`Semidiscretization::interface`]), pointing
//! from `i`'s fluid into `j`'s; else the edge's `ν_ij/|ν_ij|`. The contact is a 1D problem along
//! the interface's normal: along an edge oblique to the interface the problem along `ν̂` would
//! carry the whole pressure jump, not its normal projection, and drive the contact along every
//! such edge as fast as along the normal. On axis-aligned hexes around a sphere (the underwater
//! bubble) the facets' volume flux `Σ u* |ν|` then exceeds the interface's own `∫ u*_n dA` while
//! the pressure jumps (the bubble's acceleration); the gas nodes lost that mass through their
//! facets but the level set, moving at the normal speed, did not hand them the nodes it would
//! have filled (the gas lost 20% of its mass in the first 0.2 ms, see the case's README). Where
//! `ν̂` is the normal (a planar interface across a tube of hexes) both are the same problem.
//!
//! The Riemann problem takes the nodal states, as in the thesis (Eq. 3.9 is initialised by
//! `W_i` and `W_j`): the interface is first order. The two fluxes differ by the jump the contact
//! carries, so the scheme is not conservative at the interface: `Σ_i R_i` equals the boundary flux
//! plus `Σ (F_i - F_j)` over the two-material edges (zero for a contact at rest at equal
//! pressure, whose two fluxes are both the pressure flux `p ν`).
//!
//! Cavitation (DESIGN §5.1): the star pressure is cut off at the larger of the two fluids'
//! default cut-offs ([`cutoff`]), so a liquid next to a gas never returns tension.

use crate::eos::Eos;
use crate::flux::two_phase_flux_along;
use crate::mesh::blocks::Window;
use crate::riemann::PressureCutoff;
use crate::semidiscretization::{FluidError, Semidiscretization};

/// Adds the two-phase fluxes of edge `e` (its ends hold different materials) to the residuals of
/// its ends.
pub(crate) fn edge_flux(
    semi: &Semidiscretization,
    e: usize,
    prim: &[[f64; 5]],
    r: &mut Window<'_, [f64; 5]>,
) -> Result<(), FluidError> {
    let mesh = &semi.mesh;
    let [i, j] = mesh.edges[e];
    let (i, j) = (i as usize, j as usize);
    let (eos_i, eos_j) = (semi.eos_at(i), semi.eos_at(j));
    let n = &mesh.edge_normals[e];
    let f = two_phase_flux_along(
        semi.numerics.flux,
        eos_i,
        &prim[i],
        eos_j,
        &prim[j],
        n,
        direction(semi, i, j, n),
        cutoff(eos_i, eos_j),
    )
    .map_err(|error| {
        let m = semi.material();
        FluidError::TwoPhase {
            edge: e,
            nodes: [i, j],
            materials: [m[i], m[j]],
            position: mesh.coords[i],
            error,
        }
    })?;
    for k in 0..5 {
        r[i][k] += f.flux_i[k];
    }
    for k in 0..5 {
        r[j][k] -= f.flux_j[k];
    }
    Ok(())
}

/// The direction of the two-phase problem of the edge `i -> j` with normal `n`: the interface
/// normal `(∇φ_i + ∇φ_j)/|∇φ_i + ∇φ_j|` pointing from `i`'s fluid into `j`'s, where a level set
/// gives it (module docs), else `n/|n|`.
pub fn direction(semi: &Semidiscretization, i: usize, j: usize, n: &[f64; 3]) -> [f64; 3] {
    let along_n = || {
        let a = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        [n[0] / a, n[1] / a, n[2] / a]
    };
    let Some(normals) = &semi.interface else {
        return along_n();
    };
    let (gi, gj) = (normals.grad_phi[i], normals.grad_phi[j]);
    let g = [gi[0] + gj[0], gi[1] + gj[1], gi[2] + gj[2]];
    let norm = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
    if norm == 0.0 || !norm.is_finite() {
        return along_n();
    }
    let sign = if semi.material()[j] == normals.toward { 1.0 } else { -1.0 };
    [sign * g[0] / norm, sign * g[1] / norm, sign * g[2] / norm]
}

/// The cavitation cut-off of a two-phase problem between `a` and `b`: the larger of their
/// defaults ([`PressureCutoff::default_for`]: the vapour pressure of water for a liquid, none for
/// a perfect gas).
#[inline]
pub fn cutoff(a: &Eos, b: &Eos) -> PressureCutoff {
    let p_cut = PressureCutoff::default_for(a).p_cut.max(PressureCutoff::default_for(b).p_cut);
    PressureCutoff { p_cut }
}
