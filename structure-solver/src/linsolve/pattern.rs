//! The structurally symmetric pattern the free-dof matrix lives on, its fill-reducing
//! ordering and symbolic `LDLᵀ`, and the products with values on it.

use std::sync::{Mutex, OnceLock};

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::perm::PermRef;
use faer::sparse::linalg::amd;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, SymbolicCholesky, SymmetricOrdering,
};
use faer::sparse::linalg::solvers::SymbolicLu;
use faer::sparse::SymbolicSparseColMatRef;
use faer::Side;
use rayon::prelude::*;

use super::{FreeDofs, Tangent};

/// A structurally symmetric sparse pattern (sorted rows, every diagonal entry present) and its
/// symbolic `LDLᵀ`.
#[derive(Debug)]
pub(super) struct Pattern {
    pub n: usize,
    pub col_ptr: Vec<usize>,
    pub row_idx: Vec<usize>,
    /// Slot of the transposed entry of each slot.
    pub transpose: Vec<usize>,
    /// Slot of each diagonal entry.
    pub diag: Vec<usize>,
    pub symbolic: SymbolicCholesky<usize>,
    /// Symbolic LU of the fallback, made on first use.
    pub symbolic_lu: OnceLock<Result<SymbolicLu<usize>, String>>,
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
    /// A pattern holding the free entries of `k` and of `old`: the full 6x6 node blocks of
    /// `k`'s entries, so that entries zero in the first tangent (a flat initial geometry) and
    /// nonzero later do not force a new analysis.
    pub fn covering(free: &FreeDofs, k: &Tangent, old: Option<&Pattern>) -> Result<Self, String> {
        let mut blocks: Vec<(usize, usize)> =
            k.triplets().map(|e| (e.row / 6, e.col / 6)).collect();
        blocks.sort_unstable();
        blocks.dedup();
        let new = blocks.iter().flat_map(|&(a, b)| {
            (0..36)
                .filter_map(move |c| Some((free.index(6 * a + c / 6)?, free.index(6 * b + c % 6)?)))
        });
        let old = old.into_iter().flat_map(|p| {
            (0..p.n).flat_map(move |j| {
                p.row_idx[p.col_ptr[j]..p.col_ptr[j + 1]].iter().map(move |&i| (i, j))
            })
        });
        Pattern::new(free.len(), new.chain(old), &free.nodes())
    }

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

    /// Number of slots (stored entries).
    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }

    /// An array of `len` values of no particular content (to be overwritten), from the pool
    /// if it has one.
    pub fn take_any(&self, len: usize) -> Vec<f64> {
        let mut v = self.pool.lock().map(|mut p| p.pop()).ok().flatten().unwrap_or_default();
        v.resize(len, 0.0);
        v
    }

    /// Returns an array to the pool.
    pub fn give(&self, v: Vec<f64>) {
        if let Ok(mut p) = self.pool.lock() {
            if p.len() < 8 {
                p.push(v);
            }
        }
    }

    pub fn symbolic_ref(&self) -> SymbolicSparseColMatRef<'_, usize> {
        SymbolicSparseColMatRef::new_checked(self.n, self.n, &self.col_ptr, None, &self.row_idx)
    }

    /// `y = Jᵀ x` for the values `a` of `J` on this pattern, in parallel over the entries of
    /// `y`; `J x` is this product with the values of `Jᵀ` (the pattern is structurally
    /// symmetric). Each `y_i` sums its terms in increasing column order whatever the thread
    /// count.
    pub fn product(&self, a: &[f64], x: &[f64], y: &mut [f64]) {
        let (ptr, rows) = (&self.col_ptr, &self.row_idx);
        y.par_iter_mut().enumerate().with_min_len(512).for_each(|(i, yi)| {
            let range = ptr[i]..ptr[i + 1];
            *yi = rows[range.clone()].iter().zip(&a[range]).map(|(&j, v)| v * x[j]).sum();
        });
    }
}
