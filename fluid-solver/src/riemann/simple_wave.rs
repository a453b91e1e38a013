//! The exact simple wave driven into a perfect gas at rest by a piston on a prescribed path
//! `x_p(t)` (Courant & Friedrichs §§ 38-40; thesis §5.2.3.3, the harmonic body), valid until the
//! characteristics cross (a shock forms).
//!
//! The gas lies left of the piston (`x < x_p(t)`), at rest with sound speed `c0`. The forward
//! characteristics come from the undisturbed gas and carry `u + 2c/(γ-1) = 2c0/(γ-1)`, so
//! `c = c0 - (γ-1) u / 2` everywhere (a withdrawing piston, `u > 0`, rarefies). The backward
//! characteristics leave the piston: the one leaving at time `τ` carries `u = x_p'(τ)` and is the
//! straight line `x = x_p(τ) + (u - c)(t - τ)`, `u - c = (γ+1) u / 2 - c0`. The state follows isentropically:
//! `p = p0 (c/c0)^{2γ/(γ-1)}`, `ρ = ρ0 (c/c0)^{2/(γ-1)}`.

/// A piston path and the gas it moves.
pub struct SimpleWave<P> {
    /// `t -> (x_p(t), x_p'(t))`.
    pub piston: P,
    pub gamma: f64,
    pub rho0: f64,
    pub p0: f64,
}

