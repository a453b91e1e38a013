//! Element-independent corotation (EICR; Rankin & Nour-Omid 1988, Felippa & Haugen 2005,
//! CMAME 194:2285). One frame rule per element family, one filter for all of them: the rigid
//! motion of an element is removed by a corotated frame `E` attached to its current nodes, the
//! deformational displacements `d = [u_dᵢ, θ_dᵢ]` are measured in that frame against the initial
//! local geometry, a small-strain local element maps `d` to local forces `f_l`, and the global
//! forces are `f = Bᵀ f_l` with `B = ∂d/∂q` the exact variation of `d` with respect to the nodal
//! translations and spatial spins `q` (the projector `P` and the `H⁻¹` map of Felippa-Haugen in
//! one matrix). `f` is the exact gradient of the local energy, so the force is conservative
//! and invariant under rigid motion of any size.

use nalgebra::{DMatrix, Matrix3, Vector3};

use super::rotation::{exp, log, spin, tangent_inverse, tangent_inverse_transpose_derivative};

/// How an element's corotated frame follows its nodes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FrameRule {
    /// 3-node shell: `e1` along side 1-2, `e3` normal to the plane of the nodes.
    Triangle,
    /// 4-node shell: `e3` along the cross product of the diagonals (the mean plane of a warped
    /// quad), `e1` along the difference of the diagonals.
    Quad,
    /// 2-node beam: `e1` along the chord, `e2` from the mean of the nodal triads applied to
    /// the initial `e2`, `q0` (global).
    Beam { q0: [f64; 3] },
}

/// A corotated frame and the linearisation of its spin.
#[derive(Debug, Clone)]
pub struct Frame {
    /// Columns `e1, e2, e3` (global components).
    pub e: Matrix3<f64>,
    /// Frame origin: the centroid of the nodes.
    pub xc: Vector3<f64>,
    /// `ω̄ = Σ_j gx[j] δx_j + gr[j] δω_j`: frame spin in frame components from global nodal
    /// translations and spins.
    /// (Up to 4 nodes; entries past the element's node count are zero.)
    pub gx: [Matrix3<f64>; 4],
    pub gr: [Matrix3<f64>; 4],
}

fn row(v: Vector3<f64>) -> nalgebra::RowVector3<f64> {
    v.transpose()
}

/// The frame of `rule` at nodal positions `x` and nodal rotations `r` (total, from the initial
/// configuration).
pub fn frame(rule: FrameRule, x: &[Vector3<f64>], r: &[Matrix3<f64>]) -> Frame {
    let n = x.len();
    let xc = x.iter().sum::<Vector3<f64>>() / n as f64;
    let mut gx = [Matrix3::zeros(); 4];
    let mut gr = [Matrix3::zeros(); 4];
    match rule {
        FrameRule::Triangle | FrameRule::Quad => {
            // p, q: the two spanning vectors; a = p × q gives e3, b (⟂ a) gives e1.
            let (p, q, ip, iq) = if rule == FrameRule::Triangle {
                (x[1] - x[0], x[2] - x[0], [1usize, 0], [2usize, 0])
            } else {
                (x[2] - x[0], x[3] - x[1], [2usize, 0], [3usize, 1])
            };
            let a = p.cross(&q);
            let b = if rule == FrameRule::Triangle { p } else { p - q };
            let (na, nb) = (a.norm(), b.norm());
            let e3 = a / na;
            let e1 = b / nb;
            let e2 = e3.cross(&e1);
            // ω1 = -e2·δa/|a|, ω2 = e1·δa/|a|, ω3 = e2·δb/|b|, with
            // c·δa = δp·(q × c) + δq·(c × p).
            let mut gp = Matrix3::zeros();
            let mut gq = Matrix3::zeros();
            for (k, c) in [(0usize, -e2), (1usize, e1)] {
                gp.set_row(k, &row(q.cross(&c) / na));
                gq.set_row(k, &row(c.cross(&p) / na));
            }
            gp.set_row(2, &row(e2 / nb));
            if rule == FrameRule::Quad {
                gq.set_row(2, &row(-e2 / nb));
            }
            // δp = δx[ip0] - δx[ip1], δq = δx[iq0] - δx[iq1]
            gx[ip[0]] += gp;
            gx[ip[1]] -= gp;
            gx[iq[0]] += gq;
            gx[iq[1]] -= gq;
            Frame { e: Matrix3::from_columns(&[e1, e2, e3]), xc, gx, gr }
        }
        FrameRule::Beam { q0 } => {
            let q0 = Vector3::from(q0);
            let chord = x[1] - x[0];
            let l = chord.norm();
            let e1 = chord / l;
            let qs = [r[0] * q0, r[1] * q0];
            let qm = 0.5 * (qs[0] + qs[1]);
            let c = e1.cross(&qm);
            let nc = c.norm();
            let e3 = c / nc;
            let e2 = e3.cross(&e1);
            // δe1 = (I - e1 e1ᵀ) δchord / l
            let pe = (Matrix3::identity() - e1 * e1.transpose()) / l;
            // ω3 = e2·δe1, ω2 = -e3·δe1, ω1 = -[δe1·(q × e2) - ½ Σ δω_j·(q_j × e3)] / |e1 × q|
            let mut g = Matrix3::zeros();
            g.set_row(0, &(-row(qm.cross(&e2)) * pe / nc));
            g.set_row(1, &(-row(e3) * pe));
            g.set_row(2, &(row(e2) * pe));
            gx[1] += g;
            gx[0] -= g;
            for j in 0..2 {
                gr[j].set_row(0, &row(0.5 * qs[j].cross(&e3) / nc));
            }
            Frame { e: Matrix3::from_columns(&[e1, e2, e3]), xc, gx, gr }
        }
    }
}

