//! J2 (von Mises) plasticity with linear isotropic hardening, return maps and consistent
//! tangents (Simo & Hughes, *Computational Inelasticity*, 1998: §3.3 radial return, §3.4 the
//! plane-stress closest point projection of Simo & Taylor 1986).
//!
//! `h` is the **plastic modulus**: the yield stress is `κ(α) = σy + H α` in the equivalent plastic
//! strain `α`, so uniaxial stress is `σ = σy + H εp = σy + E H/(E+H) (ε - σy/E)` (DESIGN §6).
//!
//! Shells must use the plane-stress return: a 3D radial return applied to a plane-stress trial
//! leaves `σ_zz = 0` unenforced in the plastic flow and gets stress and plastic strain wrong.

use super::lanes::Real;
use super::Elastic;

const SQRT_2_3: f64 = 0.816_496_580_927_726;

/// Elastic part, initial yield stress `sigma_y`, plastic modulus `h`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct J2 {
    pub elastic: Elastic,
    pub sigma_y: f64,
    pub h: f64,
}

/// Result of the 3D radial return.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Return3d {
    pub sigma: [f64; 6],
    /// Equivalent plastic strain after the step.
    pub alpha: f64,
    /// Plastic multiplier `Δγ` (`Δεp = Δγ n`, tensor components).
    pub dgamma: f64,
    /// Unit deviatoric flow direction `n = s/|s|` (tensor components, Voigt order).
    pub n: [f64; 6],
    /// `|s_trial|`.
    pub s_trial_norm: f64,
}

/// Result of the plane-stress return.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlaneStressReturn<R = f64> {
    pub sigma: [R; 3],
    pub alpha: R,
    /// Plastic multiplier: `Δεp = Δγ P σ` (engineering shear).
    pub dgamma: R,
}

/// Tensor norm of a Voigt stress `|s| = sqrt(s:s)`.
fn norm_voigt(s: &[f64; 6]) -> f64 {
    (s[0] * s[0] + s[1] * s[1] + s[2] * s[2] + 2.0 * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5]))
        .sqrt()
}

impl J2 {
    /// Yield stress `κ(α) = σy + H α`.
    pub fn yield_stress(&self, alpha: f64) -> f64 {
        self.sigma_y + self.h * alpha
    }

    /// 3D radial return from a trial stress (Simo-Hughes Box 3.1).
    pub fn return_3d(&self, trial: &[f64; 6], alpha: f64) -> Return3d {
        let g = self.elastic.shear_modulus();
        let p = (trial[0] + trial[1] + trial[2]) / 3.0;
        let s = [trial[0] - p, trial[1] - p, trial[2] - p, trial[3], trial[4], trial[5]];
        let norm = norm_voigt(&s);
        let f = norm - SQRT_2_3 * self.yield_stress(alpha);
        let n = if norm > 0.0 { s.map(|v| v / norm) } else { [0.0; 6] };
        if f <= 0.0 {
            return Return3d { sigma: *trial, alpha, dgamma: 0.0, n, s_trial_norm: norm };
        }
        // Linear hardening: the consistency condition is linear in Δγ.
        let dgamma = f / (2.0 * g + 2.0 * self.h / 3.0);
        let mut sigma = *trial;
        for i in 0..6 {
            sigma[i] -= 2.0 * g * dgamma * n[i];
        }
        Return3d { sigma, alpha: alpha + SQRT_2_3 * dgamma, dgamma, n, s_trial_norm: norm }
    }

    /// Consistent tangent of the 3D radial return (Simo-Hughes Box 3.2), Voigt with
    /// engineering shear.
    pub fn tangent_3d(&self, r: &Return3d) -> [[f64; 6]; 6] {
        if r.dgamma == 0.0 {
            return self.elastic.tangent_3d();
        }
        let (k, g) = (self.elastic.bulk_modulus(), self.elastic.shear_modulus());
        let theta = 1.0 - 2.0 * g * r.dgamma / r.s_trial_norm;
        let theta_bar = 1.0 / (1.0 + self.h / (3.0 * g)) - (1.0 - theta);
        let mut c = [[0.0; 6]; 6];
        for i in 0..6 {
            for j in 0..6 {
                let dev = match (i < 3, j < 3) {
                    (true, true) => f64::from(u8::from(i == j)) - 1.0 / 3.0,
                    (false, false) if i == j => 0.5,
                    _ => 0.0,
                };
                let vol = if i < 3 && j < 3 { k } else { 0.0 };
                c[i][j] = vol + 2.0 * g * theta * dev - 2.0 * g * theta_bar * r.n[i] * r.n[j];
            }
        }
        c
    }

