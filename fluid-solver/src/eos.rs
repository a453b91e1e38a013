//! Equations of state (thesis §2.1.2, Eq. 2.6-2.9): perfect gas, stiffened gas and the Tait
//! barotropic liquid.
//!
//! State conventions shared by the whole solver: a primitive state is `[ρ, u, v, w, p]`, a
//! conserved state `[ρ, ρu, ρv, ρw, E]` with `E = ρe + ρ|u|²/2`.
//!
//! All three laws share one sound-speed form, `c² = g (p + π) / ρ`, with
//! `(g, π) = (γ, 0)` for a perfect gas, `(γ, p_c)` for a stiffened gas and `(β, α - p0)` for Tait
//! (its pressure law is the isentrope `p + α - p0 = α (ρ/ρ0)^β`). [`Eos::stiffness`] returns that
//! pair; the Riemann solver and the Roe average build on it.
//!
//! Tait is barotropic: `p = p(ρ)`, and the energy equation does not feed back. `E` is still
//! carried, with the isentropic internal energy `e(ρ) = ∫_{ρ0}^{ρ} p(r)/r² dr` (closed form in
//! [`Eos::internal_energy`]), so that smooth flow conserves it exactly and a Tait node stores the
//! same five conserved variables as a gas node.

use serde::Deserialize;

/// Pressure below which Tait water is said to cavitate (absolute zero: the model carries no
/// tension). Densities below `ρ_cav = ρ0 (1 - p0/α)^(1/β)` are rejected by [`Eos::check`].
pub const TAIT_CAVITATION_PRESSURE: f64 = 0.0;

/// An equation of state with its parameters; `Copy` and matched inline in the edge loop.
///
/// Deserialises from the case-file description [`EosSpec`] (validated).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(try_from = "EosSpec")]
pub enum Eos {
    /// `p = (γ - 1) ρ e` (thesis Eq. 2.6).
    PerfectGas { gamma: f64 },
    /// `p = (γ - 1) ρ e - γ p_c` (thesis Eq. 2.7).
    StiffenedGas { gamma: f64, p_c: f64 },
    /// `p = p0 + α ((ρ/ρ0)^β - 1)` (thesis Eq. 2.8-2.9), `α = p0 + k1/k2`, `β = k2`.
    Tait { p0: f64, rho0: f64, alpha: f64, beta: f64 },
}

/// The case-file description of an EOS (a table with a `kind` key), e.g.
/// `{ kind = "stiffened_gas", gamma = 7.15, p_c = 2.89e8 }` or
/// `{ kind = "tait", k1 = 2.07e9, k2 = 7.15, rho0 = 1000.0, p0 = 1e5 }`.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(
    tag = "kind",
    rename_all = "snake_case",
    deny_unknown_fields,
    expecting = "an EOS table with a `kind` key, e.g. { kind = \"perfect_gas\", gamma = 1.4 }"
)]
pub enum EosSpec {
    PerfectGas {
        gamma: f64,
    },
    StiffenedGas {
        gamma: f64,
        p_c: f64,
    },
    /// Bulk modulus `K = k1 + k2 p` fitted around the reference state `(ρ0, p0)`.
    Tait {
        k1: f64,
        k2: f64,
        rho0: f64,
        p0: f64,
    },
}

/// A parameter set that defines no valid EOS.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("invalid equation of state: {field} = {value}, expected {expected}")]
pub struct EosParamError {
    pub field: &'static str,
    pub value: f64,
    pub expected: &'static str,
}

/// A state outside the domain of its EOS, with the offending values.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum StateError {
    #[error("non-positive or non-finite density {rho}")]
    Density { rho: f64 },
    #[error("non-finite velocity ({u}, {v}, {w})")]
    Velocity { u: f64, v: f64, w: f64 },
    #[error("pressure {p} at or below the EOS limit {p_min} (density {rho})")]
    Pressure { rho: f64, p: f64, p_min: f64 },
    #[error("Tait liquid cavitates: density {rho} below {rho_cav} (pressure {p} < {p_cav})")]
    Cavitation { rho: f64, rho_cav: f64, p: f64, p_cav: f64 },
    #[error(
        "the Tait pressure follows from the density: ρ = {rho} gives p = {p_of_rho:e}, not {p:e}"
    )]
    Barotropic { rho: f64, p: f64, p_of_rho: f64 },
    #[error("its conserved form [ρ, ρu, ρv, ρw, E] = {cons:?} is not finite (overflow)")]
    Overflow { cons: [f64; 5] },
}

