//! The free-dof matrix `J` on its pattern, the supernodal `LDLᵀ` of its symmetric part (on
//! rayon's threads), and [`Factor`]: `J` with the `LDLᵀ` that preconditions its GMRES and
//! faer's LU of `J` as the fallback.

use std::sync::{Arc, OnceLock};

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::solvers::{ShapeCore, SolveCore};
use faer::sparse::linalg::cholesky::LdltRef;
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::sparse::SparseColMatRef;
use faer::{Conj, Mat, MatMut, Par, Side};
use rayon::prelude::*;

use super::gmres::{self, Limits, Operator, Outcome};
use super::pattern::Pattern;
use super::FactorError;

/// GMRES of a fresh factor: Krylov vectors per cycle and cycles before the LU fallback.
pub(super) const FRESH: Limits = Limits { restart: 30, cycles: 4 };

/// The parallelism of the factorisation and solves: rayon's threads of the calling pool (one
/// thread: sequential).
pub(super) fn threads() -> Par {
    match rayon::current_num_threads() {
        0 | 1 => Par::Seq,
        n => Par::rayon(n),
    }
}

/// The values of `J` on a pattern, with `|J|₁` and whether `J = Jᵀ` to round-off.
#[derive(Debug)]
pub(super) struct Jacobian {
    pub pattern: Arc<Pattern>,
    pub a: Vec<f64>,
    /// The values of `Jᵀ` on the pattern (`at[k] = a[transpose[k]]`): the rows of `J`, read in
    /// order by the products.
    pub at: Vec<f64>,
    pub symmetric: bool,
    pub norm1: f64,
}

impl Jacobian {
    /// `J` of the values `a` on `pattern`; a non-finite entry is an error naming its row and
    /// column (free-dof numbers).
    pub fn new(pattern: Arc<Pattern>, a: Vec<f64>) -> Result<Self, FactorError> {
        let p = &pattern;
        let mut at = p.take_any(a.len()); // every slot written
        at.par_iter_mut().zip(&p.transpose).with_min_len(4096).for_each(|(o, &t)| *o = a[t]);
        // one parallel pass over the columns: the first non-finite slot, the largest column
        // sum, skew entry and entry (maxima: the same for any thread count)
        let col = |j: usize| {
            let (mut bad, mut sum, mut skew, mut amax) = (usize::MAX, 0.0, 0.0f64, 0.0f64);
            for k in p.col_ptr[j]..p.col_ptr[j + 1] {
                let v = a[k];
                if !v.is_finite() && bad == usize::MAX {
                    bad = k;
                }
                sum += v.abs();
                skew = skew.max((v - at[k]).abs());
                amax = amax.max(v.abs());
            }
            (bad, sum, skew, amax)
        };
        let (bad, norm1, skew, amax) = (0..p.n).into_par_iter().with_min_len(256).map(col).reduce(
            || (usize::MAX, 0.0, 0.0, 0.0),
            |x, y| (x.0.min(y.0), x.1.max(y.1), x.2.max(y.2), x.3.max(y.3)),
        );
        if bad != usize::MAX {
            let j = p.col_ptr.partition_point(|&c| c <= bad) - 1;
            let err = format!(
                "non-finite matrix entry {} at free dofs ({}, {j})",
                a[bad], p.row_idx[bad]
            );
            p.give(a);
            p.give(at);
            return Err(FactorError(err));
        }
        Ok(Jacobian { symmetric: skew <= 1e-15 * amax, norm1, a, at, pattern })
    }

    /// `y = J x` (`transpose`: `Jᵀ x`).
    pub fn product(&self, x: &[f64], y: &mut [f64], transpose: bool) {
        let values = if transpose { &self.a } else { &self.at };
        self.pattern.product(values, x, y);
    }

    /// `J` (`transpose`: `Jᵀ`) as the operator of a GMRES solve.
    pub fn operator(&self, transpose: bool) -> Product<'_> {
        Product { j: self, transpose }
    }

    /// `J` as a faer matrix.
    pub fn matrix(&self) -> SparseColMatRef<'_, usize, f64> {
        SparseColMatRef::new(self.pattern.symbolic_ref(), &self.a)
    }
}