    /// Plane-stress closest point projection from a trial stress `[σxx, σyy, σxy]` (Simo-Taylor
    /// 1986; Simo-Hughes Box 3.3): see [`return_plane_stress_with`]; the constants of this
    /// material on every lane.
    #[inline(always)]
    pub fn return_plane_stress<R: Real>(
        &self,
        trial: [R; 3],
        alpha: R,
        max_newton: usize,
        tol: f64,
    ) -> PlaneStressReturn<R> {
        return_plane_stress_with(&self.plane_stress_constants(), trial, alpha, max_newton, tol)
    }

    /// The constants of the plane-stress return of this material, splat on every lane.
    #[inline(always)]
    pub fn plane_stress_constants<R: Real>(&self) -> PlaneStressConstants<R> {
        let g = self.elastic.shear_modulus();
        PlaneStressConstants {
            c1: R::splat(self.elastic.e / (3.0 * (1.0 - self.elastic.nu))),
            c2: R::splat(2.0 * g),
            h: R::splat(self.h),
            sigma_y: R::splat(self.sigma_y),
        }
    }
}

/// The material constants the plane-stress return reads, per lane (elements of a block may
/// have different materials): the eigenvalues `c1 = E / (3(1-ν))`, `c2 = 2G` of `C P`, the
/// plastic modulus and the initial yield stress.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlaneStressConstants<R> {
    pub c1: R,
    pub c2: R,
    pub h: R,
    pub sigma_y: R,
}

/// Updates of the safeguarded fallback of the plane-stress return: bisection alone halves the
/// bracket each update, so this many reach round-off from any bracket.
pub const FALLBACK_UPDATES: usize = 120;

/// `f`, `f'` and `κ` of the plane-stress return at `Δγ` (see [`return_plane_stress_with`]).
/// A function rather than a closure so that it is inlined into, and compiled with the vector
/// width of, the SIMD kernel that calls the return.
#[inline(always)]
fn return_eval<R: Real>(
    m: &PlaneStressConstants<R>,
    a1: R,
    a2: R,
    kappa_n: R,
    dgamma: R,
) -> (R, R, R) {
    let (c1, c2, h, one) = (m.c1, m.c2, m.h, R::splat(1.0));
    let (i1, i2) = (one / (one + c1 * dgamma), one / (one + c2 * dgamma));
    let (q1, q2) = (a1 * i1 * i1, a2 * i2 * i2);
    let xi2 = q1 + q2;
    let xi = xi2.sqrt();
    let dxi2 = R::splat(-2.0) * (q1 * c1 * i1 + q2 * c2 * i2);
    let kappa = kappa_n + h * R::splat(SQRT_2_3) * dgamma * xi;
    let f = R::splat(0.5) * xi2 - R::splat(1.0 / 3.0) * kappa * kappa;
    // dκ/dΔγ = H sqrt(2/3) (ξ + Δγ ξ'), ξ' = (ξ²)' / (2ξ).
    let dkappa = h * R::splat(SQRT_2_3) * (xi + dgamma * dxi2 * R::splat(0.5) / xi);
    let df = R::splat(0.5) * dxi2 - R::splat(2.0 / 3.0) * kappa * dkappa;
    (f, df, kappa)
}

/// Lanes of the return still to update: yielding and outside the tolerance. A lane stops when
/// it converges, so its result does not depend on the other lanes of its block.
#[inline(always)]
fn return_active<R: Real>(yielding: R::Mask, f: R, kappa: R, tol: f64) -> R::Mask {
    let excess = R::select(yielding, f.abs() - R::splat(tol) * kappa * kappa, -R::splat(1.0));
    excess.gt(R::splat(0.0))
}

