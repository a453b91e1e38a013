//! The one-sided fluid-structure Riemann problem of thesis Alg. 5.1 step 2 (Eq. 5.2-5.7, §2.4.3,
//! App. A): fluid at `(ρ, u_n, p)` on the side `s < 0`, a wall at `s = w_n t` moving with normal
//! velocity `w_n`, both along the normal pointing from the fluid into the wall.
//!
//! One wave leaves the wall: a shock if `u_n > w_n` (the wall pushes), a rarefaction otherwise;
//! the star state has `u* = w_n`, so `f(p*) = u_n - w_n` with the same wave curve `f` as the
//! two-sided problem (App. A mirrors the state about the wall: a symmetric Riemann problem whose
//! star velocity is zero in the wall frame).

use super::wave_curve::Side;
use super::{solve_increasing, RiemannError};
use crate::eos::Eos;

/// Fluid state at the wall: density `ρ*` and pressure `p*`; its velocity is the wall's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WallState {
    pub rho: f64,
    pub p: f64,
}

/// Solves the one-sided problem; `Vacuum` if the wall recedes faster than the escape speed
/// `2c/(g - 1)` (the fluid separates from the wall).
#[inline]
pub fn fluid_structure(
    eos: &Eos,
    rho: f64,
    u_n: f64,
    p: f64,
    w_n: f64,
) -> Result<WallState, RiemannError> {
    let side = Side::new(eos, rho, u_n, p);
    let rel = u_n - w_n;
    let guess = p + rho * side.c * rel;
    let p_star = solve_increasing(
        |q| {
            let (f, df) = side.f(q);
            (f - rel, df)
        },
        side.p_floor(),
        guess,
    )?;
    Ok(WallState { rho: side.density_behind(p_star), p: p_star })
}
