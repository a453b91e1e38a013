//! Shells integrated through the thickness (DESIGN §6): at each in-plane integration point the
//! in-plane strain at height `z` is `ε(z) = B_m d + z B_b d`, the stress comes from the J2
//! plane-stress return (Simo & Taylor 1986, `material::j2`) at the points of a
//! [`ThicknessRule`], and the local force is
//! `f = K_lin d + Σ_g w_g Σ_t (h/2) w_t (B_m + z_t B_b)ᵀ σ_t` (transverse shear and drilling
//! stay elastic in `K_lin`). With an elastic material and a symmetric rule of two or more
//! points this is exactly `K d` of the elastic element.
//!
//! State: `[εp_xx, εp_yy, γp_xy, α]` per point, in-plane point major, in one flat array per
//! element (the model double-buffers it for commit and revert).

use nalgebra::{DMatrix, Matrix3};

use super::section::ShellSection;
use crate::material::j2::J2StatePlane;
use crate::material::{ThicknessRule, J2};

/// State values per thickness point.
pub const POINT_STATE: usize = 4;

/// One in-plane integration point: area weight, membrane and bending strain rows over the
/// element dofs.
#[derive(Debug, Clone)]
pub struct InPlanePoint {
    pub weight: f64,
    pub bm: DMatrix<f64>,
    pub bb: DMatrix<f64>,
}

/// The in-plane integration of a flat shell element and its linear (shear, drilling) part.
#[derive(Debug, Clone)]
pub struct Layers {
    pub points: Vec<InPlanePoint>,
    pub k_linear: DMatrix<f64>,
}

impl Layers {
    /// Stiffness of an elastic section: `K_lin + Σ w (B_mᵀ h C B_m + B_bᵀ h³/12 C B_b)`.
    pub fn elastic_stiffness(&self, sec: &ShellSection) -> DMatrix<f64> {
        let to_d = |m: [[f64; 3]; 3]| DMatrix::from_fn(3, 3, |i, j| m[i][j]);
        let (dm, db) = (to_d(sec.membrane()), to_d(sec.bending()));
        let mut k = self.k_linear.clone();
        for p in &self.points {
            k.gemm_tr(p.weight, &p.bm, &(&dm * &p.bm), 1.0);
            k.gemm_tr(p.weight, &p.bb, &(&db * &p.bb), 1.0);
        }
        k
    }
}

/// Von Mises stress of a shell point `[σxx, σyy, σxy]` or `[σxx, σyy, σxy, σyz, σzx]`
/// (σzz = 0), scaled by the largest component against overflow (a diverging run then stops at
/// its first non-finite nodal value, not at a squared stress).
pub fn shell_von_mises(s: &[f64]) -> f64 {
    let scale = s.iter().fold(0.0, |m: f64, v| m.max(v.abs()));
    if scale == 0.0 || !scale.is_finite() {
        return scale;
    }
    let (xx, yy) = (s[0] / scale, s[1] / scale);
    let shear: f64 = s[2..].iter().map(|v| (v / scale).powi(2)).sum();
    scale * (xx * xx - xx * yy + yy * yy + 3.0 * shear).sqrt()
}

impl Layers {
    /// Largest in-plane von Mises stress of an elastic section at local deformational
    /// displacements `d`: `σ = C (ε_m + z κ)` at the bottom, mid and top surfaces
    /// (`z = -h/2, 0, h/2`) of every in-plane point.
    pub fn von_mises(&self, d: &[f64], sec: &ShellSection) -> f64 {
        let c = sec.membrane().map(|r| r.map(|v| v / sec.h));
        let dv = nalgebra::DVectorView::from_slice(d, d.len());
        let mut vm = 0.0_f64;
        for p in &self.points {
            let (em, kap) = (&p.bm * dv, &p.bb * dv);
            for z in [-0.5 * sec.h, 0.0, 0.5 * sec.h] {
                let eps: [f64; 3] = std::array::from_fn(|k| em[k] + z * kap[k]);
                let sigma: [f64; 3] =
                    std::array::from_fn(|i| (0..3).map(|j| c[i][j] * eps[j]).sum());
                vm = vm.max(shell_von_mises(&sigma));
            }
        }
        vm
    }
}

/// A shell element of a J2 material integrated through the thickness.
#[derive(Debug, Clone)]
pub struct LayeredJ2 {
    pub layers: Layers,
    pub material: J2,
    pub rule: ThicknessRule,
    /// Thickness.
    pub h: f64,
}

