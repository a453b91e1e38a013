//! Edges between two fluids (thesis §3.3.2, Eq. 3.9; DESIGN §5): the two-phase ghost-fluid flux.
//!
//! At an edge `i -> j` whose end nodes hold different materials, the exact two-phase Riemann
//! problem along `n̂ = ν_ij/|ν_ij|` between the nodal states `W_i` (EOS_i) and `W_j` (EOS_j)
//! gives the star states on each side of the contact; each node then takes the single-material
//! flux of the scheme between its own state and its side's star state, with its own EOS
//! ([`crate::flux::two_phase_flux`]): `R_i += F(W_i, W*_i, EOS_i, ν_ij)` and
//! `R_j -= F(W*_j, W_j, EOS_j, ν_ij)` (the j-side flux is along `+ν`, so it is subtracted as in
//! the ordinary loop). No flux mixes the two EOS.
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
use crate::flux::two_phase_flux_with_cutoff;
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
    let f = two_phase_flux_with_cutoff(
        semi.numerics.flux,
        eos_i,
        &prim[i],
        eos_j,
        &prim[j],
        &mesh.edge_normals[e],
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

/// The cavitation cut-off of a two-phase problem between `a` and `b`: the larger of their
/// defaults ([`PressureCutoff::default_for`]: the vapour pressure of water for a liquid, none for
/// a perfect gas).
#[inline]
pub fn cutoff(a: &Eos, b: &Eos) -> PressureCutoff {
    let p_cut = PressureCutoff::default_for(a).p_cut.max(PressureCutoff::default_for(b).p_cut);
    PressureCutoff { p_cut }
}
