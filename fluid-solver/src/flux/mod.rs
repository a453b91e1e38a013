//! Numerical fluxes through an edge's dual facet (thesis §3.3.1, Eq. 3.4; §5.2 Eq. 5.8).
//!
//! Every function takes primitive states `[ρ, u, v, w, p]` and an area-weighted normal `n` (from
//! the left state to the right state) and returns the flux integrated over the facet, i.e. for
//! the unit normal `n̂ = n/|n|` the flux density times `|n|`. Nothing allocates and nothing
//! dispatches virtually: an `Eos` is a small `Copy` enum matched inline.
//!
//! - [`physical_flux`] is `f(W)·n`;
//! - [`numerical_flux`] is the edge-loop entry, Roe ([`roe`]) or HLLC ([`hllc`]);
//! - [`wall_flux`] closes a facet at a wall (embedded surface or slip wall) through the one-sided
//!   fluid-structure Riemann problem (thesis Alg. 5.1);
//! - [`two_phase_flux`] gives the two sides of a fluid-fluid interface through the exact
//!   two-phase Riemann problem (ghost fluid, thesis §3.3.2, Eq. 3.9).

mod hllc;
mod roe;
mod wall;

pub use hllc::hllc;
pub use roe::{roe, ENTROPY_FIX};
pub use wall::{
    two_phase_flux, two_phase_flux_along, two_phase_flux_with_cutoff, wall_flux, TwoPhaseFlux,
    WallFlux,
};

use crate::eos::Eos;
use serde::Deserialize;

/// Approximate Riemann solver of the edge loop (case-file values `"roe"`, `"hllc"`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FluxScheme {
    /// Roe's flux with Harten's entropy fix ([`roe`]).
    #[default]
    Roe,
    /// Toro's HLLC flux with Einfeldt's wave speeds ([`hllc`]).
    Hllc,
}

/// The numerical flux `F(W_l, W_r, EOS, n)` integrated over the facet with area normal `n`.
#[inline(always)]
pub fn numerical_flux(
    scheme: FluxScheme,
    eos: &Eos,
    wl: &[f64; 5],
    wr: &[f64; 5],
    n: &[f64; 3],
) -> [f64; 5] {
    match scheme {
        FluxScheme::Roe => roe(eos, wl, wr, n),
        FluxScheme::Hllc => hllc(eos, wl, wr, n),
    }
}

/// The physical flux `f(W)·n = [ρ u_n, ρ u u_n + p n, (E + p) u_n]`.
#[inline(always)]
pub fn physical_flux(eos: &Eos, w: &[f64; 5], n: &[f64; 3]) -> [f64; 5] {
    let q = eos.prim_to_cons(w);
    flux_of(w, &q, n)
}

/// `f·n` from a primitive state and its conserved form (`n` unit or area-weighted).
#[inline(always)]
fn flux_of(w: &[f64; 5], q: &[f64; 5], n: &[f64; 3]) -> [f64; 5] {
    let un = w[1] * n[0] + w[2] * n[1] + w[3] * n[2];
    let p = w[4];
    [q[0] * un, q[1] * un + p * n[0], q[2] * un + p * n[1], q[3] * un + p * n[2], (q[4] + p) * un]
}

/// `(n̂, |n|)`.
#[inline(always)]
fn unit(n: &[f64; 3]) -> ([f64; 3], f64) {
    let a = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    let inv = 1.0 / a;
    ([n[0] * inv, n[1] * inv, n[2] * inv], a)
}

/// Roe averages of two primitive states (Roe 1981), shared by both fluxes.
#[derive(Clone, Copy)]
struct RoeAverage {
    /// `ρ̃ = √(ρ_l ρ_r)`.
    rho: f64,
    u: [f64; 3],
    /// Total enthalpy `H̃`.
    h: f64,
    /// Sound speed `c̃`.
    c: f64,
}

/// Roe averages with the sound speed that keeps `F_r - F_l = Ã (Q_r - Q_l)` exact:
/// gas (perfect and stiffened) `c̃² = (γ - 1)(H̃ - |ũ|²/2)` (the constant `-γ p_c` in the pressure
/// drops out of every difference, so Roe's parameter-vector argument is unchanged; for one state it
/// gives `γ(p + p_c)/ρ`); Tait `c̃² = Δp/Δρ`, or `c²(ρ̄)` when `|Δρ| ≤ 1e-7 ρ̄` or the quotient is
/// not positive (the energy row of Tait's Roe matrix then carries the same `H̃ ± ũ_n c̃`).
#[inline(always)]
fn roe_average(
    eos: &Eos,
    wl: &[f64; 5],
    ql: &[f64; 5],
    wr: &[f64; 5],
    qr: &[f64; 5],
) -> RoeAverage {
    let sl = wl[0].sqrt();
    let sr = wr[0].sqrt();
    let inv = 1.0 / (sl + sr);
    let (al, ar) = (sl * inv, sr * inv);
    let u = [al * wl[1] + ar * wr[1], al * wl[2] + ar * wr[2], al * wl[3] + ar * wr[3]];
    let hl = (ql[4] + wl[4]) / wl[0];
    let hr = (qr[4] + wr[4]) / wr[0];
    let h = al * hl + ar * hr;
    let c2 = match *eos {
        Eos::PerfectGas { gamma } | Eos::StiffenedGas { gamma, .. } => {
            (gamma - 1.0) * (h - 0.5 * (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]))
        }
        Eos::Tait { .. } => {
            let drho = wr[0] - wl[0];
            let rho_bar = 0.5 * (wl[0] + wr[0]);
            let secant = (wr[4] - wl[4]) / drho;
            if drho.abs() > 1e-7 * rho_bar && secant > 0.0 {
                secant
            } else {
                eos.sound_speed_sq(rho_bar, eos.tait_pressure(rho_bar))
            }
        }
    };
    debug_assert!(c2 > 0.0, "Roe-averaged c² = {c2} not positive");
    RoeAverage { rho: sl * sr, u, h, c: c2.sqrt() }
}

#[cfg(test)]
pub(crate) mod line;
#[cfg(test)]
mod tests;