/// The initial geometry of a corotated element: its frame and local nodal coordinates.
#[derive(Debug, Clone)]
pub struct Reference {
    pub rule: FrameRule,
    /// Initial frame `E0`.
    pub e0: Matrix3<f64>,
    /// Initial local coordinates `aᵢ = E0ᵀ (Xᵢ - X_c)`.
    pub a: Vec<Vector3<f64>>,
}

impl Reference {
    /// The reference of an element with initial nodal positions `x0`.
    pub fn new(rule: FrameRule, x0: &[Vector3<f64>]) -> Self {
        let ident = vec![Matrix3::identity(); x0.len()];
        let f = frame(rule, x0, &ident);
        let a = x0.iter().map(|p| f.e.transpose() * (p - f.xc)).collect();
        Reference { rule, e0: f.e, a }
    }

    /// Deformational displacements `d` (6 per node, local frame) at positions `x` and nodal
    /// rotations `r`; with `b`, also `B = ∂d/∂q` (q: global translations and spatial spins).
    pub fn deformation(
        &self,
        x: &[Vector3<f64>],
        r: &[Matrix3<f64>],
        d: &mut [f64],
        b: Option<&mut DMatrix<f64>>,
    ) -> Frame {
        let n = x.len();
        let f = frame(self.rule, x, r);
        let et = f.e.transpose();
        let mut bl = [Vector3::zeros(); 4];
        let mut tinv = [Matrix3::zeros(); 4];
        for i in 0..n {
            let bi = et * (x[i] - f.xc);
            let ud = bi - self.a[i];
            let th = log(&(et * r[i] * self.e0));
            d[6 * i..6 * i + 3].copy_from_slice(ud.as_slice());
            d[6 * i + 3..6 * i + 6].copy_from_slice(th.as_slice());
            bl[i] = bi;
            if b.is_some() {
                tinv[i] = tangent_inverse(&th);
            }
        }
        if let Some(bm) = b {
            bm.fill(0.0);
            let inv_n = 1.0 / n as f64;
            for i in 0..n {
                let sb = spin(&bl[i]);
                for j in 0..n {
                    let kron = if i == j { 1.0 } else { 0.0 };
                    let uxx = et * (kron - inv_n) + sb * f.gx[j];
                    let uxr = sb * f.gr[j];
                    let txx = -tinv[i] * f.gx[j];
                    let txr = tinv[i] * (et * kron - f.gr[j]);
                    for (bi, bj, m) in [(0, 0, uxx), (0, 3, uxr), (3, 0, txx), (3, 3, txr)] {
                        bm.fixed_view_mut::<3, 3>(6 * i + bi, 6 * j + bj).copy_from(&m);
                    }
                }
            }
        }
        f
    }
}

