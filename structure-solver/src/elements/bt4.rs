//! The one-point Belytschko-Lin-Tsay 4-node shell for the explicit hot loop (Belytschko, Lin &
//! Tsay, CMAME 42, 1984; Hallquist, *LS-DYNA Theory Manual*, §6 and §7), with
//!
//! - a corotational frame per element: `ê3 ∥ x31 × x42`, `ê1` along side 1-2 projected on the
//!   plane, `ê2 = ê3 × ê1`;
//! - warping correction by rigid links from the nodes to their projections on that plane
//!   (Belytschko, Wong & Chiang 1992): projected velocities `v̂_P = v̂_I - z_I θ̇̂_I × ê3`, and
//!   the transposed moments `m̂_x += z_I f̂_y`, `m̂_y -= z_I f̂_x`, so rigid motions stay strain
//!   free on warped elements;
//! - Flanagan-Belytschko (IJNME 17, 1981) hourglass control of stiffness type on the membrane,
//!   out-of-plane and rotational modes, `γ_I = ¼ (h_I - (h·x̂) b_xI - (h·ŷ) b_yI)`,
//!   `h = [1, -1, 1, -1]`;
//! - hypoelastic plane-stress update in the corotated frame at `n` thickness points with the
//!   J2 plane-stress return (at most `newton` updates; transverse shear stays elastic,
//!   `τ = κ G γ`, κ = 5/6).
//!
//! A step takes the end positions `x^{n+1}` and the increment `Δu` (translations and global
//! rotation increments) of the step: strain increments are computed in the mid-step geometry
//! `x^{n+1} - Δu/2`, where a rigid rotation's chord velocity is a pure spin (no strain), and the
//! nodal forces in the end geometry.
//!
//! Elements are evaluated in blocks of [`LANES`] with the kernel written once over
//! [`Real`], so the compiler vectorises across elements; per-point
//! state lives in flat arrays `[block][point][component][lane]`. State is double-buffered: a
//! step reads the committed state and writes the trial state; `commit` swaps them.

use super::section::{RotaryInertia, SHEAR_FACTOR};
use crate::material::lanes::{Lanes, Real};
use crate::material::{ThicknessRule, J2};

/// Elements per block.
pub const LANES: usize = 8;
type V = Lanes<LANES>;

/// Stress components per thickness point: `[σxx, σyy, σxy, σyz, σzx]`.
pub const N_STRESS: usize = 5;
/// Hourglass stresses per element: membrane x, y, out-of-plane w, rotations x, y.
pub const N_HOURGLASS: usize = 5;

/// Settings of a BT4 part.
#[derive(Debug, Clone, PartialEq)]
pub struct Bt4Settings {
    pub rule: ThicknessRule,
    /// Hourglass coefficient `r` (membrane, out-of-plane and rotational alike).
    pub hourglass: f64,
    /// Newton updates of the plane-stress return.
    pub newton: usize,
    /// Lumping of rotary inertia.
    pub rotary: RotaryInertia,
}

impl Default for Bt4Settings {
    fn default() -> Self {
        Bt4Settings {
            rule: ThicknessRule::gauss(5),
            hourglass: 0.05,
            newton: 3,
            rotary: RotaryInertia::Scaled,
        }
    }
}

/// Per-point and per-element state of a part, in block layout.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Bt4State {
    /// `[block][point][component][lane]`.
    pub stress: Vec<f64>,
    /// Equivalent plastic strain, `[block][point][lane]`.
    pub alpha: Vec<f64>,
    /// Hourglass stresses, `[block][mode][lane]`.
    pub hourglass: Vec<f64>,
}

/// A part of BT4 shells: connectivity (in storage order), thickness, one material.
#[derive(Debug, Clone)]
pub struct Bt4 {
    pub conn: Vec<[u32; 4]>,
    pub thickness: Vec<f64>,
    pub material: J2,
    pub settings: Bt4Settings,
    committed: Bt4State,
    trial: Bt4State,
}

/// Geometry of an element (block) in its corotated frame.
struct Frame<R> {
    e: [[R; 3]; 3],
    /// Local in-plane coordinates of the projected nodes.
    x: [R; 4],
    y: [R; 4],
    /// Warp: distance of each node from the reference plane.
    z: [R; 4],
    b1: [R; 4],
    b2: [R; 4],
    area: R,
}