/// Plane-stress closest point projection from a trial stress `[σxx, σyy, σxy]` (Simo-Taylor
/// 1986; Simo-Hughes Box 3.3): Newton updates of `Δγ` on `f(Δγ) = ½ ξ² - ⅓ κ²`,
/// `ξ² = σ(Δγ)ᵀ P σ(Δγ)`, `κ = κ_n + H sqrt(⅔) Δγ ξ`, from the radial-return estimate.
///
/// At most `max_newton` plain Newton updates, stopping early when every lane satisfies
/// `|f| <= tol κ²`. With `tol > 0`, lanes still outside the tolerance then continue with a
/// safeguarded iteration (at most [`FALLBACK_UPDATES`]): `f` falls from `f(0) > 0` to
/// `f(Δγ_max) <= 0`, `Δγ_max = (ξ_tr / (sqrt(⅔) κ_n) - 1) / min(c1, c2)` (as `ξ <= ξ_tr /
/// (1 + min(c1, c2) Δγ)` and `κ >= κ_n` for `H >= 0`), the bracket shrinks on the sign of `f`
/// and a Newton step leaving it is replaced by its midpoint. With `tol = 0` exactly
/// `max_newton` updates are made.
///
/// In the common eigenbasis of `C` and `P`, `σ(Δγ) = (1 + Δγ C P)⁻¹ σ_trial` is diagonal: the
/// mean part `(σxx+σyy)` scales by `1/(1 + c1 Δγ)`, the deviatoric parts `(σyy-σxx)/2, σxy`
/// by `1/(1 + c2 Δγ)`.
#[inline(always)]
pub fn return_plane_stress_with<R: Real>(
    m: &PlaneStressConstants<R>,
    trial: [R; 3],
    alpha: R,
    max_newton: usize,
    tol: f64,
) -> PlaneStressReturn<R> {
    let (c1, c2, h) = (m.c1, m.c2, m.h);
    let (zero, one) = (R::splat(0.0), R::splat(1.0));
    let mean = trial[0] + trial[1];
    let half_diff = (trial[1] - trial[0]) * R::splat(0.5);
    let a1 = mean * mean * R::splat(1.0 / 6.0);
    let a2 = half_diff * half_diff * R::splat(2.0) + trial[2] * trial[2] * R::splat(2.0);
    let kappa_n = m.sigma_y + h * alpha;
    let f_trial = R::splat(0.5) * (a1 + a2) - R::splat(1.0 / 3.0) * kappa_n * kappa_n;
    let yielding = f_trial.gt(zero);
    let mut dgamma = zero;
    if R::any(yielding) {
        // Start from the radial-return estimate (every component scaled by 1/(1 + 2GΔγ)):
        // ξ_tr (1 - ⅔ H Δγ) = sqrt(⅔) κ_n (1 + 2 G Δγ).
        let xi_tr = (a1 + a2).sqrt();
        let k_n = R::splat(SQRT_2_3) * kappa_n;
        let guess = (xi_tr - k_n) / (R::splat(2.0 / 3.0) * h * xi_tr + c2 * k_n);
        dgamma = R::select(yielding, guess, dgamma);
        let (mut f, mut df, mut kappa) = return_eval(m, a1, a2, kappa_n, dgamma);
        for i in 0..max_newton {
            let act = return_active(yielding, f, kappa, tol);
            if !R::any(act) {
                break;
            }
            dgamma = R::select(act, dgamma - f / df, dgamma);
            if i + 1 < max_newton || tol > 0.0 {
                (f, df, kappa) = return_eval(m, a1, a2, kappa_n, dgamma);
            }
        }
        if tol > 0.0 && R::any(return_active(yielding, f, kappa, tol)) {
            let mut lo = zero;
            let mut hi = (xi_tr / k_n - one) / c1.min(c2);
            for _ in 0..FALLBACK_UPDATES {
                let act = return_active(yielding, f, kappa, tol);
                if !R::any(act) {
                    break;
                }
                // Shrink the bracket on the sign of f.
                let above = f.gt(zero);
                lo = R::select(above, dgamma, lo);
                hi = R::select(above, hi, dgamma);
                let mid = (lo + hi) * R::splat(0.5);
                let newton = dgamma - f / df;
                let inside = R::select(newton.gt(lo), newton, mid);
                let step = R::select(hi.gt(inside), inside, mid);
                dgamma = R::select(act, step, dgamma);
                (f, df, kappa) = return_eval(m, a1, a2, kappa_n, dgamma);
            }
        }
    }
    let s1 = mean / (one + c1 * dgamma);
    let s2 = half_diff / (one + c2 * dgamma);
    let sxy = trial[2] / (one + c2 * dgamma);
    let sigma = [s1 * R::splat(0.5) - s2, s1 * R::splat(0.5) + s2, sxy];
    let xi = (s1 * s1 * R::splat(1.0 / 6.0) + s2 * s2 * R::splat(2.0) + sxy * sxy * R::splat(2.0))
        .sqrt();
    PlaneStressReturn { sigma, alpha: alpha + R::splat(SQRT_2_3) * dgamma * xi, dgamma }
}

