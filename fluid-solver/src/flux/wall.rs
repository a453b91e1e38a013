//! Fluxes built on exact Riemann star states: the wall flux of thesis Alg. 5.1 (Eq. 5.5-5.8) and
//! the two-phase ghost-fluid flux of thesis §3.3.2 (Eq. 3.9).

use super::{numerical_flux, FluxScheme};
use crate::eos::Eos;
use crate::riemann::{self, PressureCutoff, RiemannError, StarState, State1d};

/// Flux through a facet bounded by a wall, with the fluid state at the wall.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WallFlux {
    /// `F(W_i, W*, EOS_i, n)` integrated over the facet.
    pub flux: [f64; 5],
    /// `ρ*` of the one-sided problem.
    pub rho: f64,
    /// `p*`: the pressure the structure loads use (Alg. 5.1 step 3).
    pub p: f64,
}

/// Wall flux of thesis Alg. 5.1: the one-sided problem along the unit wall normal `wall_normal`
/// (pointing from the node into the wall) with the wall's normal velocity
/// `w_n = wall_velocity · wall_normal` gives `(ρ*, p*)`; the wall state
/// `W* = (ρ*, v - (v·n̂)n̂ + w_n n̂, p*)` keeps the node's tangential velocity (Eq. 5.7), and the
/// flux is the scheme's `F(W_i, W*, EOS_i, n)` (Eq. 5.8) over the facet with area normal `n`.
/// A slip wall is `wall_normal = n/|n|`, `wall_velocity = 0`.
#[inline]
pub fn wall_flux(
    scheme: FluxScheme,
    eos: &Eos,
    w: &[f64; 5],
    n: &[f64; 3],
    wall_normal: &[f64; 3],
    wall_velocity: &[f64; 3],
) -> Result<WallFlux, RiemannError> {
    let ne = wall_normal;
    let un = w[1] * ne[0] + w[2] * ne[1] + w[3] * ne[2];
    let wn = wall_velocity[0] * ne[0] + wall_velocity[1] * ne[1] + wall_velocity[2] * ne[2];
    let star = riemann::fluid_structure(eos, w[0], un, w[4], wn)?;
    let dv = wn - un;
    let w_star = [star.rho, w[1] + dv * ne[0], w[2] + dv * ne[1], w[3] + dv * ne[2], star.p];
    Ok(WallFlux { flux: numerical_flux(scheme, eos, w, &w_star, n), rho: star.rho, p: star.p })
}

/// Fluxes on both sides of a fluid-fluid interface on an edge `i -> j` (thesis Eq. 3.9).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TwoPhaseFlux {
    /// `F(W_i, W*_i, EOS_i, n)`: leaves node `i`.
    pub flux_i: [f64; 5],
    /// `F(W*_j, W_j, EOS_j, n)`: enters node `j`.
    pub flux_j: [f64; 5],
    /// The exact star state along `n̂` (`rho_l` on `i`'s side).
    pub star: StarState,
}

/// Ghost-fluid flux between nodes of different fluids (thesis §3.3.2): the exact two-phase
/// Riemann problem along `n̂` between `W_i` (EOS_i) and `W_j` (EOS_j) gives the star states
/// `W*_i = (ρ*_l, v_i + (u* - v_i·n̂) n̂, p*)` and `W*_j` likewise; each node then sees a
/// single-material flux with its own EOS, so no flux mixes EOS.
#[inline]
pub fn two_phase_flux(
    scheme: FluxScheme,
    eos_i: &Eos,
    wi: &[f64; 5],
    eos_j: &Eos,
    wj: &[f64; 5],
    n: &[f64; 3],
) -> Result<TwoPhaseFlux, RiemannError> {
    two_phase_flux_with_cutoff(scheme, eos_i, wi, eos_j, wj, n, PressureCutoff::OFF)
}

/// [`two_phase_flux`] with the cavitation cut-off `cut` on the star pressure
/// ([`riemann::solve_with_cutoff`]).
#[inline]
pub fn two_phase_flux_with_cutoff(
    scheme: FluxScheme,
    eos_i: &Eos,
    wi: &[f64; 5],
    eos_j: &Eos,
    wj: &[f64; 5],
    n: &[f64; 3],
    cut: PressureCutoff,
) -> Result<TwoPhaseFlux, RiemannError> {
    let (nh, _) = super::unit(n);
    two_phase_flux_along(scheme, eos_i, wi, eos_j, wj, n, nh, cut)
}

/// [`two_phase_flux_with_cutoff`] with the Riemann problem solved along the unit direction `nh`
/// (from `i`'s fluid into `j`'s; the interface normal where it is known) instead of along `n`:
/// the star states `W*_i = (ρ*_l, v_i + (u* - v_i·n̂) n̂, p*)` and `W*_j` likewise, each node's
/// flux through the facet `n` between its state and its star state.
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn two_phase_flux_along(
    scheme: FluxScheme,
    eos_i: &Eos,
    wi: &[f64; 5],
    eos_j: &Eos,
    wj: &[f64; 5],
    n: &[f64; 3],
    nh: [f64; 3],
    cut: PressureCutoff,
) -> Result<TwoPhaseFlux, RiemannError> {
    let uni = wi[1] * nh[0] + wi[2] * nh[1] + wi[3] * nh[2];
    let unj = wj[1] * nh[0] + wj[2] * nh[1] + wj[3] * nh[2];
    let star = riemann::solve_with_cutoff(
        eos_i,
        State1d { rho: wi[0], u: uni, p: wi[4] },
        eos_j,
        State1d { rho: wj[0], u: unj, p: wj[4] },
        cut,
    )?
    .state;
    let with_normal_velocity = |w: &[f64; 5], un: f64, rho: f64| {
        let dv = star.u - un;
        [rho, w[1] + dv * nh[0], w[2] + dv * nh[1], w[3] + dv * nh[2], star.p]
    };
    let wi_star = with_normal_velocity(wi, uni, star.rho_l);
    let wj_star = with_normal_velocity(wj, unj, star.rho_r);
    Ok(TwoPhaseFlux {
        flux_i: numerical_flux(scheme, eos_i, wi, &wi_star, n),
        flux_j: numerical_flux(scheme, eos_j, &wj_star, wj, n),
        star,
    })
}
