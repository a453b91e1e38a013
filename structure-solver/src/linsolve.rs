//! The sparse direct solve of Newton iterations on the free dofs of a [`Model`] (DESIGN §6,
//! faer): the free-dof numbering, gather and scatter between full and free vectors, and the
//! factorisation of `J = c_k K_ff + c_m M_ff`, solved through faer's `Solve` trait.
//!
//! The matrix lives on a structurally symmetric pattern (the full 6x6 node blocks of the
//! tangent's entries, every diagonal entry) made on the first call with its fill-reducing
//! ordering (AMD) and symbolic `LDLᵀ`; later calls find each triplet's slot (in O(1) when the
//! triplets come in the same order) and redo only the numeric factorisation, into value arrays
//! reused from the previous factorisations. The corotational tangent (and a follower load's)
//! is not symmetric away from equilibrium, and replacing it by its symmetric part would slow
//! Newton several-fold in large rotations, so `J` itself is solved: its symmetric part
//! `S = ½(J + Jᵀ)` is factored as `LDLᵀ` (supernodal, no pivoting, one thread: on the 61k-dof
//! plate of `bench` 6x to 10x faster than faer's sparse LU, whose COLAMD ordering and
//! partial pivoting make far more fill), and `J x = b` is solved by GMRES right-preconditioned
//! with `S⁻¹` to a relative residual of `SOLVE_TOL` (one step when the skew part is small
//! against `S`, as in shells and beams). Where `S` has a zero pivot or GMRES stalls, the solve
//! falls back to faer's LU with partial pivoting of `J` itself.

use std::sync::{Arc, Mutex, OnceLock};

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::solvers::{ShapeCore, SolveCore};
use faer::perm::PermRef;
use faer::sparse::linalg::amd;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, LdltRef, SymbolicCholesky, SymmetricOrdering,
};
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef, Triplet};
use faer::{Conj, Mat, MatMut, Par, Side};
use rayon::prelude::*;

use crate::model::Model;

/// Relative residual `|b - J x| / |b|` the solve reaches, or else the backward error
/// `|b - J x| / (|J|₁ |x|)` of `BACKWARD_TOL` (what a direct solve of an ill-conditioned
/// matrix gives).
pub const SOLVE_TOL: f64 = 1e-11;
const BACKWARD_TOL: f64 = 1e-14;

/// GMRES: Krylov vectors per cycle and cycles before the LU fallback.
const KRYLOV: usize = 30;
const CYCLES: usize = 4;

/// The matrix could not be assembled or factored.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct FactorError(pub String);

/// Numbering of the unconstrained dofs.
#[derive(Debug, Clone)]
pub struct FreeDofs {
    index: Vec<Option<usize>>,
    n_free: usize,
}

impl FreeDofs {
    /// The free dofs of `model` (those not constrained).
    pub fn new(model: &dyn Model) -> Self {
        let mut n_free = 0;
        let index = model
            .constrained()
            .iter()
            .map(|&c| {
                (!c).then(|| {
                    n_free += 1;
                    n_free - 1
                })
            })
            .collect();
        FreeDofs { index, n_free }
    }

    /// Number of free dofs.
    pub fn len(&self) -> usize {
        self.n_free
    }

    /// `true` when every dof is constrained.
    pub fn is_empty(&self) -> bool {
        self.n_free == 0
    }

    /// Free index of dof `d`, if it is free.
    pub fn index(&self, d: usize) -> Option<usize> {
        self.index.get(d).copied().flatten()
    }

    /// The free part of a full vector, as a column.
    pub fn gather(&self, v: &[f64]) -> Mat<f64> {
        let mut m = Mat::zeros(self.n_free, 1);
        for (d, i) in self.index.iter().enumerate() {
            if let Some(i) = i {
                m[(*i, 0)] = v[d];
            }
        }
        m
    }

    /// Writes a free column into the free entries of a full vector (others untouched).
    pub fn scatter(&self, m: &Mat<f64>, out: &mut [f64]) {
        for (d, i) in self.index.iter().enumerate() {
            if let Some(i) = i {
                out[d] = m[(*i, 0)];
            }
        }
    }
}