impl Drop for Jacobian {
    fn drop(&mut self) {
        self.pattern.give(std::mem::take(&mut self.a));
        self.pattern.give(std::mem::take(&mut self.at));
    }
}

/// An assembled `J` or `Jᵀ` as a GMRES [`Operator`].
pub(super) struct Product<'a> {
    j: &'a Jacobian,
    transpose: bool,
}

impl Operator for Product<'_> {
    fn apply(&mut self, x: &[f64], y: &mut [f64]) {
        self.j.product(x, y, self.transpose);
    }

    fn symmetric(&self) -> bool {
        self.j.symmetric
    }

    fn norm1(&self) -> f64 {
        self.j.norm1
    }
}

/// The `LDLᵀ` values of `S = ½(J + Jᵀ)` for some `J` on `pattern`.
#[derive(Debug)]
pub(super) struct Ldlt {
    pattern: Arc<Pattern>,
    values: Vec<f64>,
    /// `|J|₁` of the `J` factored.
    pub norm1: f64,
}

impl Ldlt {
    /// The supernodal `LDLᵀ` (no pivoting) of the symmetric part of `j` on rayon's threads;
    /// `None` at a zero pivot or a non-finite factor.
    pub fn of(j: &Jacobian) -> Option<Self> {
        let p = &j.pattern;
        let mut s = p.take_any(j.a.len()); // every slot written
        s.par_iter_mut().zip(&j.a).zip(&j.at).with_min_len(4096).for_each(|((sk, &v), &t)| {
            *sk = 0.5 * (v + t);
        });
        let mut values = p.take_any(p.symbolic.len_val()); // zeroed by the factorisation
        let par = threads();
        let ok = {
            let mut mem = MemBuffer::new(
                p.symbolic.factorize_numeric_ldlt_scratch::<f64>(par, Default::default()),
            );
            let mat = SparseColMatRef::new(p.symbolic_ref(), &s);
            p.symbolic
                .factorize_numeric_ldlt(
                    &mut values,
                    mat,
                    Side::Lower,
                    Default::default(),
                    par,
                    MemStack::new(&mut mem),
                    Default::default(),
                )
                .is_ok()
        } && values.iter().all(|v| v.is_finite());
        p.give(s);
        let ldlt = Ldlt { pattern: Arc::clone(p), values, norm1: j.norm1 };
        ok.then_some(ldlt)
    }

    /// `true` if this factors a matrix on `pattern`.
    pub fn is_on(&self, pattern: &Arc<Pattern>) -> bool {
        Arc::ptr_eq(&self.pattern, pattern)
    }

    /// `x = S⁻¹ x` in place, on one thread (faer's parallel triangular solves gain nothing on
    /// the bench plate: its supernodes are too small).
    pub fn solve_in_place(&self, x: &mut [f64]) {
        let p = &self.pattern;
        let par = Par::Seq;
        let mut mem = MemBuffer::new(p.symbolic.solve_in_place_scratch::<f64>(1, par));
        let n = x.len();
        let rhs = MatMut::from_column_major_slice_mut(x, n, 1);
        LdltRef::new(&p.symbolic, &self.values).solve_in_place_with_conj(
            Conj::No,
            rhs,
            par,
            MemStack::new(&mut mem),
        );
    }
}

impl Drop for Ldlt {
    fn drop(&mut self) {
        self.pattern.give(std::mem::take(&mut self.values));
    }
}

/// A free-dof matrix `J` and how it is solved: GMRES right-preconditioned with an `LDLᵀ` of
/// the symmetric part (of this `J`, or kept from an earlier one by `FreeSolver`), or LU of `J`.
/// Solves through faer's `Solve` (`factor.solve(&b)`).
#[derive(Debug)]
pub struct Factor {
    j: Jacobian,
    ldlt: Option<Arc<Ldlt>>,
    /// `ldlt` factors this `J`.
    fresh: bool,
    lu: OnceLock<Result<Lu<usize, f64>, String>>,
}

