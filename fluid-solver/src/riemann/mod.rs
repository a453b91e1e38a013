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

pub use fluid_structure::{fluid_structure, WallState};
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

/// Solves the Riemann problem between `l` (EOS `eos_l`) and `r` (EOS `eos_r`) for its star state.
/// With `eos_l == eos_r` this is the single-material problem P1; otherwise the two-phase P2.
pub fn solve(eos_l: &Eos, l: State1d, eos_r: &Eos, r: State1d) -> Result<StarState, RiemannError> {
    let sl = Side::new(eos_l, l.rho, l.u, l.p);
    let sr = Side::new(eos_r, r.rho, r.u, r.p);
    let p = star_pressure(&sl, &sr)?;
    Ok(star_from_pressure(&sl, &sr, p))
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
