//! The full self-similar solution `W(x/t)` of a solved Riemann problem (Toro §4.5, thesis §2.4
//! steps 5-6), for shock-tube references.

use super::wave_curve::Side;
use super::{solve, star_from_pressure, star_pressure, RiemannError, StarState, State1d};
use crate::eos::Eos;

/// A solved Riemann problem, sampled with [`RiemannSolution::sample`].
#[derive(Debug, Clone, Copy)]
pub struct RiemannSolution {
    left: Side,
    right: Side,
    pub star: StarState,
}

/// The solution at one `ξ = x/t`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    pub rho: f64,
    pub u: f64,
    pub p: f64,
    /// True left of the contact (the left fluid and its EOS; tangential velocity from the left).
    pub left: bool,
}

impl RiemannSolution {
    /// Solves the problem (see [`solve`]).
    pub fn new(eos_l: &Eos, l: State1d, eos_r: &Eos, r: State1d) -> Result<Self, RiemannError> {
        let left = Side::new(eos_l, l.rho, l.u, l.p);
        let right = Side::new(eos_r, r.rho, r.u, r.p);
        let star = star_from_pressure(&left, &right, star_pressure(&left, &right)?);
        debug_assert_eq!(Ok(star), solve(eos_l, l, eos_r, r));
        Ok(RiemannSolution { left, right, star })
    }

    /// The full solution of the one-sided problem of
    /// [`fluid_structure`](super::fluid_structure()) (fluid `s` left of a wall moving at `w_n`,
    /// lab frame): App. A's mirror image, the state `(ρ, 2w_n - u, p)` on the right, makes the
    /// contact move with the wall; sample it only at `ξ <= w_n`. For fluid right of a wall, mirror
    /// the axis (`u -> -u`, `w_n -> -w_n`, `ξ -> -ξ`).
    pub fn wall(eos: &Eos, s: State1d, w_n: f64) -> Result<Self, RiemannError> {
        RiemannSolution::new(eos, s, eos, State1d { u: 2.0 * w_n - s.u, ..s })
    }

    /// Speeds `(head, tail)` of the left wave (equal for a shock).
    pub fn left_wave(&self) -> (f64, f64) {
        wave_speeds(&self.left, &self.star, self.star.rho_l, -1.0)
    }

    /// Speeds `(head, tail)` of the right wave (equal for a shock).
    pub fn right_wave(&self) -> (f64, f64) {
        wave_speeds(&self.right, &self.star, self.star.rho_r, 1.0)
    }

    /// The state at `ξ = x/t`.
    pub fn sample(&self, xi: f64) -> Sample {
        let s = &self.star;
        let left = xi <= s.u;
        let (side, rho_star, dir, wave) = if left {
            (&self.left, s.rho_l, -1.0, self.left_wave())
        } else {
            (&self.right, s.rho_r, 1.0, self.right_wave())
        };
        // Distance outward from the contact, positive beyond the wave head.
        let outward = |speed: f64| dir * (xi - speed);
        let (rho, u, p) = if outward(wave.0) >= 0.0 {
            (side.rho, side.u, side.p)
        } else if outward(wave.1) <= 0.0 {
            (rho_star, s.u, s.p)
        } else {
            side.fan(xi, dir)
        };
        Sample { rho, u, p, left }
    }
}

/// `(head, tail)` speeds of the wave facing `dir` (-1 left, +1 right) from `side` to the star.
fn wave_speeds(side: &Side, star: &StarState, rho_star: f64, dir: f64) -> (f64, f64) {
    if star.p > side.p {
        let s = side.u + dir * side.shock_mass_flux(star.p) / side.rho;
        (s, s)
    } else {
        let head = side.u + dir * side.c;
        let tail = star.u + dir * side.sound_speed(rho_star, star.p);
        (head, tail)
    }
}
