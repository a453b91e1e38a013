//! Assembly of triplet values into a compressed-column matrix through a precomputed slot per
//! triplet: the pattern of a triplet stream (the `(row, col)` of every triplet, in the order
//! the model emits them) is read once; afterwards a values-only stream in the same order
//! becomes the column values with no sort, no search and no allocation. Duplicates are summed
//! in emission order, so the values are bitwise those of the serial sum `a[slot(k)] += v_k`
//! over `k = 0, 1, …`, whatever the thread count.

use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use rayon::prelude::*;

use super::FactorError;

/// Slot of a triplet that is dropped (an entry on a constrained dof).
const DROPPED: usize = usize::MAX;

/// Spot checks of a reused map: every `SPOT`-th triplet's indices against its slot.
const SPOT: usize = 61;

/// Length and order-sensitive hash of a triplet stream's indices: a cheap test that a stream
/// still has the pattern a [`ScatterMap`] was made for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Fingerprint {
    pub count: usize,
    pub hash: u64,
}

/// SplitMix64's finaliser.
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

impl Fingerprint {
    /// The fingerprint of the `count` index pairs `index(k)`: a wrapping sum of a hash of
    /// `(k, row, col)` (in parallel; the same for any thread count).
    pub fn of(count: usize, index: impl Fn(usize) -> (usize, usize) + Sync) -> Self {
        let hash = (0..count)
            .into_par_iter()
            .with_min_len(1 << 14)
            .map(|k| {
                let (i, j) = index(k);
                mix(mix(mix(k as u64) ^ i as u64) ^ j as u64)
            })
            .reduce(|| 0, u64::wrapping_add);
        Fingerprint { count, hash }
    }

    /// The fingerprint of the indices of the stream `k`.
    pub fn of_tangent(k: &super::Tangent) -> Self {
        Fingerprint::of(k.len(), |t| k.index(t))
    }
}

/// The slot in a compressed-column pattern of each triplet of a fixed stream, and the
/// triplets of each slot in emission order.
#[derive(Debug, Clone)]
pub struct ScatterMap {
    /// Slot of each triplet (`DROPPED`: not assembled).
    slot: Vec<usize>,
    /// The triplets summed into slot `s`: `source[start[s]..start[s + 1]]`, increasing (32
    /// bits: the scatter reads one per triplet).
    start: Vec<usize>,
    source: Vec<u32>,
    fingerprint: Fingerprint,
}

impl ScatterMap {
    /// The map of the `count` triplets `index(k)` (`None`: dropped) onto the pattern
    /// `col_ptr`, `row_idx` (rows sorted in each column). Errors with the first triplet whose
    /// entry the pattern lacks.
    pub fn onto(
        col_ptr: &[usize],
        row_idx: &[usize],
        count: usize,
        index: impl Fn(usize) -> Option<(usize, usize)> + Sync,
        fingerprint: Fingerprint,
    ) -> Result<Self, FactorError> {
        let n_slots = row_idx.len();
        let ncols = col_ptr.len() - 1;
        if u32::try_from(count).is_err() {
            return Err(FactorError(format!("{count} triplets: at most {} fit", u32::MAX)));
        }
        let mut slot = vec![DROPPED; count];
        slot.par_iter_mut().enumerate().with_min_len(4096).try_for_each(|(k, s)| {
            let Some((i, j)) = index(k) else { return Ok(()) };
            let found = (j < ncols)
                .then(|| {
                    let (a, b) = (col_ptr[j], col_ptr[j + 1]);
                    row_idx[a..b].binary_search(&i).ok().map(|p| a + p)
                })
                .flatten();
            *s = found.ok_or_else(|| {
                FactorError(format!("triplet {k}: entry ({i}, {j}) is not in the matrix pattern"))
            })?;
            Ok(())
        })?;
        // counting sort of the triplets by slot; stable, so each slot lists them in order
        let mut start = vec![0usize; n_slots + 1];
        for &s in slot.iter().filter(|&&s| s != DROPPED) {
            start[s + 1] += 1;
        }
        for s in 0..n_slots {
            start[s + 1] += start[s];
        }
        let mut fill = start[..n_slots].to_vec();
        let mut source = vec![0u32; start[n_slots]];
        for (k, &s) in slot.iter().enumerate().filter(|(_, &s)| s != DROPPED) {
            source[fill[s]] = k as u32; // count fits (checked above)
            fill[s] += 1;
        }
        Ok(ScatterMap { slot, start, source, fingerprint })
    }

    /// The fingerprint of the stream this map was made for.
    pub fn fingerprint(&self) -> Fingerprint {
        self.fingerprint
    }

    /// Number of triplets of the stream.
    pub fn len(&self) -> usize {
        self.slot.len()
    }