impl Reference {
    /// Global forces `f = Bᵀ f_l` for local forces `local(d) = f_l`, without forming `B`:
    /// with `m = Σᵢ [bᵢ]×ᵀ f_uᵢ - T⁻ᵀ(θᵢ) f_θᵢ`, `f_xⱼ = E (f_uⱼ - mean f_u) + gxⱼᵀ m` and
    /// `f_ωⱼ = E T⁻ᵀ(θⱼ) f_θⱼ + grⱼᵀ m`.
    pub fn force(
        &self,
        x: &[Vector3<f64>],
        r: &[Matrix3<f64>],
        d: &mut [f64],
        local: impl FnOnce(&[f64], &mut [f64]),
        f: &mut [f64],
    ) {
        let n = x.len();
        let fr = self.deformation(x, r, d, None);
        let mut fl = [0.0; 24];
        local(d, &mut fl[..6 * n]);
        let et = fr.e.transpose();
        let mut mean = Vector3::zeros();
        let mut m = Vector3::zeros();
        let mut ftheta = [Vector3::zeros(); 4];
        for i in 0..n {
            let fu = Vector3::new(fl[6 * i], fl[6 * i + 1], fl[6 * i + 2]);
            let ft = Vector3::new(fl[6 * i + 3], fl[6 * i + 4], fl[6 * i + 5]);
            let th = Vector3::new(d[6 * i + 3], d[6 * i + 4], d[6 * i + 5]);
            let bi = et * (x[i] - fr.xc);
            let tt = tangent_inverse(&th).transpose() * ft;
            mean += fu;
            m += spin(&bi).transpose() * fu - tt;
            ftheta[i] = tt;
        }
        mean /= n as f64;
        for j in 0..n {
            let fu = Vector3::new(fl[6 * j], fl[6 * j + 1], fl[6 * j + 2]);
            let fx = fr.e * (fu - mean) + fr.gx[j].transpose() * m;
            let fw = fr.e * ftheta[j] + fr.gr[j].transpose() * m;
            f[6 * j..6 * j + 3].copy_from_slice(fx.as_slice());
            f[6 * j + 3..6 * j + 6].copy_from_slice(fw.as_slice());
        }
    }
}

/// Relative step of the central differences of the frame's spin matrices.
const FRAME_STEP: f64 = 1e-5;