impl Factor {
    /// `J` without a preconditioner yet.
    pub(super) fn new(j: Jacobian) -> Self {
        Factor { j, ldlt: None, fresh: false, lu: OnceLock::new() }
    }

    /// Factors `J`: the `LDLᵀ` of its symmetric part, or (zero pivot) its LU.
    pub(super) fn refactor(&mut self) -> Result<(), FactorError> {
        self.ldlt = Ldlt::of(&self.j).map(Arc::new);
        self.fresh = true;
        if self.ldlt.is_none() {
            self.lu()?;
        }
        Ok(())
    }

    /// Preconditions with an earlier factorisation on the same pattern.
    pub(super) fn reuse(&mut self, kept: Arc<Ldlt>) {
        debug_assert!(kept.is_on(&self.j.pattern));
        self.ldlt = Some(kept);
        self.fresh = false;
    }

    pub(super) fn jacobian(&self) -> &Jacobian {
        &self.j
    }

    /// The `LDLᵀ` of this `J`, if it has been factored and had no zero pivot.
    pub(super) fn fresh_ldlt(&self) -> Option<&Arc<Ldlt>> {
        self.ldlt.as_ref().filter(|_| self.fresh)
    }

    pub(super) fn is_fresh(&self) -> bool {
        self.fresh
    }

    /// The LU fallback, made on first use.
    fn lu(&self) -> Result<&Lu<usize, f64>, FactorError> {
        let p = &self.j.pattern;
        self.lu
            .get_or_init(|| {
                let sym = p
                    .symbolic_lu
                    .get_or_init(|| {
                        SymbolicLu::try_new(p.symbolic_ref()).map_err(|e| format!("{e:?}"))
                    })
                    .clone()?;
                Lu::try_new_with_symbolic(sym, self.j.matrix()).map_err(|e| format!("{e:?}"))
            })
            .as_ref()
            .map_err(|e| FactorError(e.clone()))
    }

    /// Solves `J x = b` (`transpose`: `Jᵀ x = b`). A reused factor runs one GMRES cycle and
    /// gives `x: None` if that does not converge; a fresh one runs `FRESH` and falls back to
    /// the LU of `J`.
    pub(super) fn solve_vec(
        &self,
        b: &[f64],
        transpose: bool,
        tol: f64,
    ) -> Result<Outcome, FactorError> {
        let out = match &self.ldlt {
            Some(m) if !self.fresh => {
                let one = Limits { restart: FRESH.restart, cycles: 1 };
                return Ok(gmres::solve(&mut self.j.operator(transpose), m, b, one, tol));
            }
            Some(m) => gmres::solve(&mut self.j.operator(transpose), m, b, FRESH, tol),
            None => Outcome { x: None, iterations: 0 },
        };
        if out.x.is_some() || !self.fresh {
            return Ok(out);
        }
        let lu = self.lu()?;
        let n = b.len();
        let mut m = Mat::from_fn(n, 1, |i, _| b[i]);
        if transpose {
            lu.solve_transpose_in_place_with_conj(Conj::No, m.as_mut());
        } else {
            lu.solve_in_place_with_conj(Conj::No, m.as_mut());
        }
        Ok(Outcome { x: Some((0..n).map(|i| m[(i, 0)]).collect()), iterations: out.iterations })
    }

    fn solve_columns(&self, mut rhs: MatMut<'_, f64>, transpose: bool) {
        let n = rhs.nrows();
        for c in 0..rhs.ncols() {
            let b: Vec<f64> = (0..n).map(|i| rhs[(i, c)]).collect();
            let x = match self.solve_vec(&b, transpose, super::SOLVE_TOL) {
                Ok(Outcome { x: Some(x), .. }) => x,
                // SolveCore cannot return an error: a failed solve gives NaN, which every
                // caller's finite check reports
                _ => vec![f64::NAN; n],
            };
            for (i, xi) in x.into_iter().enumerate() {
                rhs[(i, c)] = xi;
            }
        }
    }
}

impl ShapeCore for Factor {
    fn nrows(&self) -> usize {
        self.j.pattern.n
    }

    fn ncols(&self) -> usize {
        self.j.pattern.n
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
