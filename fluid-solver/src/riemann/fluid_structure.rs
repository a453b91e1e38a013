//! The one-sided fluid-structure Riemann problem of thesis Alg. 5.1 step 2 (Eq. 5.2-5.7, §2.4.3,
//! App. A): fluid at `(ρ, u_n, p)` on the side `s < 0`, a wall at `s = w_n t` moving with normal
//! velocity `w_n`, both along the normal pointing from the fluid into the wall.
//!
//! One wave leaves the wall: a shock if `u_n > w_n` (the wall pushes), a rarefaction otherwise;
//! the star state has `u* = w_n`, so `f(p*) = u_n - w_n` with the same wave curve `f` as the
//! two-sided problem (App. A mirrors the state about the wall: a symmetric Riemann problem whose
//! star velocity is zero in the wall frame). That root has a closed form for every rarefaction
//! and for a gas shock (`Side::root`); only a Tait shock is solved by Newton's method.

use super::wave_curve::Side;
use super::{solve_increasing, Clipped, PressureCutoff, RiemannError};
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
    fluid_structure_with_cutoff(eos, rho, u_n, p, w_n, PressureCutoff::OFF).map(|c| c.state)
}

/// [`fluid_structure`] with the cavitation cut-off: when `f(p_cut) >= u_n - w_n` the exact `p*`
/// lies below `p_cut` (or the wall leaves a void behind), and the wall state is
/// `(ρ(p_cut), p_cut)` on the node's wave curve (the isentrope for the rarefaction a receding
/// wall makes), flagged as clipped. Otherwise the exact solution, bitwise as without the cut-off.
#[inline]
pub fn fluid_structure_with_cutoff(
    eos: &Eos,
    rho: f64,
    u_n: f64,
    p: f64,
    w_n: f64,
    cut: PressureCutoff,
) -> Result<Clipped<WallState>, RiemannError> {
    let side = Side::new(eos, rho, u_n, p);
    let rel = u_n - w_n;
    if let Some(p_cut) = cut.active_above(side.p_floor()) {
        if side.f(p_cut).0 >= rel {
            let state = WallState { rho: side.density_behind(p_cut), p: p_cut };
            return Ok(Clipped { state, clipped: true });
        }
    }
    // A non-finite input leaves no finite root: Newton's method then reports it.
    let p_star = match side.root(rel) {
        Some(Ok(root)) if root.is_finite() => root,
        Some(Err(e)) => return Err(e),
        _ => solve_increasing(
            |q| {
                let (f, df) = side.f(q);
                (f - rel, df)
            },
            side.p_floor(),
            p + rho * side.c * rel,
        )?,
    };
    Ok(Clipped { state: WallState { rho: side.density_behind(p_star), p: p_star }, clipped: false })
}