impl Reference {
    /// Consistent tangent `∂(Bᵀ f_l)/∂q = Bᵀ K_l B + K_G` of a corotated element at `x`, `r`
    /// with local forces `f_l` and local tangent `K_l` at the deformation `d` (from
    /// `deformation`, with `b` = `B` and `fr` its frame). `K_G`, the variation of `Bᵀ` at fixed
    /// `f_l` (Felippa & Haugen 2005, §6: the `K_GR`, `K_GP` and `K_GM` parts), is in closed
    /// form from `δE = E[ω̄]×`, `δbᵢ = B_uᵢ δq`, `δθᵢ = B_θᵢ δq` and `∂(T⁻ᵀ f)/∂θ`, except the
    /// variation of the frame's spin matrices `gx`, `gr` contracted with the moment vector `m`
    /// of `force`, which is by central differences of the frame alone (cross products only;
    /// translations, and for beams rotations, `FRAME_STEP` relative).
    #[allow(clippy::too_many_arguments)]
    pub fn tangent(
        &self,
        x: &[Vector3<f64>],
        r: &[Matrix3<f64>],
        d: &[f64],
        b: &DMatrix<f64>,
        fr: &Frame,
        fl: &[f64],
        kl: &DMatrix<f64>,
    ) -> DMatrix<f64> {
        let n = x.len();
        let size = 6 * n;
        let mut kt = b.transpose() * (kl * b);
        let e = fr.e;
        let et = e.transpose();
        let v3 = |s: &[f64], o: usize| Vector3::new(s[o], s[o + 1], s[o + 2]);
        // rows r0..r0+3 of column c of B
        let col3 = |r0: usize, c: usize| Vector3::new(b[(r0, c)], b[(r0 + 1, c)], b[(r0 + 2, c)]);
        // the columns of G = [gx₀ gr₀ gx₁ gr₁ …] (3 x size)
        let g: [Vector3<f64>; 24] = std::array::from_fn(|c| {
            let (j, k) = (c / 6, c % 6);
            match (c < size, k < 3) {
                (false, _) => Vector3::zeros(),
                (true, true) => fr.gx[j].column(k).into_owned(),
                (true, false) => fr.gr[j].column(k - 3).into_owned(),
            }
        });
        let mean = (0..n).map(|i| v3(fl, 6 * i)).sum::<Vector3<f64>>() / n as f64;
        // m = Σ [bᵢ]×ᵀ f_uᵢ - tᵢ and its variation Δm = Σ [f_uᵢ]× Δbᵢ - Mθᵢ Δθᵢ (columns)
        let mut m = Vector3::zeros();
        let mut dm = [Vector3::zeros(); 24];
        let mut t = [Vector3::zeros(); 4];
        let mut mth = [Matrix3::zeros(); 4];
        for i in 0..n {
            let (fu, ft, th) = (v3(fl, 6 * i), v3(fl, 6 * i + 3), v3(d, 6 * i + 3));
            let bi = et * (x[i] - fr.xc);
            t[i] = tangent_inverse(&th).transpose() * ft;
            mth[i] = tangent_inverse_transpose_derivative(&th, &ft);
            m += spin(&bi).transpose() * fu - t[i];
            let sf = spin(&fu);
            for (c, dmc) in dm[..size].iter_mut().enumerate() {
                *dmc += sf * col3(6 * i, c) - mth[i] * col3(6 * i + 3, c);
            }
        }
        for j in 0..n {
            let fu = v3(fl, 6 * j);
            let ax = -(e * spin(&(fu - mean)));
            let aw = -(e * spin(&t[j]));
            let em = e * mth[j];
            let (gxt, grt) = (fr.gx[j].transpose(), fr.gr[j].transpose());
            for c in 0..size {
                let rx = ax * g[c] + gxt * dm[c];
                let rw = aw * g[c] + em * col3(6 * j + 3, c) + grt * dm[c];
                for k in 0..3 {
                    kt[(6 * j + k, c)] += rx[k];
                    kt[(6 * j + 3 + k, c)] += rw[k];
                }
            }
        }
        // Δgxⱼᵀ m, Δgrⱼᵀ m: central differences of the frame
        let scale = (1..n).map(|i| (x[i] - x[0]).norm()).fold(0.0, f64::max);
        let rotations = matches!(self.rule, FrameRule::Beam { .. });
        let spin_terms = |f: &Frame, out: &mut [f64]| {
            for j in 0..n {
                out[6 * j..6 * j + 3].copy_from_slice((f.gx[j].transpose() * m).as_slice());
                out[6 * j + 3..6 * j + 6].copy_from_slice((f.gr[j].transpose() * m).as_slice());
            }
        };
        let (mut xp, mut rp) = (x.to_vec(), r.to_vec());
        let (mut hp, mut hm) = ([0.0; 24], [0.0; 24]);
        for k in 0..n {
            for c in 0..6 {
                if c >= 3 && !rotations {
                    continue;
                }
                let h = if c < 3 { FRAME_STEP * scale } else { FRAME_STEP };
                for (sign, out) in [(1.0, &mut hp), (-1.0, &mut hm)] {
                    if c < 3 {
                        xp[k][c] = x[k][c] + sign * h;
                    } else {
                        let mut w = Vector3::zeros();
                        w[c - 3] = sign * h;
                        rp[k] = exp(&w) * r[k];
                    }
                    spin_terms(&frame(self.rule, &xp, &rp), &mut out[..size]);
                    xp[k] = x[k];
                    rp[k] = r[k];
                }
                for i in 0..size {
                    kt[(i, 6 * k + c)] += (hp[i] - hm[i]) / (2.0 * h);
                }
            }
        }
        kt
    }
}

#[cfg(test)]
mod tests {
    use super::super::rotation::exp;
    use super::*;