impl<P: Fn(f64) -> (f64, f64)> SimpleWave<P> {
    /// `(ρ, u, p)` at `x <= x_p(t)` at time `t`, or `None` once a shock has formed anywhere (the
    /// backward characteristics have crossed by `t`).
    pub fn state(&self, x: f64, t: f64) -> Option<(f64, f64, f64)> {
        let g = self.gamma;
        let c0 = (g * self.p0 / self.rho0).sqrt();
        if x <= -c0 * t + (self.piston)(0.0).0 {
            // Not reached by the wave yet.
            return Some((self.rho0, 0.0, self.p0));
        }
        // The backward characteristic through (x, t) leaves the piston at τ: gap(τ) = 0, with
        // gap(0) < 0 < gap(t) for a point of the gas inside the wave.
        let gap = |tau: f64| {
            let (xp, u) = (self.piston)(tau);
            xp + (0.5 * (g + 1.0) * u - c0) * (t - tau) - x
        };
        // `gap + x` does not depend on x: the wave is smooth at t (one characteristic through
        // every point) exactly when it increases over [0, t]; checked on a fine grid.
        let n = 2000;
        if (0..n).any(|k| gap(t * (k + 1) as f64 / n as f64) <= gap(t * k as f64 / n as f64)) {
            return None;
        }
        let (mut lo, mut hi) = (0.0, t);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if gap(mid) < 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let tau = 0.5 * (lo + hi);
        let u = (self.piston)(tau).1;
        let c = c0 - 0.5 * (g - 1.0) * u;
        let r = c / c0;
        Some((self.rho0 * r.powf(2.0 / (g - 1.0)), u, self.p0 * r.powf(2.0 * g / (g - 1.0))))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eos::Eos;
    use crate::riemann::{RiemannSolution, State1d};

    /// A piston withdrawn at a constant speed (the gas is on its left) makes a centred
    /// rarefaction: ahead of its head and behind its tail (the fan itself issues from the single
    /// point τ = 0) the simple wave agrees with the exact one-sided Riemann solution.
    #[test]
    fn a_constant_withdrawal_gives_the_rarefaction_plateau() {
        let w = 20.0;
        let wave = SimpleWave { piston: |t: f64| (w * t, w), gamma: 1.4, rho0: 1.3, p0: 1e5 };
        let eos = Eos::PerfectGas { gamma: 1.4 };
        let exact = RiemannSolution::wall(&eos, State1d { rho: 1.3, u: 0.0, p: 1e5 }, w).unwrap();
        let (head, tail) = exact.left_wave();
        let t = 2e-3;
        let mut checked = 0;
        for k in 0..=100 {
            let x = -0.8 + (0.8 + w * t) * k as f64 / 100.0;
            if x / t > head && x / t < tail {
                continue;
            }
            let (rho, u, p) = wave.state(x, t).unwrap();
            let s = exact.sample(x / t);
            assert!((rho - s.rho).abs() < 1e-9 * s.rho, "x {x}: ρ {rho} vs {}", s.rho);
            assert!((u - s.u).abs() < 1e-8, "x {x}: u {u} vs {}", s.u);
            assert!((p - s.p).abs() < 1e-9 * s.p, "x {x}: p {p} vs {}", s.p);
            checked += 1;
        }
        assert!(checked > 50);
    }

    /// The harmonic body's wave solves the Euler equations: the mass and momentum residuals of
    /// central differences vanish at second order in the difference step.
    #[test]
    fn harmonic_wave_solves_the_euler_equations() {
        let (r, w) = (0.08, std::f64::consts::TAU * 100.0);
        let piston = move |t: f64| (r * (1.0 - (w * t).cos()), r * w * (w * t).sin());
        let wave = SimpleWave { piston, gamma: 1.4, rho0: 1.3, p0: 1e5 };
        let residual = |x: f64, t: f64, h: f64| {
            let s = |x: f64, t: f64| wave.state(x, t).unwrap();
            let ((rp, up, _), (rm, um, _)) = (s(x, t + h / 400.0), s(x, t - h / 400.0));
            let ((rr, ur, pr), (rl, ul, pl)) = (s(x + h, t), s(x - h, t));
            let (dt, dx) = (2.0 * h / 400.0, 2.0 * h);
            let mass = (rp - rm) / dt + (rr * ur - rl * ul) / dx;
            let momentum = (rp * up - rm * um) / dt + (rr * ur * ur + pr - rl * ul * ul - pl) / dx;
            (mass.abs() / (1.3 * 340.0), momentum.abs() / 1e5)
        };
        for x in [-2.5, -1.0, -0.3] {
            let (m1, q1) = residual(x, 0.008, 1e-2);
            let (m2, q2) = residual(x, 0.008, 5e-3);
            assert!(m2 < 1e-4 && q2 < 1e-4, "x {x}: {m2} {q2}");
            assert!(m1 / m2 > 3.0 && q1 / q2 > 3.0, "x {x}: {m1}/{m2}, {q1}/{q2}");
        }
    }

    /// The thesis' harmonic body: the piston's own pressure at the face follows from its speed,
    /// the wave is smooth at t = 0.01, and it has broken by t = 0.02.
    #[test]
    fn harmonic_body_wave() {
        let (r, w) = (0.08, std::f64::consts::TAU * 100.0);
        let piston = move |t: f64| (r * (1.0 - (w * t).cos()), r * w * (w * t).sin());
        let wave = SimpleWave { piston, gamma: 1.4, rho0: 1.3, p0: 1e5 };
        let t = 0.01;
        let (xp, up) = piston(t);
        let (_, u, p) = wave.state(xp - 1e-12, t).unwrap();
        let c0 = (1.4f64 * 1e5 / 1.3).sqrt();
        let c = c0 - 0.2 * up;
        assert!((u - up).abs() < 1e-6 && (p - 1e5 * (c / c0).powi(7)).abs() < 1e-3, "{u} {p}");
        assert!((-4.0..0.0).all_smooth(|x| wave.state(x, t).is_some()));
        assert!((-8.0..0.0).any_point(|x| wave.state(x, 0.02).is_none()));
    }

    trait Scan {
        fn all_smooth(self, f: impl Fn(f64) -> bool) -> bool;
        fn any_point(self, f: impl Fn(f64) -> bool) -> bool;
    }

    impl Scan for std::ops::Range<f64> {
        fn all_smooth(self, f: impl Fn(f64) -> bool) -> bool {
            (0..=400).all(|k| f(self.start + (self.end - self.start) * k as f64 / 400.0))
        }
        fn any_point(self, f: impl Fn(f64) -> bool) -> bool {
            (0..=400).any(|k| f(self.start + (self.end - self.start) * k as f64 / 400.0))
        }
    }
}
