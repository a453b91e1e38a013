//! Wave curves `u* = u_K ∓ f_K(p*)` of one side of a Riemann problem (Toro §4.2-4.3 for gases,
//! written with `p̂ = p + π` so stiffened gas follows; thesis App. A for Tait).
//!
//! Rarefactions follow the isentrope `p̂ ∝ ρ^g`, for which the Riemann invariant
//! `u ± 2c/(g - 1)` is the closed form of `∫ c/ρ dρ` (for Tait `(g, π) = (β, α - p0)` makes its
//! pressure law exactly this isentrope, thesis Eq. A.25). Shocks use the full Rankine-Hugoniot
//! relations for a gas and the mass and momentum relations only for the barotropic Tait liquid
//! (thesis Eq. A.30-A.31): `f = sqrt((p - p_K)(1/ρ_K - 1/ρ(p)))`.

use crate::eos::Eos;

/// One side of a Riemann problem: the EOS constants and the initial state.
#[derive(Debug, Clone, Copy)]
pub(super) struct Side {
    /// `g` and `π` of `c² = g (p + π) / ρ`.
    g: f64,
    pub(super) pi: f64,
    barotropic: bool,
    pub(super) rho: f64,
    pub(super) u: f64,
    pub(super) p: f64,
    pub(super) c: f64,
}

impl Side {
    /// For Tait the pressure must be `p(ρ)` (the node update and the reconstruction keep it so).
    #[inline]
    pub(super) fn new(eos: &Eos, rho: f64, u: f64, p: f64) -> Side {
        let (g, pi) = eos.stiffness();
        debug_assert!(
            !eos.is_barotropic() || (eos.tait_pressure(rho) - p).abs() <= 1e-9 * (p + pi),
            "Tait state off its pressure law: rho {rho}, p {p}"
        );
        Side { g, pi, barotropic: eos.is_barotropic(), rho, u, p, c: eos.sound_speed(rho, p) }
    }

    /// Lowest pressure of the wave curve (`ρ → 0` along the rarefaction).
    #[inline]
    pub(super) fn p_floor(&self) -> f64 {
        -self.pi
    }

    /// `(f_K(p), f_K'(p))`: the velocity jump across the wave that takes `p_K` to `p`.
    #[inline]
    pub(super) fn f(&self, p: f64) -> (f64, f64) {
        let g = self.g;
        let ph_k = self.p + self.pi;
        let dp = p - self.p;
        if dp <= 0.0 {
            // Rarefaction: f = 2c/(g-1) ((p̂/p̂_K)^((g-1)/2g) - 1), written with expm1/ln1p.
            let ln_ratio = ln_ratio(p + self.pi, dp, ph_k);
            let f = 2.0 * self.c / (g - 1.0) * ((g - 1.0) / (2.0 * g) * ln_ratio).exp_m1();
            let df = (-(g + 1.0) / (2.0 * g) * ln_ratio).exp() / (self.rho * self.c);
            (f, df)
        } else if self.barotropic {
            // Mass + momentum jump: f² = (p - p_K)(1/ρ_K - 1/ρ), ρ on the isentrope.
            let dv = -(-ln_ratio(p + self.pi, dp, ph_k) / g).exp_m1() / self.rho;
            let f = (dp * dv).sqrt();
            let rho = self.density_behind(p);
            let dv_dp = 1.0 / (rho * g * (p + self.pi));
            (f, (dv + dp * dv_dp) / (2.0 * f))
        } else {
            // Toro Eq. 4.21 with p̂: A = 2/((g+1)ρ_K), B = (g-1)/(g+1) p̂_K.
            let a = 2.0 / ((g + 1.0) * self.rho);
            let b = (g - 1.0) / (g + 1.0) * ph_k;
            let s = (a / (p + self.pi + b)).sqrt();
            (dp * s, s * (1.0 - 0.5 * dp / (p + self.pi + b)))
        }
    }

