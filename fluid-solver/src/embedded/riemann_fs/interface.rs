//! The second-order interface of Alg. 5.1 (after Main, Zeng, Avery & Farhat, "An enhanced FIVER
//! method for multi-material flow problems with second-order convergence rate", J. Comput. Phys.
//! 2017): the thesis' form puts the wall state `W*(W_i)` of the node's own state at the node's
//! facet, whatever the distance from the node to the wall, which makes the interface first order.
//! Here, for the active end `i` of a cut edge with `d = x_j - x_i`, the wall at the fraction `α` of
//! the edge at the stage time and the node's gradient `∇W_i` through same-side, same-fluid edges:
//!
//! 1. `W_Γ = W_i + α ∇W_i·d`: the node state reconstructed to the intersection point;
//! 2. `W*_Γ = W*(W_Γ)`: the one-sided fluid-structure problem there (Eq. 5.2-5.7);
//! 3. the wall-side state at the facet (the edge midpoint `x_i + d/2`) on the line through
//!    `(x_i, W_i)` and `(x_Γ, W*_Γ)`: interpolated, `W_f = W_i + (W*_Γ - W_i) / (2α)`, when the
//!    wall lies beyond the midpoint (`α >= 1/2`); otherwise extrapolated past the wall with the
//!    node's slope, `W_f = W*_Γ + (1/2 - α) ∇W_i·d` (bounded as `α -> 0`; both give `W*_Γ` at
//!    `α = 1/2`);
//! 4. the node-side state `W_L = W_i + L(2∇W_i·d - Δ, Δ)/2` of the ordinary MUSCL edge
//!    ([`crate::reconstruct::muscl`]) with `Δ = 2 (W_f - W_i)`, as if a ghost node at `x_j` held
//!    the line's value `W_i + Δ`;
//! 5. the flux `F(W_L, W_f, EOS_i, ν_ij)` of the ordinary edges.
//!
//! For a smooth flow both `W_L` and `W_f` are the flow's (smoothly continued) state at the
//! midpoint to `O(h²)`, so the facet flux is second order wherever the wall is. A uniform state
//! that satisfies the wall condition (`u·n = w·n`) has zero gradient and `W*_Γ = W_i`: every state
//! above is `W_i` and the flux is the physical flux, to round-off. A reconstructed state outside its
//! EOS's domain falls back on the node state (1, 4) or on `W*_Γ` (3), and a `W_Γ` from which the
//! wall recedes faster than its escape speed `2c/(γ-1)` (a steep expansion next to a fast wall,
//! where the unlimited reconstruction nears vacuum) on the node's own wall state `W*(W_i)` of the
//! thesis' form (2): a vacuum is an error only if the node state itself opens one. Tait fluids take
//! `p = p(ρ)`.

use super::{End, Star, WallFluxError, PARALLEL_TOLERANCE};
use crate::embedded::CutEdge;
use crate::eos::Eos;
use crate::mesh::geometry::{dot, norm, sub};
use crate::reconstruct::limiter::Limiter;
use crate::reconstruct::muscl::admissible;
use crate::riemann::RiemannError;

/// The fraction `α ∈ [0, 1]` of the edge from `x_node` (along `towards`, the edge vector from
/// the node to the other end) at which the wall plane through `x_wall` with the normal `n_wall`
/// (oriented from the node) crosses it: `α = n·(x_wall - x_node) / n·d`. For an edge nearly
/// parallel to the wall the tracked fraction of `cut` at `t_b` is kept.
#[inline]
pub fn wall_fraction(
    x_node: [f64; 3],
    towards: [f64; 3],
    n_wall: [f64; 3],
    x_wall: [f64; 3],
    cut: &CutEdge,
    end: End,
) -> f64 {
    let s = dot(n_wall, towards);
    if s > PARALLEL_TOLERANCE * norm(towards) {
        (dot(n_wall, sub(x_wall, x_node)) / s).clamp(0.0, 1.0)
    } else {
        match end {
            End::I => cut.alpha,
            End::J => 1.0 - cut.alpha,
        }
    }
}

/// Steps 1-4 of the module docs for the node state `wi` with gradient `grad` (`grad[k] = ∇W_k`),
/// the edge vector `towards` from the node, the wall fraction `alpha` and the one-sided solver
/// `star`: returns `(W_L, W_f, W*_Γ)`.
pub fn facet_states(
    limiter: Limiter,
    eos: &Eos,
    wi: &[f64; 5],
    grad: &[[f64; 3]; 5],
    towards: [f64; 3],
    alpha: f64,
    star: impl Fn(&[f64; 5]) -> Result<Star, WallFluxError>,
) -> Result<([f64; 5], [f64; 5], Star), WallFluxError> {
    let gd: [f64; 5] = std::array::from_fn(|k| dot(grad[k], towards));
    // Step 1: the node state at the intersection point.
    let at_wall = valid_or(eos, std::array::from_fn(|k| wi[k] + alpha * gd[k]), wi);
    // Step 2: the wall state there; if the reconstructed state separates from the wall (its
    // escape speed is below the wall's recession, while the node's own is not), the thesis' form.
    let s = match star(&at_wall) {
        Err(e) if matches!(e.error, RiemannError::Vacuum { .. }) && at_wall != *wi => star(wi)?,
        s => s?,
    };
    // Step 3: the wall side of the facet, on the line through the star state.
    let w_f: [f64; 5] = if alpha >= 0.5 {
        let r = 0.5 / alpha;
        std::array::from_fn(|k| wi[k] + r * (s.w[k] - wi[k]))
    } else {
        std::array::from_fn(|k| s.w[k] + (0.5 - alpha) * gd[k])
    };
    let w_f = valid_or(eos, w_f, &s.w);
    // Step 4: the node side, the ordinary MUSCL state with the line's ghost value at x_j.
    let w_l: [f64; 5] = std::array::from_fn(|k| {
        let delta = 2.0 * (w_f[k] - wi[k]);
        wi[k] + 0.5 * limiter.slope(2.0 * gd[k] - delta, delta)
    });
    let w_l = valid_or(eos, w_l, wi);
    Ok((w_l, w_f, s))
}

/// `w` with a Tait pressure recomputed from its density, or `fallback` if it leaves the EOS's
/// domain.
#[inline]
fn valid_or(eos: &Eos, mut w: [f64; 5], fallback: &[f64; 5]) -> [f64; 5] {
    if eos.is_barotropic() {
        w[4] = eos.tait_pressure(w[0]);
    }
    if admissible(eos, &w) {
        w
    } else {
        *fallback
    }
}