/// A structurally symmetric sparse pattern (sorted rows, every diagonal entry present) and its
/// symbolic `LDLᵀ`.
#[derive(Debug)]
struct Pattern {
    n: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    /// Slot of the transposed entry of each slot.
    transpose: Vec<usize>,
    /// Slot of each diagonal entry.
    diag: Vec<usize>,
    symbolic: SymbolicCholesky<usize>,
    /// Symbolic LU of the fallback, made on first use.
    symbolic_lu: OnceLock<Result<SymbolicLu<usize>, String>>,
    /// Value arrays of dropped factorisations, reused (fresh pages cost more than the
    /// factorisation's arithmetic).
    pool: Mutex<Vec<Vec<f64>>>,
}

/// A fill-reducing ordering of the dofs: AMD on the graph of the nodes (the dofs of a node
/// kept together), from the dof pattern `col_ptr`, `row_idx` and the node of each dof
/// (nondecreasing). Six times smaller a graph than the dofs', and supernodes of whole nodes.
fn node_ordering(
    col_ptr: &[usize],
    row_idx: &[usize],
    node: &[usize],
) -> Result<(Vec<usize>, Vec<usize>), String> {
    let n = node.len();
    // compact node numbers and the first dof of each
    let mut first = Vec::new();
    let mut compact = vec![0usize; n];
    for i in 0..n {
        if i == 0 || node[i] != node[i - 1] {
            first.push(i);
        }
        compact[i] = first.len() - 1;
    }
    let nn = first.len();
    first.push(n);
    let mut ptr = vec![0usize; nn + 1];
    let mut rows = Vec::new();
    let mut mark = vec![usize::MAX; nn];
    for c in 0..nn {
        let start = rows.len();
        for j in first[c]..first[c + 1] {
            for &i in &row_idx[col_ptr[j]..col_ptr[j + 1]] {
                let ci = compact[i];
                if mark[ci] != c {
                    mark[ci] = c;
                    rows.push(ci);
                }
            }
        }
        rows[start..].sort_unstable();
        ptr[c + 1] = rows.len();
    }
    let graph = SymbolicSparseColMatRef::new_checked(nn, nn, &ptr, None, &rows);
    let (mut p, mut pi) = (vec![0usize; nn], vec![0usize; nn]);
    let mut mem = MemBuffer::new(amd::order_scratch::<usize>(nn, rows.len()));
    amd::order(&mut p, &mut pi, graph, Default::default(), MemStack::new(&mut mem))
        .map_err(|e| format!("ordering: {e:?}"))?;
    let fwd: Vec<usize> = p.iter().flat_map(|&c| first[c]..first[c + 1]).collect();
    let mut inv = vec![0usize; n];
    for (k, &i) in fwd.iter().enumerate() {
        inv[i] = k;
    }
    Ok((fwd, inv))
}