    /// `true` for an empty stream.
    pub fn is_empty(&self) -> bool {
        self.slot.is_empty()
    }

    /// Number of slots of the pattern.
    pub fn n_slots(&self) -> usize {
        self.start.len() - 1
    }

    /// A cheap test that the `count` triplets `index(k)` still fit this map: the same length,
    /// and every `SPOT`-th triplet (and the last) in the row and column of its slot.
    pub fn spot_check(
        &self,
        col_ptr: &[usize],
        row_idx: &[usize],
        count: usize,
        index: impl Fn(usize) -> Option<(usize, usize)>,
    ) -> bool {
        count == self.slot.len()
            && (0..count).step_by(SPOT).chain(count.checked_sub(1)).all(|k| {
                match (index(k), self.slot[k]) {
                    (None, s) => s == DROPPED,
                    (Some(_), DROPPED) => false,
                    (Some((i, j)), s) => {
                        row_idx[s] == i
                            && j + 1 < col_ptr.len()
                            && (col_ptr[j]..col_ptr[j + 1]).contains(&s)
                    }
                }
            })
    }

    /// `out[s] = Σ value(k)` over the triplets `k` of slot `s`, summed from 0 in emission
    /// order (slots without triplets get 0); in parallel over slots, the same bits for any
    /// thread count.
    pub fn scatter_with(&self, value: impl Fn(usize) -> f64 + Sync, out: &mut [f64]) {
        assert_eq!(out.len(), self.n_slots(), "values of the wrong pattern");
        let (start, source) = (&self.start, &self.source);
        out.par_iter_mut().enumerate().with_min_len(2048).for_each(|(s, o)| {
            *o = source[start[s]..start[s + 1]].iter().fold(0.0, |acc, &k| acc + value(k as usize));
        });
    }

    /// [`Self::scatter_with`] of a values-only stream `values` (one per triplet, in order).
    pub fn scatter(&self, values: &[f64], out: &mut [f64]) {
        assert_eq!(values.len(), self.len(), "values of the wrong stream");
        self.scatter_with(|k| values[k], out);
    }
}

/// A compressed-column pattern made from a triplet stream's indices (sorted rows, duplicates
/// merged) and its [`ScatterMap`].
#[derive(Debug, Clone)]
pub struct SparsePattern {
    nrows: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    map: ScatterMap,
}

impl SparsePattern {
    /// The pattern of the entries `entries` (`(row, col)`, in emission order) of an
    /// `nrows x ncols` matrix; an entry out of range is an error naming it.
    pub fn new(
        nrows: usize,
        ncols: usize,
        entries: &[(usize, usize)],
    ) -> Result<Self, FactorError> {
        if let Some((k, &(i, j))) =
            entries.iter().enumerate().find(|(_, &(i, j))| i >= nrows || j >= ncols)
        {
            return Err(FactorError(format!(
                "triplet {k}: entry ({i}, {j}) is outside the {nrows} x {ncols} matrix"
            )));
        }
        let mut col_ptr = vec![0usize; ncols + 1];
        for &(_, j) in entries {
            col_ptr[j + 1] += 1;
        }
        for j in 0..ncols {
            col_ptr[j + 1] += col_ptr[j];
        }
        let mut fill = col_ptr[..ncols].to_vec();
        let mut rows = vec![0usize; entries.len()];
        for &(i, j) in entries {
            rows[fill[j]] = i;
            fill[j] += 1;
        }
        let mut row_idx = Vec::with_capacity(rows.len());
        let mut ptr = vec![0usize; ncols + 1];
        for j in 0..ncols {
            let col = &mut rows[col_ptr[j]..col_ptr[j + 1]];
            col.sort_unstable();
            let first = row_idx.len();
            for &i in col.iter() {
                if row_idx.len() == first || row_idx.last() != Some(&i) {
                    row_idx.push(i);
                }
            }
            ptr[j + 1] = row_idx.len();
        }
        let fingerprint = Fingerprint::of(entries.len(), |k| entries[k]);
        let map =
            ScatterMap::onto(&ptr, &row_idx, entries.len(), |k| Some(entries[k]), fingerprint)?;
        Ok(SparsePattern { nrows, col_ptr: ptr, row_idx, map })
    }