impl LayeredJ2 {
    /// Length of the element's state array.
    pub fn n_state(&self) -> usize {
        self.layers.points.len() * self.rule.len() * POINT_STATE
    }

    /// Largest in-plane von Mises stress over the in-plane and thickness points at local
    /// deformational displacements `d` with the committed `state` (the stress of the
    /// plane-stress return, as `force` computes it).
    pub fn von_mises(&self, d: &[f64], state: &[f64]) -> f64 {
        let dv = nalgebra::DVectorView::from_slice(d, d.len());
        let nt = self.rule.len();
        let mut vm = 0.0_f64;
        for (g, p) in self.layers.points.iter().enumerate() {
            let (em, kap) = (&p.bm * dv, &p.bb * dv);
            for (t, &zeta) in self.rule.points.iter().enumerate() {
                let z = 0.5 * self.h * zeta;
                let eps = [em[0] + z * kap[0], em[1] + z * kap[1], em[2] + z * kap[2]];
                let i = (g * nt + t) * POINT_STATE;
                let s0 = J2StatePlane {
                    eps_p: [state[i], state[i + 1], state[i + 2]],
                    alpha: state[i + 3],
                };
                let (sigma, _, _) = self.material.update_plane_stress(&eps, &s0);
                vm = vm.max(shell_von_mises(&sigma));
            }
        }
        vm
    }

    /// Local force `fl` at local deformational displacements `d` from the committed state
    /// `old`; writes the trial state into `new`, and with `kl` the consistent local tangent
    /// `K_lin + Σ_g w_g Σ_t (h/2) w_t (B_m + z_t B_b)ᵀ C_t (B_m + z_t B_b)` with `C_t` the
    /// algorithmic tangent of the plane-stress return (Simo & Taylor 1986).
    pub fn force(
        &self,
        d: &[f64],
        old: &[f64],
        new: &mut [f64],
        fl: &mut [f64],
        mut kl: Option<&mut DMatrix<f64>>,
    ) {
        let n = d.len();
        let dv = nalgebra::DVectorView::from_slice(d, n);
        let mut f = &self.layers.k_linear * dv;
        if let Some(k) = kl.as_deref_mut() {
            k.copy_from(&self.layers.k_linear);
        }
        let nt = self.rule.len();
        for (g, p) in self.layers.points.iter().enumerate() {
            let em = &p.bm * dv;
            let kap = &p.bb * dv;
            let (mut nres, mut mres) = ([0.0; 3], [0.0; 3]);
            // Σ wt C, Σ wt z C, Σ wt z² C
            let (mut c0, mut c1, mut c2) = (Matrix3::zeros(), Matrix3::zeros(), Matrix3::zeros());
            for (t, (&zeta, &w)) in self.rule.points.iter().zip(&self.rule.weights).enumerate() {
                let z = 0.5 * self.h * zeta;
                let eps = [em[0] + z * kap[0], em[1] + z * kap[1], em[2] + z * kap[2]];
                let i = (g * nt + t) * POINT_STATE;
                let s0 =
                    J2StatePlane { eps_p: [old[i], old[i + 1], old[i + 2]], alpha: old[i + 3] };
                let (sigma, s1, c) = self.material.update_plane_stress(&eps, &s0);
                new[i..i + 3].copy_from_slice(&s1.eps_p);
                new[i + 3] = s1.alpha;
                let wt = 0.5 * self.h * w;
                for k in 0..3 {
                    nres[k] += wt * sigma[k];
                    mres[k] += wt * z * sigma[k];
                }
                if kl.is_some() {
                    let c = Matrix3::from_fn(|a, b| c[a][b]);
                    c0 += wt * c;
                    c1 += wt * z * c;
                    c2 += wt * z * z * c;
                }
            }
            // f += w_g (B_mᵀ N + B_bᵀ M)
            let (nv, mv) = (nalgebra::Vector3::from(nres), nalgebra::Vector3::from(mres));
            f.gemv_tr(p.weight, &p.bm, &nv, 1.0);
            f.gemv_tr(p.weight, &p.bb, &mv, 1.0);
            if let Some(k) = kl.as_deref_mut() {
                let (cm, cb) = (c0 * &p.bm + c1 * &p.bb, c1 * &p.bm + c2 * &p.bb);
                k.gemm_tr(p.weight, &p.bm, &cm, 1.0);
                k.gemm_tr(p.weight, &p.bb, &cb, 1.0);
            }
        }
        fl.copy_from_slice(f.as_slice());
    }
}