impl Pattern {
    /// The pattern of the entries `(i, j)`, their transposes and the diagonal of an `n x n`
    /// matrix, and its fill-reducing ordering and symbolic factorisation; `node[i]`: the node
    /// of free dof `i` (nondecreasing).
    fn new(
        n: usize,
        entries: impl Iterator<Item = (usize, usize)> + Clone,
        node: &[usize],
    ) -> Result<Self, String> {
        let mut count = vec![1usize; n]; // the diagonal
        for (i, j) in entries.clone() {
            count[j] += 1;
            count[i] += 1;
        }
        let mut col_ptr = vec![0usize; n + 1];
        for j in 0..n {
            col_ptr[j + 1] = col_ptr[j] + count[j];
        }
        let mut fill = col_ptr[..n].to_vec();
        let mut rows = vec![0usize; col_ptr[n]];
        let mut put = |i: usize, j: usize| {
            rows[fill[j]] = i;
            fill[j] += 1;
        };
        for j in 0..n {
            put(j, j);
        }
        for (i, j) in entries {
            put(i, j);
            put(j, i);
        }
        // sort and deduplicate each column
        let mut row_idx = Vec::with_capacity(rows.len());
        let mut ptr = vec![0usize; n + 1];
        for j in 0..n {
            let col = &mut rows[col_ptr[j]..col_ptr[j + 1]];
            col.sort_unstable();
            let start = row_idx.len();
            for &i in col.iter() {
                if row_idx.len() == start || row_idx.last() != Some(&i) {
                    row_idx.push(i);
                }
            }
            ptr[j + 1] = row_idx.len();
        }
        let col_ptr = ptr;
        let find = |i: usize, j: usize| -> usize {
            let r = &row_idx[col_ptr[j]..col_ptr[j + 1]];
            col_ptr[j] + r.binary_search(&i).expect("symmetric pattern")
        };
        let mut transpose = vec![0usize; row_idx.len()];
        for j in 0..n {
            for k in col_ptr[j]..col_ptr[j + 1] {
                transpose[k] = find(j, row_idx[k]);
            }
        }
        let diag = (0..n).map(|j| find(j, j)).collect();
        let sym = SymbolicSparseColMatRef::new_checked(n, n, &col_ptr, None, &row_idx);
        let (fwd, inv) = node_ordering(&col_ptr, &row_idx, node)?;
        let perm = PermRef::new_checked(&fwd, &inv, n);
        let symbolic = factorize_symbolic_cholesky(
            sym,
            Side::Lower,
            SymmetricOrdering::Custom(perm),
            Default::default(),
        )
        .map_err(|e| format!("symbolic factorisation: {e:?}"))?;
        Ok(Pattern {
            n,
            col_ptr,
            row_idx,
            transpose,
            diag,
            symbolic,
            symbolic_lu: OnceLock::new(),
            pool: Mutex::new(Vec::new()),
        })
    }

    /// A zeroed array of `len` values, from the pool if it has one.
    fn take(&self, len: usize) -> Vec<f64> {
        let mut v = self.pool.lock().map(|mut p| p.pop()).ok().flatten().unwrap_or_default();
        v.clear();
        v.resize(len, 0.0);
        v
    }

    /// Returns an array to the pool.
    fn give(&self, v: Vec<f64>) {
        if let Ok(mut p) = self.pool.lock() {
            if p.len() < 6 {
                p.push(v);
            }
        }
    }

    /// Slot of entry `(i, j)`, if the pattern holds it.
    fn slot(&self, i: usize, j: usize) -> Option<usize> {
        let (a, b) = (self.col_ptr[j], self.col_ptr[j + 1]);
        self.row_idx[a..b].binary_search(&i).ok().map(|k| a + k)
    }

    fn symbolic_ref(&self) -> SymbolicSparseColMatRef<'_, usize> {
        SymbolicSparseColMatRef::new_checked(self.n, self.n, &self.col_ptr, None, &self.row_idx)
    }

    /// `y = J x` (`transpose`: `Jᵀ x`) for the values `a` on this pattern.
    fn product(&self, a: &[f64], x: &[f64], y: &mut [f64], transpose: bool) {
        if transpose {
            for (j, yj) in y.iter_mut().enumerate() {
                let range = self.col_ptr[j]..self.col_ptr[j + 1];
                *yj =
                    self.row_idx[range.clone()].iter().zip(&a[range]).map(|(&i, v)| v * x[i]).sum();
            }
        } else {
            y.fill(0.0);
            for (j, &xj) in x.iter().enumerate() {
                for k in self.col_ptr[j]..self.col_ptr[j + 1] {
                    y[self.row_idx[k]] += a[k] * xj;
                }
            }
        }
    }
}

/// Factorisation of `c_k K_ff + c_m diag(m)_ff` with the pattern and symbolic analysis kept
/// between calls.
#[derive(Debug, Clone)]
pub struct FreeSolver {
    pub free: FreeDofs,
    pattern: Option<Arc<Pattern>>,
    /// Slot in the pattern of each triplet of the last call (`usize::MAX`: constrained).
    slots: Vec<usize>,
}

impl FreeSolver {
    pub fn new(model: &dyn Model) -> Self {
        FreeSolver { free: FreeDofs::new(model), pattern: None, slots: Vec::new() }
    }

