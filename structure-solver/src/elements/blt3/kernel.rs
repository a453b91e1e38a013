//! The arithmetic of one BLT3 element: its elastic step bound (Gershgorin), the local
//! increment in the corotated frame, and the step itself (strain increments at the mid
//! geometry, stress update through the thickness with the J2 plane-stress return, elastic
//! transverse shear, nodal forces `A Bᵀ s` in the end geometry).

use super::strain::{apply, dot, frame, rows, Frame, N_DOF};
use super::{Blt3Settings, N_SHEAR, N_STRESS};
use crate::elements::section::SHEAR_FACTOR;
use crate::material::J2;

/// Gershgorin bound of the largest eigenvalue of `M^-1/2 K M^-1/2` of one element of
/// thickness `h` in frame `f` (elastic moduli; `stable_dt`).
pub(super) fn max_frequency_squared(mat: &J2, set: &Blt3Settings, f: &Frame, h: f64) -> f64 {
    let el = mat.elastic;
    let r = rows(f);
    let c = el.tangent_plane_stress();
    let kgh = SHEAR_FACTOR * el.shear_modulus() * h;
    let mut k = [[0.0; N_DOF]; N_DOF];
    let mut add = |a: &[f64; N_DOF], b: &[f64; N_DOF], d: f64| {
        if d != 0.0 {
            for (ki, ai) in k.iter_mut().zip(a) {
                for (kij, bj) in ki.iter_mut().zip(b) {
                    *kij += f.area * d * ai * bj;
                }
            }
        }
    };
    for (rows, scale) in [(&r.membrane, h), (&r.curvature, h * h * h / 12.0)] {
        for i in 0..3 {
            for j in 0..3 {
                add(&rows[i], &rows[j], scale * c[i][j]);
            }
        }
    }
    add(&r.shear[0], &r.shear[0], kgh);
    add(&r.shear[1], &r.shear[1], kgh);
    add(&r.shear[2], &r.shear[2], kgh * r.linear_shear_factor);
    let m = el.rho * h * f.area / 3.0;
    let i = set.rotary.of_node(m, h, f.area);
    let mass = |d: usize| if d % 6 < 3 { m } else { i };
    (0..N_DOF)
        .map(|a| (0..N_DOF).map(|b| k[a][b].abs() / (mass(a) * mass(b)).sqrt()).sum::<f64>())
        .fold(0.0, f64::max)
}

/// One element's step geometry.
pub(super) struct Geometry<'a> {
    pub x_end: &'a [[f64; 3]; 3],
    pub x_mid: &'a [[f64; 3]; 3],
    pub du: &'a [[f64; 6]; 3],
    pub h: f64,
}

/// One element's committed state.
pub(super) struct Committed<'a> {
    pub stress: &'a [f64],
    pub alpha: &'a [f64],
    pub shear: &'a [f64],
}

/// One element's trial state.
pub(super) struct Trial<'a> {
    pub stress: &'a mut [f64],
    pub alpha: &'a mut [f64],
    pub shear: &'a mut [f64],
}

/// Local dofs of the increment in frame `f`; rotation increments as the mid-step spin of
/// their Cayley transform, scaled by `2 tan(|Δθ|/2)/|Δθ|` (`bt4` takes its series
/// `1 + |Δθ|²/12`): a rigid rotation's chord `Δu = (R - I) X` is exactly that spin applied to
/// the mid geometry `(R + I) X / 2`, so translations and rotations agree and any rigid
/// increment below a half turn is strain free.
fn local_increment(f: &Frame, du: &[[f64; 6]; 3]) -> [f64; N_DOF] {
    let mut d = [0.0; N_DOF];
    for i in 0..3 {
        let u = [du[i][0], du[i][1], du[i][2]];
        let th = [du[i][3], du[i][4], du[i][5]];
        let t2 = dot(th, th);
        let t = t2.sqrt();
        let cay = if t > 1e-3 { 2.0 * (0.5 * t).tan() / t } else { 1.0 + t2 / 12.0 };
        for a in 0..3 {
            d[6 * i + a] = dot(f.e[a], u);
            d[6 * i + 3 + a] = dot(f.e[a], th) * cay;
        }
    }
    d
}

/// One element: strain increments at the mid geometry, stress update at every thickness
/// point, resultants, nodal forces and moments `A Bᵀ (N, M, Q)` in the end geometry (global).
pub(super) fn element(
    mat: &J2,
    set: &Blt3Settings,
    g: Geometry,
    old: Committed,
    new: Trial,
) -> [[f64; 6]; 3] {
    let h = g.h;
    let fm = frame(g.x_mid);
    let rm = rows(&fm);
    let d = local_increment(&fm, g.du);
    let em = rm.membrane.map(|r| apply(&r, &d));
    let kap = rm.curvature.map(|r| apply(&r, &d));
    let gam = rm.shear.map(|r| apply(&r, &d));

    // --- Membrane and bending through the thickness.
    let el = mat.elastic;
    let c = el.tangent_plane_stress();
    let (mut n, mut m) = ([0.0; 3], [0.0; 3]);
    for (p, (&zeta, &w)) in set.rule.points.iter().zip(&set.rule.weights).enumerate() {
        let z = 0.5 * h * zeta;
        let de = [em[0] + z * kap[0], em[1] + z * kap[1], em[2] + z * kap[2]];
        let s = p * N_STRESS;
        let trial = [
            old.stress[s] + c[0][0] * de[0] + c[0][1] * de[1],
            old.stress[s + 1] + c[1][0] * de[0] + c[1][1] * de[1],
            old.stress[s + 2] + c[2][2] * de[2],
        ];
        let r = mat.return_plane_stress(trial, old.alpha[p], set.newton, set.return_tol);
        new.stress[s..s + N_STRESS].copy_from_slice(&r.sigma);
        new.alpha[p] = r.alpha;
        let wn = 0.5 * h * w;
        for k in 0..3 {
            n[k] += wn * r.sigma[k];
            m[k] += wn * z * r.sigma[k];
        }
    }
    // --- Elastic transverse shear: Q = κ G h γ at the centroid, κ G h m c for the linear part.
    let kgh = SHEAR_FACTOR * el.shear_modulus() * h;
    let ks = [kgh, kgh, kgh * rm.linear_shear_factor];
    for k in 0..N_SHEAR {
        new.shear[k] = old.shear[k] + ks[k] * gam[k];
    }

    // --- Forces in the end frame.
    let fe = frame(g.x_end);
    let re = rows(&fe);
    let mut fl = [0.0; N_DOF];
    for (rows, s) in [(&re.membrane, n), (&re.curvature, m)] {
        for (row, sk) in rows.iter().zip(s) {
            for (o, b) in fl.iter_mut().zip(row) {
                *o += fe.area * b * sk;
            }
        }
    }
    for (row, &q) in re.shear.iter().zip(new.shear.iter()) {
        for (o, b) in fl.iter_mut().zip(row) {
            *o += fe.area * b * q;
        }
    }
    // --- Back to the global frame.
    let mut out = [[0.0; 6]; 3];
    for i in 0..3 {
        for k in 0..3 {
            out[i][k] = (0..3).map(|a| fe.e[a][k] * fl[6 * i + a]).sum();
            out[i][3 + k] = (0..3).map(|a| fe.e[a][k] * fl[6 * i + 3 + a]).sum();
        }
    }
    out
}
