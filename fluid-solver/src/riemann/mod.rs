//! Exact Riemann solvers (thesis §2.4): the single- and two-phase fluid problems (P1, P2) for any
//! pair of EOS, and the one-sided fluid-structure problem (P3, App. A) of Alg. 5.1.
//!
//! The star pressure solves `f_l(p) + f_r(p) + u_r - u_l = 0` (Toro §4.3), each `f_K` built from
//! its own side's EOS (module `wave_curve`), by Newton's method safeguarded by a bracket: the
//! function is increasing and concave, the bracket starts at the lowest pressure both wave curves
//! reach and is widened upward until it changes sign, and any Newton step leaving the bracket is
//! replaced by bisection. The problem is one-dimensional along a normal: states are `(ρ, u_n, p)`.

mod fluid_structure;
mod sample;
pub mod simple_wave;
mod wave_curve;

pub use fluid_structure::{fluid_structure, fluid_structure_with_cutoff, WallState};
pub use sample::{RiemannSolution, Sample};

use crate::eos::Eos;
use wave_curve::Side;

/// Relative tolerance on the star pressure, measured from the lowest admissible pressure.
const TOLERANCE: f64 = 1e-14;
/// Iteration cap: Newton from the acoustic guess needs a handful of steps; the cap only stops
/// non-finite input, which then reports `NoConvergence` instead of looping.
const MAX_ITERATIONS: usize = 200;

/// A one-dimensional state along the problem's axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct State1d {
    pub rho: f64,
    /// Velocity along the axis.
    pub u: f64,
    pub p: f64,
}

/// The star region between the two acoustic waves: velocity and pressure continuous, density
/// jumping at the contact (thesis Fig. 2.1-2.2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StarState {
    pub p: f64,
    pub u: f64,
    /// Density left of the contact (left EOS).
    pub rho_l: f64,
    /// Density right of the contact (right EOS).
    pub rho_r: f64,
}

/// Why a Riemann problem has no star state.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum RiemannError {
    /// The rarefactions (or a receding wall) open a void: even at the lowest pressure `p_floor`
    /// both wave curves reach, the fluid separates with velocity gap `gap` (Toro §4.6).
    #[error(
        "the Riemann problem opens a vacuum: velocity gap {gap} at the lowest pressure {p_floor}"
    )]
    Vacuum { p_floor: f64, gap: f64 },
    /// The safeguarded Newton iteration did not converge (a bug, or non-finite input).
    #[error("star pressure iteration did not converge: p = {p}, residual {residual}")]
    NoConvergence { p: f64, residual: f64 },
}

/// Vapour pressure of water at 20 °C (Pa): the default cavitation cut-off of a liquid.
pub const WATER_VAPOUR_PRESSURE_20C: f64 = 2339.0;

/// The cavitation cut-off of DESIGN §5.1: star pressures below `p_cut` are set to `p_cut`, the
/// density then taken on the same wave curve at `p_cut` (the isentrope through the node state for
/// a rarefaction). A liquid cannot sustain the tension an inviscid Riemann solver returns behind a
/// receding wall (1 atm Tait water reaches `p* < 0` at 0.07 m/s of wall speed); the cut-off models
/// the vapour cavity as a region held at `p_cut`, which the thesis' model does not carry.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PressureCutoff {
    /// The minimum star pressure; `-∞` is off.
    pub p_cut: f64,
}

impl PressureCutoff {
    /// No cut-off: tension is returned as computed, a void as [`RiemannError::Vacuum`].
    pub const OFF: PressureCutoff = PressureCutoff { p_cut: f64::NEG_INFINITY };

    /// The default for a material: liquids (Tait, and stiffened gas with `p_c > 0`) the vapour
    /// pressure of water at 20 °C, 2339 Pa; perfect gases off (a gas at `p = 0` has `ρ = 0`, a
    /// true vacuum, which stays an error).
    pub fn default_for(eos: &Eos) -> PressureCutoff {
        match *eos {
            Eos::Tait { .. } => PressureCutoff { p_cut: WATER_VAPOUR_PRESSURE_20C },
            Eos::StiffenedGas { p_c, .. } if p_c > 0.0 => {
                PressureCutoff { p_cut: WATER_VAPOUR_PRESSURE_20C }
            }
            _ => PressureCutoff::OFF,
        }
    }

    /// The cut-off pressure if it can act: strictly above the lowest pressure `p_floor` the wave
    /// curve reaches (at or below it the cut-off would hold a void, `ρ = 0`).
    #[inline]
    fn active_above(&self, p_floor: f64) -> Option<f64> {
        (self.p_cut > p_floor).then_some(self.p_cut)
    }
}

/// A star state and whether the cavitation cut-off clipped its pressure.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Clipped<T> {
    pub state: T,
    /// True when the exact star pressure lay below `p_cut` (or the problem opened a void) and
    /// `p_cut` was used instead.
    pub clipped: bool,
}