    /// Slots of the free triplets of `k` in the current pattern; `false` if some entry is not
    /// in it. A triplet at the same place as in the last call keeps its slot (checked in O(1)).
    fn locate(&mut self, k: &[Triplet<usize, usize, f64>]) -> bool {
        let (free, slots) = (&self.free, &mut self.slots);
        let Some(p) = &self.pattern else { return false };
        if slots.len() != k.len() {
            slots.clear();
            slots.resize(k.len(), usize::MAX);
        }
        slots.par_iter_mut().zip(k.par_iter()).with_min_len(4096).all(|(s, e)| {
            *s = match (free.index(e.row), free.index(e.col)) {
                (Some(i), Some(j)) => {
                    let same = *s < p.row_idx.len()
                        && p.row_idx[*s] == i
                        && (p.col_ptr[j]..p.col_ptr[j + 1]).contains(s);
                    if same {
                        *s
                    } else {
                        match p.slot(i, j) {
                            Some(s) => s,
                            None => return false,
                        }
                    }
                }
                _ => usize::MAX,
            };
            true
        })
    }

    /// Factors `ck K_ff + cm diag(mass)_ff` (`mass: None` for a static tangent) from the full
    /// triplets `k` (entries on constrained dofs are dropped, duplicates summed).
    pub fn factor(
        &mut self,
        k: &[Triplet<usize, usize, f64>],
        ck: f64,
        mass: Option<(f64, &[f64])>,
    ) -> Result<Factor, FactorError> {
        let n = self.free.n_free;
        if !self.locate(k) {
            // A new pattern: the old one (if any) and the full 6x6 node blocks of these
            // entries, so that entries zero in the first tangent (a flat initial geometry) and
            // nonzero later do not force a new analysis.
            let mut blocks: Vec<(usize, usize)> =
                k.iter().map(|e| (e.row / 6, e.col / 6)).collect();
            blocks.sort_unstable();
            blocks.dedup();
            let free = &self.free;
            let new = blocks.iter().flat_map(|&(a, b)| {
                (0..36).filter_map(move |c| {
                    Some((free.index(6 * a + c / 6)?, free.index(6 * b + c % 6)?))
                })
            });
            let old = self.pattern.iter().flat_map(|p| {
                (0..n).flat_map(move |j| {
                    p.row_idx[p.col_ptr[j]..p.col_ptr[j + 1]].iter().map(move |&i| (i, j))
                })
            });
            let node: Vec<usize> =
                (0..free.index.len()).filter(|&d| free.index(d).is_some()).map(|d| d / 6).collect();
            let pattern = Pattern::new(n, new.chain(old), &node).map_err(FactorError)?;
            self.pattern = Some(Arc::new(pattern));
            let located = self.locate(k);
            debug_assert!(located);
        }
        let pattern = Arc::clone(self.pattern.as_ref().expect("set above"));
        let mut a = pattern.take(pattern.row_idx.len());
        for (e, &s) in k.iter().zip(&self.slots) {
            if s != usize::MAX {
                a[s] += ck * e.val;
            }
        }
        if let Some((cm, m)) = mass {
            for (d, &mi) in m.iter().enumerate() {
                if let Some(i) = self.free.index(d) {
                    a[pattern.diag[i]] += cm * mi;
                }
            }
        }
        if let Some(bad) = a.iter().find(|v| !v.is_finite()) {
            return Err(FactorError(format!("non-finite matrix entry {bad}")));
        }
        let (mut skew, mut amax) = (0.0f64, 0.0f64);
        let mut s = pattern.take(a.len());
        for ((sk, &v), &t) in s.iter_mut().zip(&a).zip(&pattern.transpose) {
            skew = skew.max((v - a[t]).abs());
            amax = amax.max(v.abs());
            *sk = 0.5 * (v + a[t]);
        }
        let symmetric = skew <= 1e-15 * amax;
        let mut ldlt = pattern.take(pattern.symbolic.len_val());
        let par = Par::Seq;
        let ok = {
            let mut mem = MemBuffer::new(
                pattern.symbolic.factorize_numeric_ldlt_scratch::<f64>(par, Default::default()),
            );
            let mat = SparseColMatRef::new(pattern.symbolic_ref(), &s);
            pattern
                .symbolic
                .factorize_numeric_ldlt(
                    &mut ldlt,
                    mat,
                    Side::Lower,
                    Default::default(),
                    par,
                    MemStack::new(&mut mem),
                    Default::default(),
                )
                .is_ok()
        } && ldlt.iter().all(|v| v.is_finite());
        pattern.give(s);
        let ldlt = if ok {
            Some(ldlt)
        } else {
            pattern.give(ldlt);
            None
        };
        let norm1 = (0..n)
            .map(|j| a[pattern.col_ptr[j]..pattern.col_ptr[j + 1]].iter().map(|v| v.abs()).sum())
            .fold(0.0, f64::max);
        let factor = Factor { pattern, a, ldlt, symmetric, norm1, lu: OnceLock::new() };
        if !ok {
            factor.lu()?;
        }
        Ok(factor)
    }
}