/// Relative mismatch between a given Tait pressure and `p(ρ)` that [`Eos::check_input`] accepts.
const BAROTROPIC_TOLERANCE: f64 = 1e-6;

impl TryFrom<EosSpec> for Eos {
    type Error = EosParamError;

    fn try_from(spec: EosSpec) -> Result<Eos, EosParamError> {
        let need = |ok: bool, field: &'static str, value: f64, expected: &'static str| {
            if ok && value.is_finite() {
                Ok(())
            } else {
                Err(EosParamError { field, value, expected })
            }
        };
        match spec {
            EosSpec::PerfectGas { gamma } => {
                need(gamma > 1.0, "gamma", gamma, "a finite number > 1")?;
                Ok(Eos::PerfectGas { gamma })
            }
            EosSpec::StiffenedGas { gamma, p_c } => {
                need(gamma > 1.0, "gamma", gamma, "a finite number > 1")?;
                need(p_c >= 0.0, "p_c", p_c, "a finite number >= 0")?;
                Ok(Eos::StiffenedGas { gamma, p_c })
            }
            EosSpec::Tait { k1, k2, rho0, p0 } => {
                need(k1 > 0.0, "k1", k1, "a finite bulk modulus > 0")?;
                need(k2 > 1.0, "k2", k2, "a finite number > 1")?;
                need(rho0 > 0.0, "rho0", rho0, "a finite density > 0")?;
                need(p0 + k1 / k2 > 0.0, "p0", p0, "a finite pressure > -k1/k2")?;
                Ok(Eos::tait(k1, k2, rho0, p0))
            }
        }
    }
}

impl Eos {
    /// Tait liquid from the bulk-modulus fit `K = k1 + k2 p` around `(ρ0, p0)` (thesis Eq. 2.9).
    pub fn tait(k1: f64, k2: f64, rho0: f64, p0: f64) -> Eos {
        Eos::Tait { p0, rho0, alpha: p0 + k1 / k2, beta: k2 }
    }

    /// `(g, π)` with `c² = g (p + π) / ρ` (see the module docs).
    #[inline(always)]
    pub fn stiffness(&self) -> (f64, f64) {
        match *self {
            Eos::PerfectGas { gamma } => (gamma, 0.0),
            Eos::StiffenedGas { gamma, p_c } => (gamma, p_c),
            Eos::Tait { p0, alpha, beta, .. } => (beta, alpha - p0),
        }
    }

    /// True for Tait: the pressure depends on the density only.
    #[inline(always)]
    pub fn is_barotropic(&self) -> bool {
        matches!(self, Eos::Tait { .. })
    }

    /// Pressure from density and specific internal energy (Tait ignores `e`).
    #[inline(always)]
    pub fn pressure(&self, rho: f64, e: f64) -> f64 {
        match *self {
            Eos::PerfectGas { gamma } => (gamma - 1.0) * rho * e,
            Eos::StiffenedGas { gamma, p_c } => (gamma - 1.0) * rho * e - gamma * p_c,
            Eos::Tait { .. } => self.tait_pressure(rho),
        }
    }

    /// Specific internal energy from density and pressure (Tait: `e(ρ)`, ignores `p`).
    #[inline(always)]
    pub fn internal_energy(&self, rho: f64, p: f64) -> f64 {
        match *self {
            Eos::PerfectGas { gamma } => p / ((gamma - 1.0) * rho),
            Eos::StiffenedGas { gamma, p_c } => (p + gamma * p_c) / ((gamma - 1.0) * rho),
            Eos::Tait { p0, rho0, alpha, beta } => {
                // ∫_{ρ0}^{ρ} (p0 - α + α (r/ρ0)^β) / r² dr.
                (p0 - alpha) * (1.0 / rho0 - 1.0 / rho)
                    + alpha / (rho0 * (beta - 1.0)) * ((rho / rho0).powf(beta - 1.0) - 1.0)
            }
        }
    }

