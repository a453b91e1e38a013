//! The Keller-Miksis equation of a spherical gas bubble in a weakly compressible liquid
//! (Keller & Miksis, J. Acoust. Soc. Am. 68, 1980, Eq. 3.2, without surface tension and
//! viscosity):
//!
//! `(1 - Ṙ/c) R R̈ + 3/2 (1 - Ṙ/(3c)) Ṙ² = (1 + Ṙ/c) (p_g - p_∞)/ρ + R/(ρ c) dp_g/dt`,
//!
//! with the gas adiabatic and uniform, `p_g = p_g0 (R0/R)^(3γ)` (so `dp_g/dt = -3γ p_g Ṙ/R`),
//! the liquid's density `ρ` and sound speed `c` at the ambient pressure `p_∞`. With `c = ∞` it
//! is the Rayleigh-Plesset equation. Integrated by classical RK4 with the step bounded by a
//! fraction of `R/|Ṙ|`, so the step shrinks near a collapse.

/// A bubble and its liquid.
#[derive(Debug, Clone, Copy)]
pub struct Bubble {
    /// Initial radius (the bubble starts at rest).
    pub r0: f64,
    /// Initial gas pressure.
    pub p_g0: f64,
    /// The gas's ratio of specific heats.
    pub gamma: f64,
    /// Ambient liquid pressure.
    pub p_inf: f64,
    /// Liquid density.
    pub rho: f64,
    /// Liquid sound speed (`f64::INFINITY`: Rayleigh-Plesset).
    pub c: f64,
}

/// The first cycle of the radius: its first maximum and the first minimum after it.
#[derive(Debug, Clone, Copy)]
pub struct Cycle {
    pub t_max: f64,
    pub r_max: f64,
    pub t_min: f64,
    pub r_min: f64,
}

impl Bubble {
    /// `p_g(R)`.
    pub fn gas_pressure(&self, r: f64) -> f64 {
        self.p_g0 * (self.r0 / r).powf(3.0 * self.gamma)
    }

    /// `R̈` from the equation at `(R, Ṙ)`.
    pub fn acceleration(&self, r: f64, v: f64) -> f64 {
        let m = v / self.c;
        let p_g = self.gas_pressure(r);
        let dp_g = -3.0 * self.gamma * p_g * v / r;
        let rhs = (1.0 + m) * (p_g - self.p_inf) / self.rho + r / (self.rho * self.c) * dp_g;
        (rhs - 1.5 * (1.0 - m / 3.0) * v * v) / ((1.0 - m) * r)
    }

    /// One RK4 step of `(R, Ṙ)`.
    fn rk4(&self, y: [f64; 2], dt: f64) -> [f64; 2] {
        let f = |y: [f64; 2]| [y[1], self.acceleration(y[0], y[1])];
        let add = |y: [f64; 2], k: [f64; 2], h: f64| [y[0] + h * k[0], y[1] + h * k[1]];
        let k1 = f(y);
        let k2 = f(add(y, k1, 0.5 * dt));
        let k3 = f(add(y, k2, 0.5 * dt));
        let k4 = f(add(y, k3, dt));
        [
            y[0] + dt / 6.0 * (k1[0] + 2.0 * k2[0] + 2.0 * k3[0] + k4[0]),
            y[1] + dt / 6.0 * (k1[1] + 2.0 * k2[1] + 2.0 * k3[1] + k4[1]),
        ]
    }

    /// Integrates from `(R, Ṙ) = (r_start, v_start)` at `t = 0` with steps no longer than
    /// `dt_max` nor than `eta R/|Ṙ|`, until `stop(t, R, Ṙ, R_prev, Ṙ_prev)` says so; returns the
    /// samples `(t, R, Ṙ)` of every step.
    pub fn integrate(
        &self,
        r_start: f64,
        v_start: f64,
        dt_max: f64,
        eta: f64,
        mut stop: impl FnMut(f64, [f64; 2], [f64; 2]) -> bool,
    ) -> Vec<(f64, f64, f64)> {
        let mut t = 0.0;
        let mut y = [r_start, v_start];
        let mut out = vec![(t, y[0], y[1])];
        for _ in 0..100_000_000 {
            let dt = dt_max.min(eta * y[0] / y[1].abs().max(1e-300));
            let next = self.rk4(y, dt);
            t += dt;
            out.push((t, next[0], next[1]));
            if stop(t, next, y) {
                break;
            }
            y = next;
        }
        out
    }

    /// The first maximum and the following minimum of `R(t)` from rest at `R0`, with steps no
    /// longer than `dt_max`: each extremum where `Ṙ` changes sign, its time by linear
    /// interpolation of `Ṙ` within the step and its radius by the quadratic through that step.
    pub fn first_cycle(&self, dt_max: f64) -> Cycle {
        let mut found: Vec<(f64, f64)> = Vec::new();
        let mut t_prev = 0.0;
        self.integrate(self.r0, 0.0, dt_max, 1e-3, |t, y, prev| {
            let turned = match found.len() {
                0 => prev[1] > 0.0 && y[1] <= 0.0,
                _ => prev[1] < 0.0 && y[1] >= 0.0,
            };
            if turned {
                let s = prev[1] / (prev[1] - y[1]);
                let h = t - t_prev;
                // R on the step's quadratic through (R_prev, Ṙ_prev) with slope zero at s h.
                found.push((t_prev + s * h, prev[0] + 0.5 * prev[1] * s * h));
            }
            t_prev = t;
            found.len() == 2
        });
        assert_eq!(found.len(), 2, "no full cycle");
        Cycle { t_max: found[0].0, r_max: found[0].1, t_min: found[1].0, r_min: found[1].1 }
    }

    /// The Rayleigh-Plesset invariant (`c = ∞`): the liquid's kinetic energy, the work against
    /// the ambient pressure and the gas's internal energy, over `4π`:
    /// `ρR³Ṙ²/2 + p_∞R³/3 + p_g(R) R³/(3(γ-1))`.
    pub fn rayleigh_plesset_energy(&self, r: f64, v: f64) -> f64 {
        let r3 = r.powi(3);
        0.5 * self.rho * r3 * v * v
            + self.p_inf * r3 / 3.0
            + self.gas_pressure(r) * r3 / (3.0 * (self.gamma - 1.0))
    }
}

/// Rayleigh's collapse time of an empty cavity of radius `r` under `p_∞`:
/// `t_c = ξ r √(ρ/p_∞)`, `ξ = √(π/6) Γ(5/6)/Γ(4/3) = 0.914681...` (Rayleigh 1917).
pub const RAYLEIGH_FACTOR: f64 = 0.914_681_037;