/// The factorisation of a free-dof matrix `J`: `LDLᵀ` of its symmetric part with GMRES for
/// the skew part, or LU of `J`. Solves through faer's `Solve` (`factor.solve(&b)`).
#[derive(Debug)]
pub struct Factor {
    pattern: Arc<Pattern>,
    /// Values of `J` on the pattern.
    a: Vec<f64>,
    /// `LDLᵀ` values of `½(J + Jᵀ)`, if it factored.
    ldlt: Option<Vec<f64>>,
    /// `J = Jᵀ` to round-off: the `LDLᵀ` solve alone is exact.
    symmetric: bool,
    /// `|J|₁`, the largest column sum.
    norm1: f64,
    lu: OnceLock<Result<Lu<usize, f64>, String>>,
}

impl Factor {
    /// The LU fallback, made on first use.
    fn lu(&self) -> Result<&Lu<usize, f64>, FactorError> {
        let p = &self.pattern;
        self.lu
            .get_or_init(|| {
                let sym = p
                    .symbolic_lu
                    .get_or_init(|| {
                        SymbolicLu::try_new(p.symbolic_ref()).map_err(|e| format!("{e:?}"))
                    })
                    .clone()?;
                let mat = SparseColMatRef::new(p.symbolic_ref(), &self.a);
                Lu::try_new_with_symbolic(sym, mat).map_err(|e| format!("{e:?}"))
            })
            .as_ref()
            .map_err(|e| FactorError(e.clone()))
    }

    /// `x = S⁻¹ x` in place.
    fn precondition(&self, ldlt: &[f64], x: &mut [f64]) {
        let p = &self.pattern;
        let par = Par::Seq;
        let mut mem = MemBuffer::new(p.symbolic.solve_in_place_scratch::<f64>(1, par));
        let n = x.len();
        let rhs = MatMut::from_column_major_slice_mut(x, n, 1);
        LdltRef::new(&p.symbolic, ldlt).solve_in_place_with_conj(
            Conj::No,
            rhs,
            par,
            MemStack::new(&mut mem),
        );
    }

