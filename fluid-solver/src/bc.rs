//! Boundary fluxes at the dual boundary facets of the named boundaries (DESIGN §5).
//!
//! Each boundary node `i` with outward dual boundary area vector `n_i` receives one flux
//! `F_b(W_i, n_i)` built from the node state (first order at the boundary, as in vertex-centred
//! codes):
//! - slip wall and symmetry: the wall flux of thesis Alg. 5.1 with a fixed wall
//!   ([`crate::flux::wall_flux`]): the one-sided Riemann problem gives the wall pressure `p*`
//!   (at symmetry planes the operator then also removes the momentum residual along the normal,
//!   [`crate::symmetry`]);
//! - far field: the upwind flux `F(W_i, W_∞, n)` against the free stream: flux-difference
//!   splitting takes the incoming characteristics from `W_∞` and the outgoing ones from `W_i`
//!   (non-reflecting for waves leaving along `n`, the characteristic far field of Steger-Warming
//!   type codes);
//! - inflow: supersonic, the physical flux of the given state; subsonic, a ghost state with the
//!   given density and velocity and the interior pressure;
//! - outflow: supersonic, the interior state; subsonic, a ghost state with the interior density
//!   and velocity and the given pressure.

use crate::eos::Eos;
use crate::flux::{numerical_flux, physical_flux, wall_flux, FluxScheme};
use crate::mesh::geometry::{dot, norm, scale};
use crate::riemann::RiemannError;

/// The condition applied on a named boundary.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BoundaryCondition {
    /// Impermeable wall, fluid slips along it.
    SlipWall,
    /// Symmetry plane (the same flux as a slip wall for the Euler equations).
    Symmetry,
    /// Non-reflecting far field with free-stream primitive state `[ρ, u, v, w, p]`.
    FarField { state: [f64; 5] },
    /// Inflow of the primitive state `[ρ, u, v, w, p]`.
    Inflow { state: [f64; 5] },
    /// Outflow at static pressure `pressure`.
    Outflow { pressure: f64 },
}

impl BoundaryCondition {
    /// The flux out of node `i` (primitive state `w`) through its dual boundary area vector `n`.
    #[inline]
    pub fn flux(
        &self,
        scheme: FluxScheme,
        eos: &Eos,
        w: &[f64; 5],
        n: &[f64; 3],
    ) -> Result<[f64; 5], RiemannError> {
        let normal_mach = || {
            let un = dot([w[1], w[2], w[3]], *n) / norm(*n);
            un / eos.sound_speed(w[0], w[4])
        };
        Ok(match *self {
            BoundaryCondition::SlipWall | BoundaryCondition::Symmetry => {
                let unit = scale(*n, 1.0 / norm(*n));
                wall_flux(scheme, eos, w, n, &unit, &[0.0; 3])?.flux
            }
            BoundaryCondition::FarField { state } => numerical_flux(scheme, eos, w, &state, n),
            BoundaryCondition::Inflow { state } => {
                let un = dot([state[1], state[2], state[3]], *n) / norm(*n);
                if -un >= eos.sound_speed(state[0], state[4]) {
                    physical_flux(eos, &state, n)
                } else {
                    // Barotropic (Tait): the density follows the pressure.
                    let rho = if eos.is_barotropic() { eos.tait_density(w[4]) } else { state[0] };
                    let ghost = [rho, state[1], state[2], state[3], w[4]];
                    numerical_flux(scheme, eos, w, &ghost, n)
                }
            }
            BoundaryCondition::Outflow { pressure } => {
                if normal_mach() >= 1.0 {
                    physical_flux(eos, w, n)
                } else {
                    let rho = if eos.is_barotropic() { eos.tait_density(pressure) } else { w[0] };
                    let ghost = [rho, w[1], w[2], w[3], pressure];
                    numerical_flux(scheme, eos, w, &ghost, n)
                }
            }
        })
    }
}