#[inline(always)]
fn cross<R: Real>(a: [R; 3], b: [R; 3]) -> [R; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

#[inline(always)]
fn dot<R: Real>(a: [R; 3], b: [R; 3]) -> R {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline(always)]
fn normalize<R: Real>(a: [R; 3]) -> [R; 3] {
    let inv = R::splat(1.0) / dot(a, a).sqrt();
    [a[0] * inv, a[1] * inv, a[2] * inv]
}

/// Corotated frame, projected local coordinates and the one-point `b = ∂N/∂x̂` at the centre.
#[inline(always)]
fn frame<R: Real>(x: &[[R; 3]; 4]) -> Frame<R> {
    let sub = |a: [R; 3], b: [R; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let e3 = normalize(cross(sub(x[2], x[0]), sub(x[3], x[1])));
    let x21 = sub(x[1], x[0]);
    let d = dot(x21, e3);
    let e1 = normalize([x21[0] - d * e3[0], x21[1] - d * e3[1], x21[2] - d * e3[2]]);
    let e2 = cross(e3, e1);
    let quarter = R::splat(0.25);
    let c: [R; 3] = std::array::from_fn(|k| (x[0][k] + x[1][k] + x[2][k] + x[3][k]) * quarter);
    let mut lx = [R::splat(0.0); 4];
    let mut ly = lx;
    let mut lz = lx;
    for i in 0..4 {
        let r = sub(x[i], c);
        lx[i] = dot(r, e1);
        ly[i] = dot(r, e2);
        lz[i] = dot(r, e3);
    }
    let two_a = (lx[2] - lx[0]) * (ly[3] - ly[1]) - (lx[3] - lx[1]) * (ly[2] - ly[0]);
    let inv = R::splat(1.0) / two_a;
    let b1 = [
        (ly[1] - ly[3]) * inv,
        (ly[2] - ly[0]) * inv,
        (ly[3] - ly[1]) * inv,
        (ly[0] - ly[2]) * inv,
    ];
    let b2 = [
        (lx[3] - lx[1]) * inv,
        (lx[0] - lx[2]) * inv,
        (lx[1] - lx[3]) * inv,
        (lx[2] - lx[0]) * inv,
    ];
    Frame { e: [e1, e2, e3], x: lx, y: ly, z: lz, b1, b2, area: two_a * R::splat(0.5) }
}

impl Bt4 {
    /// A part; `thickness` per element.
    pub fn new(
        conn: Vec<[u32; 4]>,
        thickness: Vec<f64>,
        material: J2,
        settings: Bt4Settings,
    ) -> Self {
        assert_eq!(conn.len(), thickness.len(), "one thickness per element");
        let nb = conn.len().div_ceil(LANES);
        let np = settings.rule.len();
        let state = Bt4State {
            stress: vec![0.0; nb * np * N_STRESS * LANES],
            alpha: vec![0.0; nb * np * LANES],
            hourglass: vec![0.0; nb * N_HOURGLASS * LANES],
        };
        Bt4 { conn, thickness, material, settings, committed: state.clone(), trial: state }
    }

    pub fn n_elements(&self) -> usize {
        self.conn.len()
    }

    fn n_blocks(&self) -> usize {
        self.conn.len().div_ceil(LANES)
    }

    /// Committed state (for checkpoints).
    pub fn state(&self) -> &Bt4State {
        &self.committed
    }

    /// Restores a committed state.
    pub fn set_state(&mut self, s: Bt4State) {
        assert_eq!(s.stress.len(), self.committed.stress.len(), "state of another part");
        self.trial = s.clone();
        self.committed = s;
    }

    /// Accepts the trial state.
    pub fn commit(&mut self) {
        std::mem::swap(&mut self.committed, &mut self.trial);
    }

    /// Committed stress `[σxx, σyy, σxy, σyz, σzx]` of element `e` at thickness point `p`, in the
    /// corotated frame.
    pub fn stress(&self, e: usize, p: usize) -> [f64; N_STRESS] {
        let np = self.settings.rule.len();
        let (b, l) = (e / LANES, e % LANES);
        std::array::from_fn(|c| self.committed.stress[((b * np + p) * N_STRESS + c) * LANES + l])
    }

    /// Sets the committed (and trial) stress of element `e` at point `p` (prestress).
    pub fn set_stress(&mut self, e: usize, p: usize, s: [f64; N_STRESS]) {
        let np = self.settings.rule.len();
        let (b, l) = (e / LANES, e % LANES);
        for (c, v) in s.iter().enumerate() {
            let i = ((b * np + p) * N_STRESS + c) * LANES + l;
            self.committed.stress[i] = *v;
            self.trial.stress[i] = *v;
        }
    }

    /// Committed equivalent plastic strain of element `e` at point `p`.
    pub fn plastic_strain(&self, e: usize, p: usize) -> f64 {
        let np = self.settings.rule.len();
        self.committed.alpha[((e / LANES) * np + p) * LANES + e % LANES]
    }

    /// Adds the lumped mass (`ρ h A / 4` per node) and rotary inertia to a 6-per-node vector.
    pub fn lumped_mass(&self, x: &[[f64; 3]], mass: &mut [f64]) {
        let rho = self.material.elastic.rho;
        for (c, &h) in self.conn.iter().zip(&self.thickness) {
            let xe = c.map(|n| x[n as usize]);
            let a = frame(&xe).area;
            let m = rho * h * a / 4.0;
            let i = self.settings.rotary.of_node(m, h, a);
            for &n in c {
                let n = n as usize;
                for k in 0..3 {
                    mass[6 * n + k] += m;
                    mass[6 * n + 3 + k] += i;
                }
            }
        }
    }

    /// The element estimate of the critical step: the smaller of the membrane bound
    /// `L_e / c`, `L_e = A / max(diagonal)`, `c` the plate wave speed (Hallquist uses
    /// `A / max(side)`; the diagonal leaves room for the hourglass stiffness), and the rotational
    /// bound `2/ω_r`, `ω_r² = (12 κ G + 4 E h²/A) / (ρ (h² + a))` of the transverse-shear and
    /// bending modes of a node's rotary inertia `m (h² + a)/12` (`a = A` when scaled, else 0).
    pub fn stable_dt(&self, x: &[[f64; 3]]) -> f64 {
        let el = self.material.elastic;
        let c = el.plate_wave_speed();
        let mut dt = f64::INFINITY;
        for (conn, &h) in self.conn.iter().zip(&self.thickness) {
            let xe = conn.map(|n| x[n as usize]);
            let a = frame(&xe).area;
            let d = |i: usize, j: usize| {
                ((xe[i][0] - xe[j][0]).powi(2)
                    + (xe[i][1] - xe[j][1]).powi(2)
                    + (xe[i][2] - xe[j][2]).powi(2))
                .sqrt()
            };
            let l = a / d(0, 2).max(d(1, 3));
            let a_rot = self.settings.rotary.added_area(a);
            let w2 = (12.0 * SHEAR_FACTOR * el.shear_modulus() + 4.0 * el.e * h * h / a)
                / (el.rho * (h * h + a_rot));
            dt = dt.min(l / c).min(2.0 / w2.sqrt());
        }
        dt
    }

    /// Adds the internal forces (6 per node, global frame) of the step with end positions
    /// `x_end` and increment `du` (6 per node) to `f`, writing the trial state. Uses AVX2 and
    /// FMA when the processor has them (the same kernel, compiled twice).
    pub fn internal_force(&mut self, x_end: &[[f64; 3]], du: &[f64], f: &mut [f64]) {
        assert!(du.len() >= 6 * x_end.len() && f.len() >= 6 * x_end.len(), "6 dofs per node");
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
        {
            // SAFETY: the processor supports the features the function is compiled for.
            unsafe { self.internal_force_avx2(x_end, du, f) };
            return;
        }
        self.internal_force_blocks(x_end, du, f);
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    fn internal_force_avx2(&mut self, x_end: &[[f64; 3]], du: &[f64], f: &mut [f64]) {
        self.internal_force_blocks(x_end, du, f);
    }

    #[inline(always)]
    fn internal_force_blocks(&mut self, x_end: &[[f64; 3]], du: &[f64], f: &mut [f64]) {
        let nb = self.n_blocks();
        let np = self.settings.rule.len();
        let ne = self.conn.len();
        for b in 0..nb {
            let e0 = b * LANES;
            let valid = (ne - e0).min(LANES);
            // Gather: padded lanes repeat the block's last element.
            let node = |l: usize, i: usize| self.conn[e0 + l.min(valid - 1)][i] as usize;
            let mut xe = [[V::splat(0.0); 3]; 4];
            let mut xm = xe;
            let mut dv = [[V::splat(0.0); 6]; 4];
            for i in 0..4 {
                for l in 0..LANES {
                    let n = node(l, i);
                    for k in 0..3 {
                        xe[i][k].0[l] = x_end[n][k];
                        xm[i][k].0[l] = x_end[n][k] - 0.5 * du[6 * n + k];
                    }
                    for k in 0..6 {
                        dv[i][k].0[l] = du[6 * n + k];
                    }
                }
            }
            let h = Lanes(std::array::from_fn(|l| self.thickness[e0 + l.min(valid - 1)]));
            let sb = b * np * N_STRESS * LANES;
            let ab = b * np * LANES;
            let hb = b * N_HOURGLASS * LANES;
            let fe = element_block(
                &self.material,
                &self.settings,
                &xe,
                &xm,
                &dv,
                h,
                &self.committed.stress[sb..sb + np * N_STRESS * LANES],
                &self.committed.alpha[ab..ab + np * LANES],
                &self.committed.hourglass[hb..hb + N_HOURGLASS * LANES],
                &mut self.trial.stress[sb..sb + np * N_STRESS * LANES],
                &mut self.trial.alpha[ab..ab + np * LANES],
                &mut self.trial.hourglass[hb..hb + N_HOURGLASS * LANES],
            );
            for l in 0..valid {
                for i in 0..4 {
                    let n = node(l, i);
                    for k in 0..6 {
                        f[6 * n + k] += fe[i][k].0[l];
                    }
                }
            }
        }
    }
}

#[inline(always)]
fn load(s: &[f64], i: usize) -> V {
    Lanes(s[i * LANES..(i + 1) * LANES].try_into().expect("lane slice"))
}

#[inline(always)]
fn store(s: &mut [f64], i: usize, v: V) {
    s[i * LANES..(i + 1) * LANES].copy_from_slice(&v.0);
}

/// One block: strain increments at the mid geometry, stress update at every thickness point,
/// resultants, hourglass, nodal forces and moments in the end geometry (global frame).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn element_block(
    mat: &J2,
    set: &Bt4Settings,
    x_end: &[[V; 3]; 4],
    x_mid: &[[V; 3]; 4],
    du: &[[V; 6]; 4],
    h: V,
    stress_old: &[f64],
    alpha_old: &[f64],
    hg_old: &[f64],
    stress_new: &mut [f64],
    alpha_new: &mut [f64],
    hg_new: &mut [f64],
) -> [[V; 6]; 4] {
    let zero = V::splat(0.0);
    let quarter = V::splat(0.25);
    // --- Strain increments in the mid-step frame.
    let fm = frame(x_mid);
    let mut ul = [[zero; 3]; 4];
    let mut rl = [[zero; 3]; 4];
    for i in 0..4 {
        // Rotation increment as the mid-step spin of its Cayley transform,
        // 2 tan(|Δθ|/2) / |Δθ| ≈ 1 + |Δθ|²/12: a rigid rotation's chord at the mid geometry is
        // exactly that spin, so rotations and translations agree and it stays strain free.
        let th = [du[i][3], du[i][4], du[i][5]];
        let cay = V::splat(1.0) + dot(th, th) * V::splat(1.0 / 12.0);
        for a in 0..3 {
            ul[i][a] = dot(fm.e[a], [du[i][0], du[i][1], du[i][2]]);
            rl[i][a] = dot(fm.e[a], th) * cay;
        }
    }
    let (mut em, mut kap, mut gs) = ([zero; 3], [zero; 3], [zero; 2]);
    let mut rx_mean = zero;
    let mut ry_mean = zero;
    for i in 0..4 {
        // Rigid-link projection (warping correction).
        let upx = ul[i][0] - fm.z[i] * rl[i][1];
        let upy = ul[i][1] + fm.z[i] * rl[i][0];
        em[0] += fm.b1[i] * upx;
        em[1] += fm.b2[i] * upy;
        em[2] += fm.b2[i] * upx + fm.b1[i] * upy;
        kap[0] += fm.b1[i] * rl[i][1];
        kap[1] -= fm.b2[i] * rl[i][0];
        kap[2] += fm.b2[i] * rl[i][1] - fm.b1[i] * rl[i][0];
        gs[0] += fm.b1[i] * ul[i][2];
        gs[1] += fm.b2[i] * ul[i][2];
        rx_mean += rl[i][0] * quarter;
        ry_mean += rl[i][1] * quarter;
    }
    // γ_xz = w_,x + θ_y, γ_yz = w_,y - θ_x.
    let gxz = gs[0] + ry_mean;
    let gyz = gs[1] - rx_mean;

    // --- Stress update through the thickness and resultants.
    let el = mat.elastic;
    let c = el.tangent_plane_stress();
    let (c00, c01, c22) = (V::splat(c[0][0]), V::splat(c[0][1]), V::splat(c[2][2]));
    let gk = V::splat(SHEAR_FACTOR * el.shear_modulus());
    let half_h = h * V::splat(0.5);
    let (mut n, mut m, mut q) = ([zero; 3], [zero; 3], [zero; 2]);
    for (p, (&zeta, &w)) in set.rule.points.iter().zip(&set.rule.weights).enumerate() {
        let z = half_h * V::splat(zeta);
        let de = [em[0] + z * kap[0], em[1] + z * kap[1], em[2] + z * kap[2]];
        let s = p * N_STRESS;
        let trial = [
            load(stress_old, s) + c00 * de[0] + c01 * de[1],
            load(stress_old, s + 1) + c01 * de[0] + c00 * de[1],
            load(stress_old, s + 2) + c22 * de[2],
        ];
        let r = mat.return_plane_stress(trial, load(alpha_old, p), set.newton, 0.0);
        let syz = load(stress_old, s + 3) + gk * gyz;
        let szx = load(stress_old, s + 4) + gk * gxz;
        for k in 0..3 {
            store(stress_new, s + k, r.sigma[k]);
        }
        store(stress_new, s + 3, syz);
        store(stress_new, s + 4, szx);
        store(alpha_new, p, r.alpha);
        let wn = half_h * V::splat(w);
        let wm = wn * z;
        for k in 0..3 {
            n[k] += wn * r.sigma[k];
            m[k] += wm * r.sigma[k];
        }
        q[0] += wn * szx;
        q[1] += wn * syz;
    }

    // --- Forces in the end frame.
    let fe = frame(x_end);
    let a = fe.area;
    let mut fl = [[zero; 6]; 4];
    for i in 0..4 {
        let fx = a * (fe.b1[i] * n[0] + fe.b2[i] * n[2]);
        let fy = a * (fe.b2[i] * n[1] + fe.b1[i] * n[2]);
        fl[i][0] = fx;
        fl[i][1] = fy;
        fl[i][2] = a * (fe.b1[i] * q[0] + fe.b2[i] * q[1]);
        fl[i][3] = -a * (fe.b2[i] * m[1] + fe.b1[i] * m[2]) - a * quarter * q[1] + fe.z[i] * fy;
        fl[i][4] = a * (fe.b1[i] * m[0] + fe.b2[i] * m[2]) + a * quarter * q[0] - fe.z[i] * fx;
    }

    // --- Hourglass control (Flanagan-Belytschko), stiffness form, in the end frame.
    let hv = [1.0, -1.0, 1.0, -1.0].map(V::splat);
    let hx = hv[0] * fe.x[0] + hv[1] * fe.x[1] + hv[2] * fe.x[2] + hv[3] * fe.x[3];
    let hy = hv[0] * fe.y[0] + hv[1] * fe.y[1] + hv[2] * fe.y[2] + hv[3] * fe.y[3];
    let g: [V; 4] = std::array::from_fn(|i| quarter * (hv[i] - hx * fe.b1[i] - hy * fe.b2[i]));
    let mut bb = zero;
    for i in 0..4 {
        bb += fe.b1[i] * fe.b1[i] + fe.b2[i] * fe.b2[i];
    }
    let r = V::splat(set.hourglass);
    let e = V::splat(el.e);
    let h3 = h * h * h;
    let k_mem = r * e * h * a * bb * V::splat(1.0 / 8.0);
    let k_w = r * gk * h3 * bb * V::splat(1.0 / 12.0);
    let k_rot = r * e * h3 * a * bb * V::splat(1.0 / 192.0);
    let mut qd = [zero; N_HOURGLASS];
    for i in 0..4 {
        let ue = [
            dot(fe.e[0], [du[i][0], du[i][1], du[i][2]]),
            dot(fe.e[1], [du[i][0], du[i][1], du[i][2]]),
            dot(fe.e[2], [du[i][0], du[i][1], du[i][2]]),
        ];
        qd[0] += g[i] * ue[0];
        qd[1] += g[i] * ue[1];
        qd[2] += g[i] * ue[2];
        qd[3] += g[i] * dot(fe.e[0], [du[i][3], du[i][4], du[i][5]]);
        qd[4] += g[i] * dot(fe.e[1], [du[i][3], du[i][4], du[i][5]]);
    }
    let kh = [k_mem, k_mem, k_w, k_rot, k_rot];
    let mut qh = [zero; N_HOURGLASS];
    for k in 0..N_HOURGLASS {
        qh[k] = load(hg_old, k) + kh[k] * qd[k];
        store(hg_new, k, qh[k]);
    }
    for i in 0..4 {
        for k in 0..N_HOURGLASS {
            fl[i][k] += g[i] * qh[k];
        }
    }

    // --- Back to the global frame.
    let mut out = [[zero; 6]; 4];
    for i in 0..4 {
        for k in 0..3 {
            out[i][k] = fe.e[0][k] * fl[i][0] + fe.e[1][k] * fl[i][1] + fe.e[2][k] * fl[i][2];
            out[i][3 + k] = fe.e[0][k] * fl[i][3] + fe.e[1][k] * fl[i][4] + fe.e[2][k] * fl[i][5];
        }
    }
    out
}
