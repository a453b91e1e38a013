//! Roe's approximate Riemann solver (Roe, J. Comput. Phys. 43, 1981) with Harten's entropy fix,
//! for all three EOS (thesis Eq. 3.4 uses it for every edge between nodes of one fluid).

use super::{flux_of, roe_average, unit, RoeAverage};
use crate::eos::Eos;

/// Harten's entropy-fix coefficient ε: an acoustic eigenvalue `λ` with `|λ| < δ`,
/// `δ = ε (|ũ_n| + c̃)`, is replaced by `(λ² + δ²) / (2δ)` (Harten, J. Comput. Phys. 49, 1983),
/// which removes expansion shocks at sonic points (checked by the test
/// `sonic_rarefaction_has_no_expansion_shock`). Contact and shear waves are not fixed, so a
/// stationary contact stays sharp.
pub const ENTROPY_FIX: f64 = 0.1;

/// Roe flux `½(f(W_l) + f(W_r))·n - ½ |Ã| (Q_r - Q_l) |n|`.
#[inline(always)]
pub fn roe(eos: &Eos, wl: &[f64; 5], wr: &[f64; 5], n: &[f64; 3]) -> [f64; 5] {
    let (nh, area) = unit(n);
    let ql = eos.prim_to_cons(wl);
    let qr = eos.prim_to_cons(wr);
    let avg = roe_average(eos, wl, &ql, wr, &qr);
    let delta = (avg.u[0] * nh[0] + avg.u[1] * nh[1] + avg.u[2] * nh[2]).abs() + avg.c;
    let diss = apply_roe_matrix(&avg, wl, &ql, wr, &qr, &nh, |lambda, acoustic| {
        let a = lambda.abs();
        let d = ENTROPY_FIX * delta;
        if acoustic && a < d {
            (lambda * lambda + d * d) / (2.0 * d)
        } else {
            a
        }
    });
    let fl = flux_of(wl, &ql, &nh);
    let fr = flux_of(wr, &qr, &nh);
    let mut f = [0.0; 5];
    for k in 0..5 {
        f[k] = 0.5 * area * (fl[k] + fr[k] - diss[k]);
    }
    f
}

/// `φ(Ã) ΔQ = Σ_k φ(λ_k) α_k r_k` for the Roe matrix `Ã` along the unit normal `n̂`.
///
/// The acoustic waves `λ = ũ_n ∓ c̃`, `r = (1, ũ ∓ c̃ n̂, H̃ ∓ ũ_n c̃)`,
/// `α = (Δp ∓ ρ̃ c̃ Δu_n) / (2 c̃²)` are the same for all three EOS; every other wave (contact,
/// shear, and for Tait the decoupled energy) moves at `ũ_n`, so their sum is
/// `ΔQ - α₁ r₁ - α₅ r₅` whatever its split:
/// `φ(Ã)ΔQ = φ(ũ_n) ΔQ + Σ_{acoustic} (φ(λ) - φ(ũ_n)) α r`.
/// `phi(λ, acoustic)` is told whether `λ` belongs to an acoustic wave.
#[inline(always)]
pub(super) fn apply_roe_matrix(
    avg: &RoeAverage,
    wl: &[f64; 5],
    ql: &[f64; 5],
    wr: &[f64; 5],
    qr: &[f64; 5],
    nh: &[f64; 3],
    phi: impl Fn(f64, bool) -> f64,
) -> [f64; 5] {
    let c = avg.c;
    let un = avg.u[0] * nh[0] + avg.u[1] * nh[1] + avg.u[2] * nh[2];
    let dun = (wr[1] - wl[1]) * nh[0] + (wr[2] - wl[2]) * nh[1] + (wr[3] - wl[3]) * nh[2];
    let dp = wr[4] - wl[4];
    let inv_2c2 = 0.5 / (c * c);
    let a1 = (dp - avg.rho * c * dun) * inv_2c2;
    let a5 = (dp + avg.rho * c * dun) * inv_2c2;
    let phi_u = phi(un, false);
    let k1 = (phi(un - c, true) - phi_u) * a1;
    let k5 = (phi(un + c, true) - phi_u) * a5;
    let mut out = [0.0; 5];
    for k in 0..5 {
        out[k] = phi_u * (qr[k] - ql[k]);
    }
    out[0] += k1 + k5;
    for d in 0..3 {
        out[1 + d] += k1 * (avg.u[d] - c * nh[d]) + k5 * (avg.u[d] + c * nh[d]);
    }
    out[4] += k1 * (avg.h - un * c) + k5 * (avg.h + un * c);
    out
}
