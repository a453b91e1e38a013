//! Restarted GMRES (Saad & Schultz 1986) for `J x = b` right-preconditioned with an `LDLᵀ`
//! factorisation `S = L D Lᵀ`, symmetric, of `½(J + Jᵀ)` for this `J` or an earlier one:
//! `J S⁻¹ y = b`, `x = S⁻¹ y`, Givens rotations on the Hessenberg matrix. `J` is an
//! [`Operator`]: an assembled matrix, or the directional derivative of a residual
//! (matrix-free).

use super::factor::Ldlt;

/// The `J` GMRES solves with.
pub(super) trait Operator {
    /// `y = J x`.
    fn apply(&mut self, x: &[f64], y: &mut [f64]);
    /// `J = Jᵀ` to round-off (or nearly: GMRES then starts from `S⁻¹ b`).
    fn symmetric(&self) -> bool;
    /// `|J|₁`, the scale of the backward error.
    fn norm1(&self) -> f64;
}
/// Backward error `|b - J x| / (|J|₁ |x|)` accepted as converged (what a direct solve of an
/// ill-conditioned matrix gives) when the relative residual cannot reach the tolerance.
const BACKWARD_TOL: f64 = 1e-14;

/// Krylov vectors per cycle and cycles.
#[derive(Debug, Clone, Copy)]
pub(super) struct Limits {
    pub restart: usize,
    pub cycles: usize,
}

/// The solution if it reached the tolerance, and the preconditioner applications it took.
#[derive(Debug)]
pub(super) struct Outcome {
    pub x: Option<Vec<f64>>,
    pub iterations: usize,
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// Solves `J x = b` to a relative residual of `tol` (or the backward error `BACKWARD_TOL`).
/// A symmetric `J` starts from `x = S⁻¹ b` (exact when `S` is the factor of this `J`: one
/// iteration); otherwise from 0.
pub(super) fn solve(j: &mut dyn Operator, m: &Ldlt, b: &[f64], lim: Limits, tol: f64) -> Outcome {
    let n = b.len();
    let bn = norm(b);
    let mut x = vec![0.0; n];
    if bn == 0.0 {
        return Outcome { x: Some(x), iterations: 0 };
    }
    let mut iterations = 0;
    let mut r = b.to_vec();
    let mut w = vec![0.0; n];
    if j.symmetric() {
        x.copy_from_slice(b);
        m.solve_in_place(&mut x);
        iterations += 1;
        j.apply(&x, &mut w);
        for ((ri, bi), v) in r.iter_mut().zip(b).zip(&w) {
            *ri = bi - v;
        }
    }
    let norm1 = j.norm1();
    let converged = |r: &[f64], x: &[f64]| {
        let rn = norm(r);
        rn <= tol * bn || rn <= BACKWARD_TOL * norm1 * norm(x)
    };
    for _ in 0..lim.cycles {
        if converged(&r, &x) {
            return Outcome { x: Some(x), iterations };
        }
        let beta = norm(&r);
        let mut v: Vec<Vec<f64>> = vec![r.iter().map(|ri| ri / beta).collect()];
        let mut z: Vec<Vec<f64>> = Vec::new();
        let mut h: Vec<Vec<f64>> = Vec::new(); // columns, rotated to upper triangular
        let (mut cs, mut sn): (Vec<f64>, Vec<f64>) = (Vec::new(), Vec::new());
        let mut g = vec![beta];
        for k in 0..lim.restart {
            // z_k = S⁻¹ v_k, w = J z_k, orthogonalised against v_0..v_k (modified Gram-Schmidt)
            let mut zk = v[k].clone();
            m.solve_in_place(&mut zk);
            iterations += 1;
            j.apply(&zk, &mut w);
            let mut hk = vec![0.0; k + 2];
            for (i, vi) in v.iter().enumerate() {
                let d: f64 = w.iter().zip(vi).map(|(a, b)| a * b).sum();
                hk[i] = d;
                for (wl, vl) in w.iter_mut().zip(vi) {
                    *wl -= d * vl;
                }
            }
            let wn = norm(&w);
            hk[k + 1] = wn;
            // earlier rotations, then the one that zeroes h_{k+1,k}
            for i in 0..k {
                let t = cs[i] * hk[i] + sn[i] * hk[i + 1];
                hk[i + 1] = -sn[i] * hk[i] + cs[i] * hk[i + 1];
                hk[i] = t;
            }
            let rho = hk[k].hypot(hk[k + 1]);
            let (c, s) = if rho == 0.0 { (1.0, 0.0) } else { (hk[k] / rho, hk[k + 1] / rho) };
            hk[k] = rho;
            hk[k + 1] = 0.0;
            cs.push(c);
            sn.push(s);
            g.push(-s * g[k]);
            g[k] *= c;
            h.push(hk);
            z.push(zk);
            if g[k + 1].abs() <= 0.1 * tol * bn || wn == 0.0 {
                break;
            }
            v.push(w.iter().map(|wl| wl / wn).collect());
        }
        // back substitution H y = g, x += Z y, and the true residual
        let mm = h.len();
        let mut y = vec![0.0; mm];
        for i in (0..mm).rev() {
            let s: f64 = (i + 1..mm).map(|k| h[k][i] * y[k]).sum();
            y[i] = (g[i] - s) / h[i][i];
        }
        for (zk, yk) in z.iter().zip(&y) {
            for (xi, zi) in x.iter_mut().zip(zk) {
                *xi += yk * zi;
            }
        }
        j.apply(&x, &mut w);
        for ((ri, bi), wi) in r.iter_mut().zip(b).zip(&w) {
            *ri = bi - wi;
        }
    }
    let ok = converged(&r, &x) && x.iter().all(|v| v.is_finite());
    Outcome { x: ok.then_some(x), iterations }
}