    fn energy_and_force(
        re: &Reference,
        k: &DMatrix<f64>,
        x: &[Vector3<f64>],
        r: &[Matrix3<f64>],
    ) -> (f64, Vec<f64>) {
        let n = x.len();
        let mut d = vec![0.0; 6 * n];
        let mut b = DMatrix::zeros(6 * n, 6 * n);
        re.deformation(x, r, &mut d, Some(&mut b));
        let dv = nalgebra::DVector::from_vec(d);
        let fl = k * &dv;
        let e = 0.5 * dv.dot(&fl);
        (e, (b.transpose() * fl).as_slice().to_vec())
    }

    /// `Bᵀ K d` is the gradient of `½ dᵀ K d` for translations and spatial spins, for each
    /// frame rule, in a deformed and rotated configuration.
    #[test]
    fn force_is_gradient_of_local_energy() {
        let cases: Vec<(FrameRule, Vec<Vector3<f64>>)> = vec![
            (
                FrameRule::Triangle,
                vec![
                    Vector3::new(0.0, 0.0, 0.0),
                    Vector3::new(1.0, 0.1, 0.0),
                    Vector3::new(0.2, 0.9, 0.1),
                ],
            ),
            (
                FrameRule::Quad,
                vec![
                    Vector3::new(0.0, 0.0, 0.0),
                    Vector3::new(1.1, 0.0, 0.05),
                    Vector3::new(1.0, 0.9, 0.0),
                    Vector3::new(-0.1, 1.0, -0.03),
                ],
            ),
            (
                FrameRule::Beam { q0: [0.0, 1.0, 0.0] },
                vec![Vector3::new(0.0, 0.0, 0.0), Vector3::new(2.0, 0.0, 0.0)],
            ),
        ];
        for (rule, x0) in cases {
            let n = x0.len();
            let re = Reference::new(rule, &x0);
            // a symmetric positive local stiffness
            let m =
                DMatrix::from_fn(6 * n, 6 * n, |i, j| ((i * 7 + j * 3) % 11) as f64 / 11.0 - 0.4);
            let k = &m * m.transpose() + DMatrix::identity(6 * n, 6 * n);
            let x: Vec<_> = x0
                .iter()
                .enumerate()
                .map(|(i, p)| {
                    exp(&Vector3::new(0.3, -0.5, 0.8)) * p
                        + Vector3::new(0.05 * i as f64, 0.02, -0.03 * i as f64)
                })
                .collect();
            let r: Vec<_> = (0..n)
                .map(|i| exp(&Vector3::new(0.3 + 0.05 * i as f64, -0.5, 0.8 - 0.04 * i as f64)))
                .collect();
            let (_, f) = energy_and_force(&re, &k, &x, &r);
            let mut d = vec![0.0; 6 * n];
            let mut fast = vec![0.0; 6 * n];
            re.force(
                &x,
                &r,
                &mut d,
                |d, fl| {
                    fl.copy_from_slice((&k * nalgebra::DVector::from_column_slice(d)).as_slice())
                },
                &mut fast,
            );
            for (a, b) in fast.iter().zip(&f) {
                assert!(
                    (a - b).abs() < 1e-12 * (1.0 + b.abs()),
                    "{rule:?}: fast force {a} vs Bᵀf {b}"
                );
            }
            let h = 1e-6;
            for j in 0..n {
                for c in 0..3 {
                    let (mut xp, mut xm) = (x.clone(), x.clone());
                    xp[j][c] += h;
                    xm[j][c] -= h;
                    let fd = (energy_and_force(&re, &k, &xp, &r).0
                        - energy_and_force(&re, &k, &xm, &r).0)
                        / (2.0 * h);
                    assert!(
                        (fd - f[6 * j + c]).abs() < 1e-6,
                        "{rule:?} node {j} dir {c}: {fd} vs {}",
                        f[6 * j + c]
                    );
                    let mut w = Vector3::zeros();
                    w[c] = h;
                    let (mut rp, mut rm) = (r.clone(), r.clone());
                    rp[j] = exp(&w) * r[j];
                    rm[j] = exp(&(-w)) * r[j];
                    let fd = (energy_and_force(&re, &k, &x, &rp).0
                        - energy_and_force(&re, &k, &x, &rm).0)
                        / (2.0 * h);
                    assert!(
                        (fd - f[6 * j + 3 + c]).abs() < 1e-6,
                        "{rule:?} node {j} rot {c}: {fd} vs {}",
                        f[6 * j + 3 + c]
                    );
                }
            }
        }
    }
}