impl J2 {
    /// Consistent tangent of the plane-stress return (derived from the linearised consistency
    /// condition; Simo-Hughes eq. 3.4.x): with `Ξ = (C⁻¹ + Δγ P)⁻¹`, `n = P σ`,
    /// `θ = 1 - ⅔ H Δγ`, `β = ⅔ H ξ² / θ`: `C_ep = Ξ - (Ξ n)(Ξ n)ᵀ / (nᵀ Ξ n + β)`.
    pub fn tangent_plane_stress(&self, r: &PlaneStressReturn) -> [[f64; 3]; 3] {
        let c = self.elastic.tangent_plane_stress();
        if r.dgamma == 0.0 {
            return c;
        }
        let (e, nu, g) = (self.elastic.e, self.elastic.nu, self.elastic.shear_modulus());
        let dg = r.dgamma;
        // C⁻¹ + Δγ P.
        let m = [
            [1.0 / e + dg * 2.0 / 3.0, -nu / e - dg / 3.0, 0.0],
            [-nu / e - dg / 3.0, 1.0 / e + dg * 2.0 / 3.0, 0.0],
            [0.0, 0.0, 1.0 / g + 2.0 * dg],
        ];
        let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
        let xi_m = [
            [m[1][1] / det, -m[0][1] / det, 0.0],
            [-m[1][0] / det, m[0][0] / det, 0.0],
            [0.0, 0.0, 1.0 / m[2][2]],
        ];
        let s = r.sigma;
        let n = p_times(&s);
        let xi2 = s[0] * n[0] + s[1] * n[1] + s[2] * n[2];
        let xn: [f64; 3] = std::array::from_fn(|i| (0..3).map(|j| xi_m[i][j] * n[j]).sum());
        let nxn = n[0] * xn[0] + n[1] * xn[1] + n[2] * xn[2];
        let theta = 1.0 - 2.0 / 3.0 * self.h * dg;
        let beta = 2.0 / 3.0 * self.h * xi2 / theta;
        std::array::from_fn(|i| std::array::from_fn(|j| xi_m[i][j] - xn[i] * xn[j] / (nxn + beta)))
    }
}

/// `P σ` for plane stress: the deviatoric projector `⅓ [[2, -1, 0], [-1, 2, 0], [0, 0, 6]]`;
/// `Δγ P σ` is the plastic strain increment with engineering shear.
pub fn p_times(s: &[f64; 3]) -> [f64; 3] {
    [(2.0 * s[0] - s[1]) / 3.0, (2.0 * s[1] - s[0]) / 3.0, 2.0 * s[2]]
}

/// Strain-driven J2 state of one 3D point (small strain): plastic strain (engineering shear)
/// and equivalent plastic strain.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct J2State3d {
    pub eps_p: [f64; 6],
    pub alpha: f64,
}

/// Strain-driven J2 state of one plane-stress point; `eps_p` is in-plane, the thickness plastic
/// strain is `-(εp_xx + εp_yy)` (plastic incompressibility).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct J2StatePlane {
    pub eps_p: [f64; 3],
    pub alpha: f64,
}

impl J2 {
    /// Stress, updated state and consistent tangent at total strain `eps` (3D).
    pub fn update_3d(
        &self,
        eps: &[f64; 6],
        state: &J2State3d,
    ) -> ([f64; 6], J2State3d, [[f64; 6]; 6]) {
        let ee: [f64; 6] = std::array::from_fn(|i| eps[i] - state.eps_p[i]);
        let r = self.return_3d(&self.elastic.stress_3d(&ee), state.alpha);
        let mut eps_p = state.eps_p;
        for i in 0..6 {
            // Engineering shear doubles the tensor component.
            eps_p[i] += r.dgamma * r.n[i] * if i < 3 { 1.0 } else { 2.0 };
        }
        (r.sigma, J2State3d { eps_p, alpha: r.alpha }, self.tangent_3d(&r))
    }

    /// Stress, updated state and consistent tangent at in-plane total strain `eps` (plane
    /// stress), the return converged to `1e-14`.
    pub fn update_plane_stress(
        &self,
        eps: &[f64; 3],
        state: &J2StatePlane,
    ) -> ([f64; 3], J2StatePlane, [[f64; 3]; 3]) {
        let ee: [f64; 3] = std::array::from_fn(|i| eps[i] - state.eps_p[i]);
        let r =
            self.return_plane_stress(self.elastic.stress_plane_stress(&ee), state.alpha, 50, 1e-14);
        let n = p_times(&r.sigma);
        let eps_p = std::array::from_fn(|i| state.eps_p[i] + r.dgamma * n[i]);
        (r.sigma, J2StatePlane { eps_p, alpha: r.alpha }, self.tangent_plane_stress(&r))
    }
}