    /// Squared sound speed `c² = g (p + π) / ρ`; for Tait `p` must be `p(ρ)`.
    #[inline(always)]
    pub fn sound_speed_sq(&self, rho: f64, p: f64) -> f64 {
        let (g, pi) = self.stiffness();
        g * (p + pi) / rho
    }

    /// Sound speed.
    #[inline(always)]
    pub fn sound_speed(&self, rho: f64, p: f64) -> f64 {
        self.sound_speed_sq(rho, p).sqrt()
    }

    /// Tait pressure `p0 + α((ρ/ρ0)^β - 1)`; for a gas, NaN.
    #[inline(always)]
    pub fn tait_pressure(&self, rho: f64) -> f64 {
        match *self {
            Eos::Tait { p0, rho0, alpha, beta } => p0 + alpha * ((rho / rho0).powf(beta) - 1.0),
            _ => f64::NAN,
        }
    }

    /// Tait density at pressure `p` (inverse of [`Eos::tait_pressure`]); for a gas, NaN.
    #[inline(always)]
    pub fn tait_density(&self, p: f64) -> f64 {
        match *self {
            Eos::Tait { p0, rho0, alpha, beta } => rho0 * ((p - p0) / alpha + 1.0).powf(1.0 / beta),
            _ => f64::NAN,
        }
    }

    /// Lowest admissible pressure: the state must satisfy `p > p_min` (gas) or `p >= p_min`
    /// (Tait, cavitation at [`TAIT_CAVITATION_PRESSURE`]).
    #[inline(always)]
    pub fn min_pressure(&self) -> f64 {
        match *self {
            Eos::PerfectGas { .. } => 0.0,
            Eos::StiffenedGas { p_c, .. } => -p_c,
            Eos::Tait { .. } => TAIT_CAVITATION_PRESSURE,
        }
    }

    /// Conserved `[ρ, ρu, ρv, ρw, E]` from primitive `[ρ, u, v, w, p]`.
    #[inline(always)]
    pub fn prim_to_cons(&self, w: &[f64; 5]) -> [f64; 5] {
        let [rho, u, v, wz, p] = *w;
        let e = self.internal_energy(rho, p);
        [rho, rho * u, rho * v, rho * wz, rho * e + 0.5 * rho * (u * u + v * v + wz * wz)]
    }

    /// Primitive `[ρ, u, v, w, p]` from conserved `[ρ, ρu, ρv, ρw, E]` (Tait: `p = p(ρ)`).
    #[inline(always)]
    pub fn cons_to_prim(&self, q: &[f64; 5]) -> [f64; 5] {
        let rho = q[0];
        let inv = 1.0 / rho;
        let (u, v, w) = (q[1] * inv, q[2] * inv, q[3] * inv);
        let e = q[4] * inv - 0.5 * (u * u + v * v + w * w);
        [rho, u, v, w, self.pressure(rho, e)]
    }

    /// The nodal cavitation cut-off (DESIGN §5.1): a node whose pressure lies below `p_cut` is
    /// set to `p_cut` at fixed density and velocity (its energy recomputed); returns whether it
    /// was. A barotropic liquid has no pressure to set at fixed density (`p = p(ρ)`), and since
    /// `p(ρ)` increases, `p >= p_cut` is `ρ >= ρ_cut = ρ(p_cut)`: the cut-off is a density floor,
    /// the node set to `ρ_cut` at fixed velocity, the state the Riemann cut-off gives on a Tait
    /// wave curve at `p_cut` ([`crate::riemann::PressureCutoff`]). That adds mass
    /// `(ρ_cut - ρ)|C_i|`, which the caller counts with the clip. A cut-off at or below the lowest
    /// pressure of the EOS, or a state with a non-positive or non-finite density, is left alone
    /// (for [`Eos::check`] to report).
    pub fn cut_off(&self, q: &mut [f64; 5], p_cut: f64) -> bool {
        let rho = q[0];
        let acts = if self.is_barotropic() {
            p_cut >= self.min_pressure()
        } else {
            p_cut > self.min_pressure()
        };
        if !(acts && rho > 0.0 && rho.is_finite()) {
            return false;
        }
        let mut w = self.cons_to_prim(q);
        if self.is_barotropic() {
            let rho_cut = self.tait_density(p_cut);
            // Not below the floor, or no comparable floor (NaN): nothing to clip.
            if rho.partial_cmp(&rho_cut) != Some(std::cmp::Ordering::Less) {
                return false;
            }
            w[0] = rho_cut;
            w[4] = p_cut;
        } else {
            if w[4].partial_cmp(&p_cut) != Some(std::cmp::Ordering::Less) {
                return false;
            }
            w[4] = p_cut;
        }
        *q = self.prim_to_cons(&w);
        true
    }

