//! The numbering of the unconstrained dofs of a [`Model`], and the gather and scatter between
//! full vectors and free columns.

use faer::Mat;

use crate::model::Model;

/// Numbering of the unconstrained dofs.
#[derive(Debug, Clone, PartialEq, Eq)]
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

    /// Number of dofs, free and constrained.
    pub fn n_dof(&self) -> usize {
        self.index.len()
    }

    /// Free index of dof `d`, if it is free.
    pub fn index(&self, d: usize) -> Option<usize> {
        self.index.get(d).copied().flatten()
    }

    /// The node of each free dof, in free order (nondecreasing).
    pub fn nodes(&self) -> Vec<usize> {
        (0..self.index.len()).filter(|&d| self.index[d].is_some()).map(|d| d / 6).collect()
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

    /// Writes the free values `x` (free numbering) into the free entries of a full vector
    /// (others untouched).
    pub fn scatter_values(&self, x: &[f64], out: &mut [f64]) {
        for (d, i) in self.index.iter().enumerate() {
            if let Some(i) = i {
                out[d] = x[*i];
            }
        }
    }

    /// The free entries of a full vector `v` into `out` (free numbering).
    pub fn gather_values(&self, v: &[f64], out: &mut [f64]) {
        for (d, i) in self.index.iter().enumerate() {
            if let Some(i) = i {
                out[*i] = v[d];
            }
        }
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
