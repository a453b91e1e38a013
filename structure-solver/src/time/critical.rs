//! The critical step of central differences, `Δt_cr = 2/ω_max` (DESIGN §6: all stiffness
//! included), estimated from the model: the elements' own estimate (`Model::stable_dt`), a
//! matrix-free power iteration on `M⁻¹K` through the internal force, and Gershgorin's bound
//! `ω_max² <= max_i Σ_j |K_ij| / sqrt(m_i m_j)` which never overestimates the step; and the
//! rule that recomputes the step every step from the element bound ([`StableStep`]).

use crate::model::Model;

/// The three estimates of the critical step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CriticalDt {
    /// `Model::stable_dt`: the element estimate.
    pub element: f64,
    /// `2/sqrt(λ)` with λ from a power iteration on `M⁻¹K` (a lower bound of `λ_max`, so an
    /// upper estimate of the step; converged to about 1% in `iterations`).
    pub power: f64,
    /// Gershgorin: a guaranteed lower bound of the critical step.
    pub gershgorin: f64,
}

impl CriticalDt {
    /// The step to use: `safety ·` the smallest estimate of the element and power iterations.
    pub fn stable(&self, safety: f64) -> f64 {
        safety * self.element.min(self.power)
    }
}

/// The step of central differences taken at every step of a run: `safety · ratio ·` the
/// element bound at the current configuration (`Model::stable_dt`), `ratio = min(1,
/// power / element)` of the estimates at the start, so the first step is
/// `safety · CriticalDt::stable(1)` and later ones follow the element bound as elements
/// deform; `fallback` when the model has no element bound.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StableStep {
    pub safety: f64,
    pub ratio: f64,
    pub fallback: f64,
}

impl StableStep {
    /// The rule of a run started with the estimates `initial` and the stated `safety`.
    pub fn new(initial: &CriticalDt, safety: f64) -> Self {
        let stable = initial.stable(1.0);
        let ratio = if initial.element.is_finite() && initial.element > 0.0 {
            (stable / initial.element).min(1.0)
        } else {
            1.0
        };
        StableStep { safety, ratio, fallback: safety * stable }
    }

    /// The step at the model's current configuration.
    pub fn at(&self, model: &dyn Model) -> f64 {
        let element = model.stable_dt();
        if element.is_finite() {
            self.safety * self.ratio * element
        } else {
            self.fallback
        }
    }
}

/// Estimates the critical step at the committed state: Gershgorin from the tangent at `t`
/// (infinite when the model has no tangent, as explicit-only elements), and a matrix-free power
/// iteration on `M^-1/2 K M^-1/2` with `K v ≈ (f_int(u + δ v) - f_int(u)) / δ` (free dofs with
/// mass only, increments of at most `probe` in any dof). The model is reverted afterwards.
pub fn critical_dt(model: &mut dyn Model, t: f64, iterations: usize, probe: f64) -> CriticalDt {
    let n = model.n_dof();
    let mut k = crate::model::Tangent::default();
    model.tangent(t, &mut k);
    let m = model.lumped_mass().to_vec();
    let free: Vec<bool> =
        model.constrained().iter().zip(&m).map(|(&c, &m)| !c && m > 0.0).collect();
    let inv_sqrt: Vec<f64> =
        m.iter().zip(&free).map(|(&m, &f)| if f { 1.0 / m.sqrt() } else { 0.0 }).collect();
    let mut rows = vec![0.0; n];
    for e in k.triplets() {
        rows[e.row] += (e.val * inv_sqrt[e.row] * inv_sqrt[e.col]).abs();
    }
    let bound = rows.iter().cloned().fold(0.0, f64::max);
    let mut f0 = vec![0.0; n];
    model.internal_force(&mut f0);
    let mut x: Vec<f64> = (0..n)
        .map(|i| if free[i] { 1.0 + 0.37 * ((i * 7919) % 101) as f64 / 101.0 } else { 0.0 })
        .collect();
    let (mut du, mut f1) = (vec![0.0; n], vec![0.0; n]);
    let mut lambda = 0.0;
    for _ in 0..iterations {
        let norm = x.iter().map(|v| v * v).sum::<f64>().sqrt();
        if norm == 0.0 {
            break;
        }
        x.iter_mut().for_each(|v| *v /= norm);
        for i in 0..n {
            du[i] = inv_sqrt[i] * x[i];
        }
        let scale = probe / du.iter().fold(0.0f64, |a, v| a.max(v.abs())).max(1e-300);
        du.iter_mut().for_each(|v| *v *= scale);
        model.apply_increment(&du);
        model.internal_force(&mut f1);
        model.revert();
        // y = M^-1/2 K M^-1/2 x.
        for i in 0..n {
            f1[i] = inv_sqrt[i] * (f1[i] - f0[i]) / scale;
        }
        lambda = x.iter().zip(&f1).map(|(a, b)| a * b).sum::<f64>();
        std::mem::swap(&mut x, &mut f1);
    }
    let dt = |l: f64| if l > 0.0 { 2.0 / l.sqrt() } else { f64::INFINITY };
    CriticalDt { element: model.stable_dt(), power: dt(lambda), gershgorin: dt(bound) }
}