    /// The column pointers and row indices.
    pub fn symbolic(&self) -> SymbolicSparseColMatRef<'_, usize> {
        SymbolicSparseColMatRef::new_checked(
            self.nrows,
            self.col_ptr.len() - 1,
            &self.col_ptr,
            None,
            &self.row_idx,
        )
    }

    /// The scatter map of the stream.
    pub fn map(&self) -> &ScatterMap {
        &self.map
    }

    /// Number of stored entries.
    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }

    /// The column values of a values-only stream into `out` (length `nnz()`).
    pub fn scatter(&self, values: &[f64], out: &mut [f64]) {
        self.map.scatter(values, out);
    }

    /// The matrix of values `val` (from [`Self::scatter`]) on this pattern.
    pub fn matrix<'a>(&'a self, val: &'a [f64]) -> SparseColMatRef<'a, usize, f64> {
        SparseColMatRef::new(self.symbolic(), val)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::sparse::{SparseColMat, Triplet};

    /// A pseudo-random stream with many duplicates, out of order.
    fn stream(n: usize, len: usize) -> (Vec<(usize, usize)>, Vec<f64>) {
        let mut z = 12345u64;
        let mut next = move || {
            z = mix(z.wrapping_add(0x9e37_79b9_7f4a_7c15));
            z
        };
        let entries = (0..len)
            .map(|_| ((next() % n as u64) as usize, (next() % n as u64) as usize))
            .collect();
        let values = (0..len).map(|_| (next() >> 11) as f64 / (1u64 << 53) as f64 - 0.5).collect();
        (entries, values)
    }

    #[test]
    fn scatter_is_bitwise_the_serial_triplet_sum() {
        let (n, len) = (40, 20_000);
        let (entries, values) = stream(n, len);
        let p = SparsePattern::new(n, n, &entries).unwrap();
        let mut got = vec![f64::NAN; p.nnz()];
        p.scatter(&values, &mut got);
        // the triplet path: each triplet's slot found by search, summed in emission order
        let mut want = vec![0.0; p.nnz()];
        for (&(i, j), v) in entries.iter().zip(&values) {
            let r = &p.row_idx[p.col_ptr[j]..p.col_ptr[j + 1]];
            want[p.col_ptr[j] + r.binary_search(&i).unwrap()] += v;
        }
        assert!(got.iter().zip(&want).all(|(a, b)| a.to_bits() == b.to_bits()));
        // and the same matrix as faer's triplet assembly (its own summation order)
        let trip: Vec<_> =
            entries.iter().zip(&values).map(|(&(i, j), &v)| Triplet::new(i, j, v)).collect();
        let faer = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &trip).unwrap();
        let (a, b) = (p.matrix(&got).to_dense(), faer.to_dense());
        let diff = (0..n).flat_map(|i| (0..n).map(move |j| (i, j)));
        let err = diff.map(|(i, j)| (a[(i, j)] - b[(i, j)]).abs()).fold(0.0, f64::max);
        assert!(err < 1e-12, "{err}");
        assert_eq!(p.nnz(), faer.compute_nnz());
        // a one-thread pool gives the same bits
        let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
        let mut one = vec![0.0; p.nnz()];
        pool.install(|| p.scatter(&values, &mut one));
        assert!(one.iter().zip(&got).all(|(a, b)| a.to_bits() == b.to_bits()));
    }

    #[test]
    fn fingerprint_and_spot_check_see_a_changed_stream() {
        let (entries, _) = stream(30, 5000);
        let p = SparsePattern::new(30, 30, &entries).unwrap();
        let f = Fingerprint::of(entries.len(), |k| entries[k]);
        assert_eq!(f, p.map().fingerprint());
        let mut swapped = entries.clone();
        swapped.swap(0, 1);
        if swapped[0] != entries[0] {
            assert_ne!(Fingerprint::of(swapped.len(), |k| swapped[k]), f);
        }
        let idx = |e: &[(usize, usize)], k: usize| Some(e[k]);
        assert!(p.map().spot_check(&p.col_ptr, &p.row_idx, entries.len(), |k| idx(&entries, k)));
        assert!(!p
            .map()
            .spot_check(&p.col_ptr, &p.row_idx, entries.len() - 1, |k| idx(&entries, k)));
        // the first triplet moved to another entry of the pattern
        let other = entries.iter().copied().find(|&e| e != entries[0]).unwrap();
        let mut moved = entries.clone();
        moved[0] = other;
        assert!(!p.map().spot_check(&p.col_ptr, &p.row_idx, moved.len(), |k| idx(&moved, k)));
    }

    #[test]
    fn an_entry_outside_the_pattern_is_named() {
        let p = SparsePattern::new(3, 3, &[(0, 0), (1, 2)]).unwrap();
        let fp = Fingerprint { count: 1, hash: 0 };
        let err = ScatterMap::onto(&p.col_ptr, &p.row_idx, 1, |_| Some((2, 1)), fp).unwrap_err();
        assert!(err.0.contains("triplet 0: entry (2, 1)"), "{}", err.0);
        let err = SparsePattern::new(3, 3, &[(0, 0), (3, 1)]).unwrap_err();
        assert!(err.0.contains("triplet 1: entry (3, 1) is outside the 3 x 3"), "{}", err.0);
    }
}