    /// The pressure `p*` of `f_K(p*) = du` in closed form where there is one, the one-sided
    /// (wall) problem's root: along the rarefaction (`du < 0`, every EOS),
    /// `p̂* = p̂_K (1 + (g-1) du/(2c))^(2g/(g-1))` (as `p_K + p̂_K expm1(..)` when weak), a vacuum
    /// when the base is not positive (`du <= -2c/(g-1)`, the escape speed); across a gas shock
    /// (`du > 0`), the positive root of Toro's Eq. 4.21 squared, the quadratic
    /// `A Δp² - du² Δp - du² (p̂_K + B) = 0`. `None` for a Tait shock, whose root is Newton's.
    #[inline]
    pub(super) fn root(&self, du: f64) -> Option<Result<f64, super::RiemannError>> {
        let g = self.g;
        let ph_k = self.p + self.pi;
        if du <= 0.0 {
            let base = (g - 1.0) / (2.0 * self.c) * du;
            if base <= -1.0 {
                let gap = -2.0 * self.c / (g - 1.0) - du;
                return Some(Err(super::RiemannError::Vacuum { p_floor: self.p_floor(), gap }));
            }
            // Weak: p_K + p̂_K expm1(..) keeps the digits of p* - p_K; strong: p̂* itself.
            let ln_ratio = 2.0 * g / (g - 1.0) * base.ln_1p();
            Some(Ok(if ln_ratio > -0.5 {
                self.p + ph_k * ln_ratio.exp_m1()
            } else {
                ph_k * ln_ratio.exp() - self.pi
            }))
        } else if self.barotropic {
            None
        } else {
            let a = 2.0 / ((g + 1.0) * self.rho);
            let b = (g - 1.0) / (g + 1.0) * ph_k;
            Some(Ok(self.p + du * (du + (du * du + 4.0 * a * (ph_k + b)).sqrt()) / (2.0 * a)))
        }
    }

    /// Density behind the wave that takes `p_K` to `p`.
    #[inline]
    pub(super) fn density_behind(&self, p: f64) -> f64 {
        let g = self.g;
        let ratio = (p + self.pi) / (self.p + self.pi);
        if p <= self.p || self.barotropic {
            self.rho * ratio.powf(1.0 / g)
        } else {
            let mu = (g - 1.0) / (g + 1.0);
            self.rho * (ratio + mu) / (mu * ratio + 1.0)
        }
    }

    /// Mass flux `ρ_K |u_K - S|` through a shock to `p > p_K` (`ρ_K c_K` in the acoustic limit).
    #[inline]
    pub(super) fn shock_mass_flux(&self, p: f64) -> f64 {
        let dp = p - self.p;
        if self.barotropic {
            let (f, _) = self.f(p);
            if f > 0.0 {
                dp / f
            } else {
                self.rho * self.c
            }
        } else {
            let g = self.g;
            let ph = p + self.pi;
            let ph_k = self.p + self.pi;
            (0.5 * self.rho * ((g + 1.0) * ph + (g - 1.0) * ph_k)).sqrt()
        }
    }

    /// Sound speed at pressure `p` and density `rho` on this side's EOS.
    #[inline]
    pub(super) fn sound_speed(&self, rho: f64, p: f64) -> f64 {
        (self.g * (p + self.pi) / rho).sqrt()
    }

    /// State `(ρ, u, p)` inside a rarefaction fan at `ξ = x/t`; `dir = -1` for a left-facing fan,
    /// `+1` for a right-facing one (Toro Eq. 4.56, 4.63 with `p̂`).
    #[inline]
    pub(super) fn fan(&self, xi: f64, dir: f64) -> (f64, f64, f64) {
        let g = self.g;
        let k = 2.0 / (g + 1.0);
        let c = k * (self.c - dir * 0.5 * (g - 1.0) * (self.u - xi));
        let u = k * (-dir * self.c + 0.5 * (g - 1.0) * self.u + xi);
        let ratio = c / self.c;
        let rho = self.rho * ratio.powf(2.0 / (g - 1.0));
        let p = (self.p + self.pi) * ratio.powf(2.0 * g / (g - 1.0)) - self.pi;
        (rho, u, p)
    }
}

/// `ln(p̂/p̂_K)` with `dp = p - p_K`: through `ln_1p` near 1 (weak waves), directly far from it
/// (where `1 + dp/p̂_K` would lose the digits of a small `p̂`).
#[inline(always)]
fn ln_ratio(ph: f64, dp: f64, ph_k: f64) -> f64 {
    if dp.abs() < 0.5 * ph_k {
        (dp / ph_k).ln_1p()
    } else {
        (ph / ph_k).ln()
    }
}