/// Solves the Riemann problem between `l` (EOS `eos_l`) and `r` (EOS `eos_r`) for its star state.
/// With `eos_l == eos_r` this is the single-material problem P1; otherwise the two-phase P2.
pub fn solve(eos_l: &Eos, l: State1d, eos_r: &Eos, r: State1d) -> Result<StarState, RiemannError> {
    solve_with_cutoff(eos_l, l, eos_r, r, PressureCutoff::OFF).map(|c| c.state)
}

/// [`solve`] with the cavitation cut-off `cut` (the larger of the two materials' cut-offs is the
/// caller's choice): if the star-pressure function is already non-negative at `p_cut`, the root
/// lies below it (or there is none: a void) and the star state is taken at `p_cut` on both wave
/// curves, its velocity the mean of the two curves' velocities there; otherwise the problem is
/// solved exactly as without the cut-off.
pub fn solve_with_cutoff(
    eos_l: &Eos,
    l: State1d,
    eos_r: &Eos,
    r: State1d,
    cut: PressureCutoff,
) -> Result<Clipped<StarState>, RiemannError> {
    let sl = Side::new(eos_l, l.rho, l.u, l.p);
    let sr = Side::new(eos_r, r.rho, r.u, r.p);
    if let Some(p_cut) = cut.active_above(sl.p_floor().max(sr.p_floor())) {
        let (fl, _) = sl.f(p_cut);
        let (fr, _) = sr.f(p_cut);
        if fl + fr + sr.u - sl.u >= 0.0 {
            return Ok(Clipped { state: star_from_pressure(&sl, &sr, p_cut), clipped: true });
        }
    }
    let p = star_pressure(&sl, &sr)?;
    Ok(Clipped { state: star_from_pressure(&sl, &sr, p), clipped: false })
}

#[inline]
fn star_from_pressure(sl: &Side, sr: &Side, p: f64) -> StarState {
    let (fl, _) = sl.f(p);
    let (fr, _) = sr.f(p);
    StarState {
        p,
        u: 0.5 * (sl.u + sr.u) + 0.5 * (fr - fl),
        rho_l: sl.density_behind(p),
        rho_r: sr.density_behind(p),
    }
}

fn star_pressure(sl: &Side, sr: &Side) -> Result<f64, RiemannError> {
    let du = sr.u - sl.u;
    let residual = |p: f64| {
        let (fl, dfl) = sl.f(p);
        let (fr, dfr) = sr.f(p);
        (fl + fr + du, dfl + dfr)
    };
    // Acoustic (impedance-weighted) first guess.
    let (zl, zr) = (sl.rho * sl.c, sr.rho * sr.c);
    let guess = (zr * sl.p + zl * sr.p - zl * zr * du) / (zl + zr);
    let p_floor = sl.p_floor().max(sr.p_floor());
    solve_increasing(residual, p_floor, guess)
}

/// Root of an increasing, concave `g` on `(p_floor, ∞)` by bracketed Newton from `guess`.
/// `Vacuum` if `g(p_floor) >= 0`.
#[inline]
fn solve_increasing(
    g: impl Fn(f64) -> (f64, f64),
    p_floor: f64,
    guess: f64,
) -> Result<f64, RiemannError> {
    let (g_floor, _) = g(p_floor);
    if g_floor >= 0.0 {
        return Err(RiemannError::Vacuum { p_floor, gap: g_floor });
    }
    // Scale of the problem: distance from the floor.
    let mut lo = p_floor;
    let mut p =
        if guess > p_floor { guess } else { p_floor + 1e-3 * (guess - p_floor).abs().max(1.0) };
    let (mut r, mut dr) = g(p);
    let mut hi = f64::INFINITY;
    if r > 0.0 {
        hi = p;
    } else {
        lo = p;
    }
    for _ in 0..MAX_ITERATIONS {
        if r == 0.0 {
            return Ok(p);
        }
        let newton = p - r / dr;
        let tol = TOLERANCE * (p - p_floor);
        if (newton - p).abs() <= tol {
            // Quadratic convergence: this last step is below round-off of the next one.
            return Ok(newton);
        }
        p = if newton > lo && newton < hi && newton.is_finite() {
            newton
        } else if hi.is_finite() {
            0.5 * (lo + hi)
        } else {
            // No upper bound yet: double the distance from the floor.
            p_floor + 2.0 * (p - p_floor)
        };
        (r, dr) = g(p);
        if r > 0.0 {
            hi = p;
        } else {
            lo = p;
        }
        if hi - lo <= tol {
            return Ok(p);
        }
    }
    Err(RiemannError::NoConvergence { p, residual: r })
}

#[cfg(test)]
mod tests;
