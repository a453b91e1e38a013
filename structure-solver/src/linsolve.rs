//! The sparse direct solve of Newton iterations on the free dofs of a [`Model`] (DESIGN §6,
//! faer): the free-dof numbering, gather and scatter between full and free vectors, and the LU
//! factorisation of `c_k K_ff + c_m M_ff` whose symbolic analysis is reused while the sparsity
//! pattern does not change (the pattern of a model is fixed, so every Newton iteration after
//! the first redoes only the numeric factorisation).
//!
//! LU, not Cholesky: the corotational tangent is not symmetric away from equilibrium, and its
//! symmetric part slows Newton several-fold in large rotations.

use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::sparse::{SparseColMat, Triplet};
use faer::Mat;

use crate::model::Model;

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

/// LU factorisation of `c_k K_ff + c_m diag(m)_ff` with the symbolic analysis kept between
/// calls.
#[derive(Debug, Clone)]
pub struct FreeSolver {
    pub free: FreeDofs,
    triplets: Vec<Triplet<usize, usize, f64>>,
    /// Symbolic LU and the column pointers and row indices it was made for.
    symbolic: Option<(SymbolicLu<usize>, Vec<usize>, Vec<usize>)>,
}

impl FreeSolver {
    pub fn new(model: &dyn Model) -> Self {
        FreeSolver { free: FreeDofs::new(model), triplets: Vec::new(), symbolic: None }
    }

    /// Factors `ck K_ff + cm diag(mass)_ff` (`mass: None` for a static tangent) from the full
    /// triplets `k` (entries on constrained dofs are dropped, duplicates summed).
    pub fn factor(
        &mut self,
        k: &[Triplet<usize, usize, f64>],
        ck: f64,
        mass: Option<(f64, &[f64])>,
    ) -> Result<Lu<usize, f64>, FactorError> {
        let free = &self.free;
        self.triplets.clear();
        self.triplets.extend(k.iter().filter_map(|e| {
            match (free.index(e.row), free.index(e.col)) {
                (Some(i), Some(j)) => Some(Triplet::new(i, j, ck * e.val)),
                _ => None,
            }
        }));
        if let Some((cm, m)) = mass {
            for (d, &mi) in m.iter().enumerate() {
                if let Some(i) = free.index(d) {
                    self.triplets.push(Triplet::new(i, i, cm * mi));
                }
            }
        }
        let err = |e: &dyn std::fmt::Debug| FactorError(format!("{e:?}"));
        let n = free.n_free;
        let a = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &self.triplets)
            .map_err(|e| err(&e))?;
        let same = self.symbolic.as_ref().is_some_and(|(_, cp, ri)| {
            cp.as_slice() == a.symbolic().col_ptr() && ri.as_slice() == a.symbolic().row_idx()
        });
        if !same {
            let sym = SymbolicLu::try_new(a.symbolic()).map_err(|e| err(&e))?;
            self.symbolic =
                Some((sym, a.symbolic().col_ptr().to_vec(), a.symbolic().row_idx().to_vec()));
        }
        let sym = self.symbolic.as_ref().map(|s| s.0.clone()).expect("set above");
        Lu::try_new_with_symbolic(sym, a.as_ref()).map_err(|e| err(&e))
    }
}
