//! The arithmetic of one block of [`LANES`] BT4 elements: corotated frame, strain increments at
//! the mid-step geometry, stress update through the thickness with the J2 plane-stress return,
//! resultants, Flanagan-Belytschko hourglass control and nodal forces in the end geometry.

use super::{Bt4Settings, LANES, N_HOURGLASS, N_STRESS};
use crate::elements::section::SHEAR_FACTOR;
use crate::material::lanes::{Block8, Real};
use crate::material::{return_plane_stress_with, PlaneStressConstants, J2};

/// Geometry of an element (block) in its corotated frame.
pub(super) struct Frame<R> {
    pub e: [[R; 3]; 3],
    /// Local in-plane coordinates of the projected nodes.
    pub x: [R; 4],
    pub y: [R; 4],
    /// Warp: distance of each node from the reference plane.
    pub z: [R; 4],
    pub b1: [R; 4],
    pub b2: [R; 4],
    pub area: R,
}

#[inline(always)]
fn cross<R: Real>(a: [R; 3], b: [R; 3]) -> [R; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

#[inline(always)]
fn sub<R: Real>(a: [R; 3], b: [R; 3]) -> [R; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
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
pub(super) fn frame<R: Real>(x: &[[R; 3]; 4]) -> Frame<R> {
    let e3 = normalize(cross(sub(x[2], x[0]), sub(x[3], x[1])));
    let x21 = sub(x[1], x[0]);
    let d = dot(x21, e3);
    let e1 = normalize([x21[0] - d * e3[0], x21[1] - d * e3[1], x21[2] - d * e3[2]]);
    let e2 = cross(e3, e1);
    let quarter = R::splat(0.25);
    // Functions and loops rather than closures over lanes: a closure is compiled apart from
    // the instruction set of the kernel, so its vector operations may stay calls.
    let mut c = [R::splat(0.0); 3];
    for k in 0..3 {
        c[k] = (x[0][k] + x[1][k] + x[2][k] + x[3][k]) * quarter;
    }
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

/// The material constants the kernel reads: one value per material (`f64`) or per lane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Constants<R> {
    /// Plane-stress elastic tangent `C00 = C11`, `C01`, `C22 = G`.
    pub c00: R,
    pub c01: R,
    pub c22: R,
    /// Transverse shear modulus `κ G`.
    pub gk: R,
    pub e: R,
    pub ret: PlaneStressConstants<R>,
}

impl Constants<f64> {
    pub fn of(m: &J2) -> Self {
        let el = m.elastic;
        let c = el.tangent_plane_stress();
        Constants {
            c00: c[0][0],
            c01: c[0][1],
            c22: c[2][2],
            gk: SHEAR_FACTOR * el.shear_modulus(),
            e: el.e,
            ret: m.plane_stress_constants(),
        }
    }
}

impl<R: Block8> Constants<R> {
    /// Lane `l` takes the constants `of(l)`.
    #[inline(always)]
    pub fn gather<'a>(of: impl Fn(usize) -> &'a Constants<f64>) -> Self {
        let cs: [&Constants<f64>; LANES] = std::array::from_fn(of);
        macro_rules! lanes {
            ($($f:ident).+) => {
                R::from_array(std::array::from_fn(|l| cs[l].$($f).+))
            };
        }
        Constants {
            c00: lanes!(c00),
            c01: lanes!(c01),
            c22: lanes!(c22),
            gk: lanes!(gk),
            e: lanes!(e),
            ret: PlaneStressConstants {
                c1: lanes!(ret.c1),
                c2: lanes!(ret.c2),
                h: lanes!(ret.h),
                sigma_y: lanes!(ret.sigma_y),
            },
        }
    }

    #[inline(always)]
    pub fn splat(c: &Constants<f64>) -> Self {
        Self::gather(|_| c)
    }
}

#[inline(always)]
fn load<R: Block8>(s: &[f64], i: usize) -> R {
    R::from_array(s[i * LANES..(i + 1) * LANES].try_into().expect("lane slice"))
}

#[inline(always)]
fn store<R: Block8>(s: &mut [f64], i: usize, v: R) {
    s[i * LANES..(i + 1) * LANES].copy_from_slice(&v.to_array());
}

/// The committed (read) and trial (written) state of one block.
pub(super) struct BlockState<'a> {
    pub stress_old: &'a [f64],
    pub alpha_old: &'a [f64],
    pub hg_old: &'a [f64],
    pub stress_new: &'a mut [f64],
    pub alpha_new: &'a mut [f64],
    pub hg_new: &'a mut [f64],
}

/// One block: strain increments at the mid geometry, stress update at every thickness point,
/// resultants, hourglass, nodal forces and moments in the end geometry (global frame).
#[inline(always)]
pub(super) fn element_block<V: Block8>(
    mat: &Constants<V>,
    set: &Bt4Settings,
    x_end: &[[V; 3]; 4],
    x_mid: &[[V; 3]; 4],
    du: &[[V; 6]; 4],
    h: V,
    st: BlockState<'_>,
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
    let (c00, c01, c22, gk) = (mat.c00, mat.c01, mat.c22, mat.gk);
    let half_h = h * V::splat(0.5);
    let (mut n, mut m, mut q) = ([zero; 3], [zero; 3], [zero; 2]);
    for (p, (&zeta, &w)) in set.rule.points.iter().zip(&set.rule.weights).enumerate() {
        let z = half_h * V::splat(zeta);
        let de = [em[0] + z * kap[0], em[1] + z * kap[1], em[2] + z * kap[2]];
        let s = p * N_STRESS;
        let trial = [
            load::<V>(st.stress_old, s) + c00 * de[0] + c01 * de[1],
            load::<V>(st.stress_old, s + 1) + c01 * de[0] + c00 * de[1],
            load::<V>(st.stress_old, s + 2) + c22 * de[2],
        ];
        let r = return_plane_stress_with(
            &mat.ret,
            trial,
            load::<V>(st.alpha_old, p),
            set.newton,
            set.return_tol,
        );
        let syz = load::<V>(st.stress_old, s + 3) + gk * gyz;
        let szx = load::<V>(st.stress_old, s + 4) + gk * gxz;
        for k in 0..3 {
            store(st.stress_new, s + k, r.sigma[k]);
        }
        store(st.stress_new, s + 3, syz);
        store(st.stress_new, s + 4, szx);
        store(st.alpha_new, p, r.alpha);
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
    let (one, minus_one) = (V::splat(1.0), V::splat(-1.0));
    let hv = [one, minus_one, one, minus_one];
    let hx = hv[0] * fe.x[0] + hv[1] * fe.x[1] + hv[2] * fe.x[2] + hv[3] * fe.x[3];
    let hy = hv[0] * fe.y[0] + hv[1] * fe.y[1] + hv[2] * fe.y[2] + hv[3] * fe.y[3];
    let mut g = [zero; 4];
    for i in 0..4 {
        g[i] = quarter * (hv[i] - hx * fe.b1[i] - hy * fe.b2[i]);
    }
    let mut bb = zero;
    for i in 0..4 {
        bb += fe.b1[i] * fe.b1[i] + fe.b2[i] * fe.b2[i];
    }
    let r = V::splat(set.hourglass);
    let e = mat.e;
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
        qh[k] = load::<V>(st.hg_old, k) + kh[k] * qd[k];
        store(st.hg_new, k, qh[k]);
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