    /// Solves `J x = b` (`transpose`: `Jᵀ x = b`) by GMRES right-preconditioned with the
    /// `LDLᵀ` of the symmetric part; `None` if it does not reach `SOLVE_TOL`.
    fn gmres(&self, ldlt: &[f64], b: &[f64], transpose: bool) -> Option<Vec<f64>> {
        let n = b.len();
        let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
        let bn = norm(b);
        let mut x = vec![0.0; n];
        if bn == 0.0 {
            return Some(x);
        }
        let p = &self.pattern;
        let mut r = b.to_vec();
        if self.symmetric {
            // S = J: one preconditioned step, checked like the others
            x.copy_from_slice(b);
            self.precondition(ldlt, &mut x);
            let mut jx = vec![0.0; n];
            p.product(&self.a, &x, &mut jx, transpose);
            for ((ri, bi), v) in r.iter_mut().zip(b).zip(&jx) {
                *ri = bi - v;
            }
        }
        let converged = |r: &[f64], x: &[f64]| {
            let rn = norm(r);
            rn <= SOLVE_TOL * bn || rn <= BACKWARD_TOL * self.norm1 * norm(x)
        };
        let mut w = vec![0.0; n];
        for _ in 0..CYCLES {
            if converged(&r, &x) {
                return Some(x);
            }
            let beta = norm(&r);
            let mut v: Vec<Vec<f64>> = vec![r.iter().map(|ri| ri / beta).collect()];
            let mut z: Vec<Vec<f64>> = Vec::new();
            let mut h: Vec<Vec<f64>> = Vec::new(); // columns, rotated to upper triangular
            let (mut cs, mut sn): (Vec<f64>, Vec<f64>) = (Vec::new(), Vec::new());
            let mut g = vec![beta];
            for j in 0..KRYLOV {
                let mut zj = v[j].clone();
                self.precondition(ldlt, &mut zj);
                p.product(&self.a, &zj, &mut w, transpose);
                let mut hj = vec![0.0; j + 2];
                for (i, vi) in v.iter().enumerate() {
                    let d: f64 = w.iter().zip(vi).map(|(a, b)| a * b).sum();
                    hj[i] = d;
                    for (wk, vk) in w.iter_mut().zip(vi) {
                        *wk -= d * vk;
                    }
                }
                let wn = norm(&w);
                hj[j + 1] = wn;
                for i in 0..j {
                    let t = cs[i] * hj[i] + sn[i] * hj[i + 1];
                    hj[i + 1] = -sn[i] * hj[i] + cs[i] * hj[i + 1];
                    hj[i] = t;
                }
                let rho = hj[j].hypot(hj[j + 1]);
                let (c, s) = if rho == 0.0 { (1.0, 0.0) } else { (hj[j] / rho, hj[j + 1] / rho) };
                hj[j] = rho;
                hj[j + 1] = 0.0;
                cs.push(c);
                sn.push(s);
                g.push(-s * g[j]);
                g[j] *= c;
                h.push(hj);
                z.push(zj);
                if g[j + 1].abs() <= 0.1 * SOLVE_TOL * bn || wn == 0.0 {
                    break;
                }
                v.push(w.iter().map(|wk| wk / wn).collect());
            }
            // back substitution H y = g, x += Z y
            let m = h.len();
            let mut y = vec![0.0; m];
            for i in (0..m).rev() {
                let s: f64 = (i + 1..m).map(|k| h[k][i] * y[k]).sum();
                y[i] = (g[i] - s) / h[i][i];
            }
            for (zk, yk) in z.iter().zip(&y) {
                for (xi, zi) in x.iter_mut().zip(zk) {
                    *xi += yk * zi;
                }
            }
            p.product(&self.a, &x, &mut w, transpose);
            for ((ri, bi), wi) in r.iter_mut().zip(b).zip(&w) {
                *ri = bi - wi;
            }
        }
        converged(&r, &x).then_some(x)
    }

    fn solve_columns(&self, mut rhs: MatMut<'_, f64>, transpose: bool) {
        let n = rhs.nrows();
        for c in 0..rhs.ncols() {
            let b: Vec<f64> = (0..n).map(|i| rhs[(i, c)]).collect();
            let x = self.ldlt.as_ref().and_then(|l| self.gmres(l, &b, transpose));
            let x = x.unwrap_or_else(|| {
                let lu = self.lu().expect("LU of the free-dof matrix");
                let mut m = Mat::from_fn(n, 1, |i, _| b[i]);
                if transpose {
                    lu.solve_transpose_in_place_with_conj(Conj::No, m.as_mut());
                } else {
                    lu.solve_in_place_with_conj(Conj::No, m.as_mut());
                }
                (0..n).map(|i| m[(i, 0)]).collect()
            });
            for (i, xi) in x.into_iter().enumerate() {
                rhs[(i, c)] = xi;
            }
        }
    }
}

impl Drop for Factor {
    fn drop(&mut self) {
        self.pattern.give(std::mem::take(&mut self.a));
        if let Some(l) = self.ldlt.take() {
            self.pattern.give(l);
        }
    }
}

impl ShapeCore for Factor {
    fn nrows(&self) -> usize {
        self.pattern.n
    }

    fn ncols(&self) -> usize {
        self.pattern.n
    }
}

impl SolveCore<f64> for Factor {
    fn solve_in_place_with_conj(&self, _conj: Conj, rhs: MatMut<'_, f64>) {
        self.solve_columns(rhs, false);
    }

    fn solve_transpose_in_place_with_conj(&self, _conj: Conj, rhs: MatMut<'_, f64>) {
        self.solve_columns(rhs, true);
    }
}