    /// Checks a primitive state against the domain of the EOS.
    pub fn check(&self, w: &[f64; 5]) -> Result<(), StateError> {
        let [rho, u, v, wz, p] = *w;
        if !(rho > 0.0 && rho.is_finite()) {
            return Err(StateError::Density { rho });
        }
        if !(u.is_finite() && v.is_finite() && wz.is_finite()) {
            return Err(StateError::Velocity { u, v, w: wz });
        }
        match *self {
            Eos::Tait { .. } => {
                let p_cav = TAIT_CAVITATION_PRESSURE;
                let rho_cav = self.tait_density(p_cav);
                if !(rho >= rho_cav && p >= p_cav) {
                    return Err(StateError::Cavitation { rho, rho_cav, p, p_cav });
                }
            }
            _ => {
                let p_min = self.min_pressure();
                if !(p > p_min && p.is_finite()) {
                    return Err(StateError::Pressure { rho, p, p_min });
                }
            }
        }
        Ok(())
    }

    /// Checks a state given as input (a case's initial or boundary state): [`Eos::check`], then
    /// for a barotropic EOS that `p` is the pressure of `ρ` (the solver would silently use
    /// `p(ρ)` instead), and that the conserved form does not overflow.
    pub fn check_input(&self, w: &[f64; 5]) -> Result<(), StateError> {
        self.check(w)?;
        let [rho, .., p] = *w;
        if self.is_barotropic() {
            let p_of_rho = self.tait_pressure(rho);
            let scale = p.abs().max(p_of_rho.abs()).max(self.stiffness().1);
            if (p - p_of_rho).abs() > BAROTROPIC_TOLERANCE * scale {
                return Err(StateError::Barotropic { rho, p, p_of_rho });
            }
        }
        let cons = self.prim_to_cons(w);
        if cons.iter().any(|q| !q.is_finite()) {
            return Err(StateError::Overflow { cons });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn eoses() -> [Eos; 3] {
        [
            Eos::PerfectGas { gamma: 1.4 },
            Eos::StiffenedGas { gamma: 7.15, p_c: 2.89e8 },
            Eos::tait(2.07e9, 7.15, 1000.0, 1e5),
        ]
    }

    fn sample_state(eos: &Eos) -> [f64; 5] {
        match eos {
            Eos::PerfectGas { .. } => [1.3, 12.0, -3.0, 4.5, 1.2e5],
            Eos::StiffenedGas { .. } => [1010.0, -2.0, 1.0, 0.5, 3e7],
            Eos::Tait { .. } => {
                let rho = 1003.0;
                [rho, 1.5, -0.2, 0.3, eos.tait_pressure(rho)]
            }
        }
    }

    #[test]
    fn prim_cons_round_trip() {
        for eos in eoses() {
            let w = sample_state(&eos);
            let back = eos.cons_to_prim(&eos.prim_to_cons(&w));
            for k in 0..5 {
                assert!((back[k] - w[k]).abs() <= 1e-12 * w[k].abs().max(1.0), "{eos:?} {k}");
            }
        }
    }

    #[test]
    fn pressure_inverts_internal_energy() {
        for eos in eoses() {
            let [rho, .., p] = sample_state(&eos);
            let e = eos.internal_energy(rho, p);
            assert!((eos.pressure(rho, e) - p).abs() <= 1e-12 * p.abs(), "{eos:?}");
        }
    }

    /// c² = ∂p/∂ρ at constant entropy: checked by a central difference along the isentrope
    /// `de = p/ρ² dρ` (for Tait along its pressure law).
    #[test]
    fn sound_speed_is_isentropic_derivative() {
        for eos in eoses() {
            let [rho, .., p] = sample_state(&eos);
            let e = eos.internal_energy(rho, p);
            let h = 1e-5 * rho;
            let pp = eos.pressure(rho + h, e + p / (rho * rho) * h);
            let pm = eos.pressure(rho - h, e - p / (rho * rho) * h);
            let fd = (pp - pm) / (2.0 * h);
            let c2 = eos.sound_speed_sq(rho, p);
            assert!((fd - c2).abs() <= 1e-6 * c2, "{eos:?}: {fd} vs {c2}");
        }
    }

    /// Tait: e(ρ) is the isentropic energy, de/dρ = p/ρ², and the bulk modulus is k1 + k2 p.
    #[test]
    fn tait_energy_and_bulk_modulus() {
        let (k1, k2) = (2.07e9, 7.15);
        let eos = Eos::tait(k1, k2, 1000.0, 1e5);
        for rho in [995.0, 1000.0, 1020.0, 1100.0] {
            let h = 1e-4;
            let de =
                (eos.internal_energy(rho + h, 0.0) - eos.internal_energy(rho - h, 0.0)) / (2.0 * h);
            let p = eos.tait_pressure(rho);
            assert!((de - p / (rho * rho)).abs() <= 1e-6 * (p / (rho * rho)).abs().max(1e-3));
            let k = rho * eos.sound_speed_sq(rho, p);
            assert!((k - (k1 + k2 * p)).abs() <= 1e-9 * k);
            assert!((eos.tait_density(p) - rho).abs() <= 1e-12 * rho);
        }
        assert_eq!(eos.internal_energy(1000.0, 0.0), 0.0);
    }

    #[test]
    fn check_reports_values() {
        let gas = Eos::PerfectGas { gamma: 1.4 };
        assert_eq!(gas.check(&[1.0, 0.0, 0.0, 0.0, 1.0]), Ok(()));
        assert_eq!(gas.check(&[-1.0, 0.0, 0.0, 0.0, 1.0]), Err(StateError::Density { rho: -1.0 }));
        assert_eq!(
            gas.check(&[1.0, 0.0, 0.0, 0.0, 0.0]),
            Err(StateError::Pressure { rho: 1.0, p: 0.0, p_min: 0.0 })
        );
        let sg = Eos::StiffenedGas { gamma: 7.15, p_c: 2.89e8 };
        assert!(sg.check(&[1000.0, 0.0, 0.0, 0.0, -1e8]).is_ok());
        assert!(matches!(
            sg.check(&[1000.0, 0.0, 0.0, 0.0, -3e8]),
            Err(StateError::Pressure { .. })
        ));
        let tait = Eos::tait(2.07e9, 7.15, 1000.0, 1e5);
        let rho = 999.0;
        match tait.check(&[rho, 0.0, 0.0, 0.0, tait.tait_pressure(rho)]) {
            Err(StateError::Cavitation { rho_cav, p, .. }) => {
                assert!(rho_cav > 999.9 && rho_cav < 1000.0 && p < 0.0)
            }
            other => panic!("expected cavitation, got {other:?}"),
        }
        assert!(gas.check(&[1.0, f64::NAN, 0.0, 0.0, 1.0]).is_err());
    }

    /// The nodal cut-off: a gas keeps its density and velocity and takes `p_cut`; Tait takes
    /// `ρ(p_cut)` at its velocity (a density floor); states above the cut-off, and cut-offs
    /// below the EOS's lowest pressure, are untouched.
    #[test]
    fn the_cut_off_sets_the_pressure_at_fixed_density_or_the_tait_density_floor() {
        let p_cut = 2339.0;
        for eos in eoses() {
            let above = sample_state(&eos);
            let mut q = eos.prim_to_cons(&above);
            let before = q;
            assert!(!eos.cut_off(&mut q, p_cut), "{eos:?}");
            assert_eq!(q, before);
            let low = match eos {
                Eos::Tait { .. } => {
                    let rho = 0.999 * eos.tait_density(0.0);
                    [rho, 3.0, -1.0, 0.5, eos.tait_pressure(rho)]
                }
                Eos::PerfectGas { .. } => [1.2, 3.0, -1.0, 0.5, 100.0],
                Eos::StiffenedGas { .. } => [1000.0, 3.0, -1.0, 0.5, -1e7],
            };
            let mut q = eos.prim_to_cons(&low);
            assert!(eos.cut_off(&mut q, p_cut), "{eos:?}");
            let w = eos.cons_to_prim(&q);
            let rho = if eos.is_barotropic() { eos.tait_density(p_cut) } else { low[0] };
            assert!((w[0] - rho).abs() <= 1e-14 * rho, "{eos:?}: {w:?}");
            assert!(eos.is_barotropic() || w[0] == low[0]);
            for k in 1..4 {
                assert!((w[k] - low[k]).abs() <= 1e-12, "{eos:?}: velocity {w:?}");
            }
            assert!((w[4] - p_cut).abs() <= 1e-9 * eos.stiffness().1.max(p_cut), "{eos:?} {w:?}");
            assert_eq!(eos.check(&w), Ok(()));
            // Off (the default of a perfect gas), or below the EOS's own limit: untouched.
            let mut q = eos.prim_to_cons(&low);
            assert!(!eos.cut_off(&mut q, f64::NEG_INFINITY) && q == eos.prim_to_cons(&low));
        }
        let gas = Eos::PerfectGas { gamma: 1.4 };
        let mut q = gas.prim_to_cons(&[1.2, 0.0, 0.0, 0.0, 100.0]);
        assert!(!gas.cut_off(&mut q, -5.0));
    }

    #[test]
    fn input_states_must_mean_what_they_say() {
        let tait = Eos::tait(2.07e9, 7.15, 1000.0, 1e5);
        assert_eq!(tait.check_input(&[1000.0, 0.0, 0.0, 0.0, 1e5]), Ok(()));
        let p = tait.tait_pressure(1100.0);
        assert_eq!(tait.check_input(&[1100.0, 1.0, 0.0, 0.0, p]), Ok(()));
        // A pressure the density does not give would be replaced by p(ρ) without a word.
        let e = tait.check_input(&[1000.0, 0.0, 0.0, 0.0, 5e5]).unwrap_err();
        assert!(matches!(e, StateError::Barotropic { p_of_rho, .. } if p_of_rho == 1e5), "{e}");
        assert!(e.to_string().contains("gives p = 1e5, not 5e5"), "{e}");
        // A speed whose kinetic energy overflows passes `check` but not `check_input`.
        let gas = Eos::PerfectGas { gamma: 1.4 };
        let fast = [1.0, 1e200, 0.0, 0.0, 1.0];
        assert_eq!(gas.check(&fast), Ok(()));
        assert!(matches!(gas.check_input(&fast), Err(StateError::Overflow { .. })));
        assert_eq!(
            gas.check_input(&[1.0, 0.0, 0.0, 0.0, 0.0]),
            gas.check(&[1.0, 0.0, 0.0, 0.0, 0.0])
        );
    }

    #[test]
    fn deserialises_and_validates() {
        let parse = |s: &str| serde_json::from_str::<Eos>(s);
        let tait = r#"{"kind": "tait", "k1": 2.07e9, "k2": 7.15, "rho0": 1000.0, "p0": 1e5}"#;
        assert_eq!(parse(tait).unwrap(), Eos::tait(2.07e9, 7.15, 1000.0, 1e5));
        let sg = r#"{"kind": "stiffened_gas", "gamma": 7.15, "p_c": 2.89e8}"#;
        assert_eq!(parse(sg).unwrap(), Eos::StiffenedGas { gamma: 7.15, p_c: 2.89e8 });
        let err = parse(r#"{"kind": "perfect_gas", "gamma": 0.9}"#).unwrap_err();
        assert!(err.to_string().contains("gamma = 0.9"), "{err}");
        let err = parse(r#"{"kind": "perfect_gas", "gama": 1.4}"#).unwrap_err();
        assert!(err.to_string().contains("gama"), "{err}");
    }
}
