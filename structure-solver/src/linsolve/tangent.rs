//! A sparse matrix as a model emits it: dense blocks on lists of dofs (one per element,
//! column-major), then loose entries (springs, reductions, masses). The stream's order (the
//! blocks in order, each column by column, then the entries) is the order in which
//! duplicates are summed. Elements write their blocks in place, in parallel, and the
//! [`super::ScatterMap`] sums them into the matrix's slots: no triplet is made for them.

use faer::sparse::Triplet;

/// At most this many reduced dofs stand for one dof in [`Tangent::reduce`].
pub const MAX_EXPANSION: usize = 6;

/// The reduced dofs and coefficients `(dof, c)` of a dof in [`Tangent::reduce`]: its first
/// `len` pairs.
pub type Expansion = ([(usize, f64); MAX_EXPANSION], usize);

/// Dense blocks and loose entries of a sparse matrix.
#[derive(Debug, Clone, Default)]
pub struct Tangent {
    /// The dofs of block `b`: `dofs[dof_start[b]..dof_start[b + 1]]`.
    dofs: Vec<usize>,
    dof_start: Vec<usize>,
    /// The values of block `b`, column-major: `values[value_start[b]..value_start[b + 1]]`.
    values: Vec<f64>,
    value_start: Vec<usize>,
    /// Entries after the blocks, in order.
    pub entries: Vec<Triplet<usize, usize, f64>>,
}

impl From<Vec<Triplet<usize, usize, f64>>> for Tangent {
    /// A stream of loose entries only.
    fn from(entries: Vec<Triplet<usize, usize, f64>>) -> Self {
        Tangent { entries, ..Tangent::default() }
    }
}

impl Tangent {
    /// Empties the stream, keeping its memory.
    pub fn clear(&mut self) {
        self.dofs.clear();
        self.dof_start.clear();
        self.value_start.clear();
        self.values.clear();
        self.entries.clear();
    }

    /// Replaces the blocks by one block per dof list of `lists` and returns their values, one
    /// mutable slice per block, to be filled in parallel: the caller writes every value (they
    /// hold what the last call left, not zeros: a refill would write the whole array once more
    /// each Newton iteration).
    pub fn set_blocks<L: IntoIterator<Item = usize>>(
        &mut self,
        lists: impl Iterator<Item = L>,
    ) -> Vec<&mut [f64]> {
        self.dofs.clear();
        self.dof_start.clear();
        self.value_start.clear();
        self.dof_start.push(0);
        self.value_start.push(0);
        let mut total = 0;
        for l in lists {
            let first = self.dofs.len();
            self.dofs.extend(l);
            let n = self.dofs.len() - first;
            self.dof_start.push(self.dofs.len());
            total += n * n;
            self.value_start.push(total);
        }
        self.values.resize(total, 0.0);
        let mut out = Vec::with_capacity(self.dof_start.len() - 1);
        let mut rest = &mut self.values[..];
        for w in self.value_start.windows(2) {
            let (head, tail) = rest.split_at_mut(w[1] - w[0]);
            out.push(head);
            rest = tail;
        }
        out
    }

    /// Number of blocks.
    pub fn n_blocks(&self) -> usize {
        self.dof_start.len().saturating_sub(1)
    }

    /// Entries of the stream (block entries and loose ones).
    pub fn len(&self) -> usize {
        self.values.len() + self.entries.len()
    }

    /// `true` for an empty stream.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The dofs of block `b` and its values (column-major).
    fn block(&self, b: usize) -> (&[usize], &[f64]) {
        let d = &self.dofs[self.dof_start[b]..self.dof_start[b + 1]];
        (d, &self.values[self.value_start[b]..self.value_start[b + 1]])
    }

    /// `(row, col)` of stream entry `k`.
    pub fn index(&self, k: usize) -> (usize, usize) {
        if k >= self.values.len() {
            let e = &self.entries[k - self.values.len()];
            return (e.row, e.col);
        }
        let b = self.value_start.partition_point(|&s| s <= k) - 1;
        let (dofs, _) = self.block(b);
        let a = k - self.value_start[b];
        (dofs[a % dofs.len()], dofs[a / dofs.len()])
    }

    /// Value of stream entry `k`.
    #[inline]
    pub fn value(&self, k: usize) -> f64 {
        match self.values.get(k) {
            Some(&v) => v,
            None => self.entries[k - self.values.len()].val,
        }
    }

    /// Every entry in stream order, as triplets.
    pub fn triplets(&self) -> impl Iterator<Item = Triplet<usize, usize, f64>> + '_ {
        let blocks = (0..self.n_blocks()).flat_map(move |b| {
            let (dofs, v) = self.block(b);
            let n = dofs.len();
            (0..n * n).map(move |a| Triplet::new(dofs[a % n], dofs[a / n], v[a]))
        });
        blocks.chain(self.entries.iter().copied())
    }

    /// `K ← Tᵀ K T` for a `T` that is the identity except at the dofs where `touched` holds,
    /// which stand for the combinations `expand(d)` of reduced dofs: a block with such a dof
    /// has its nonzero entries expanded, in stream order, ahead of the loose entries and is
    /// zeroed (its slots stay: the blocks keep their length and order whatever the values);
    /// a loose entry on such a dof is expanded where it stands.
    pub fn reduce(&mut self, touched: impl Fn(usize) -> bool, expand: impl Fn(usize) -> Expansion) {
        let mut out = Vec::new();
        let push = |out: &mut Vec<Triplet<usize, usize, f64>>, i: usize, j: usize, v: f64| {
            let ((rows, nr), (cols, nc)) = (expand(i), expand(j));
            for &(r, a) in &rows[..nr] {
                for &(c, b) in &cols[..nc] {
                    out.push(Triplet::new(r, c, a * v * b));
                }
            }
        };
        for b in 0..self.n_blocks() {
            let dofs = &self.dofs[self.dof_start[b]..self.dof_start[b + 1]];
            if !dofs.iter().any(|&d| touched(d)) {
                continue;
            }
            let n = dofs.len();
            for (a, v) in
                self.values[self.value_start[b]..self.value_start[b + 1]].iter_mut().enumerate()
            {
                if *v != 0.0 {
                    push(&mut out, dofs[a % n], dofs[a / n], *v);
                    *v = 0.0;
                }
            }
        }
        for e in std::mem::take(&mut self.entries) {
            if touched(e.row) || touched(e.col) {
                push(&mut out, e.row, e.col, e.val);
            } else {
                out.push(e);
            }
        }
        self.entries = out;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two 2-dof blocks sharing dof 1 and a loose entry.
    fn sample() -> Tangent {
        let mut k = Tangent::default();
        let mut blocks = k.set_blocks([vec![0, 1], vec![1, 2]].into_iter());
        blocks[0].copy_from_slice(&[4.0, -1.0, -2.0, 5.0]);
        blocks[1].copy_from_slice(&[3.0, 0.5, 0.0, 6.0]);
        k.entries.push(Triplet::new(2, 0, 7.0));
        k
    }

    fn dense(k: &Tangent, n: usize) -> Vec<f64> {
        let mut a = vec![0.0; n * n];
        for e in k.triplets() {
            a[e.row * n + e.col] += e.val;
        }
        a
    }

    #[test]
    fn index_and_value_follow_the_stream() {
        let k = sample();
        assert_eq!((k.len(), k.n_blocks()), (9, 2));
        let t: Vec<_> = k.triplets().collect();
        for (i, e) in t.iter().enumerate() {
            assert_eq!(k.index(i), (e.row, e.col));
            assert_eq!(k.value(i), e.val);
        }
        // column-major blocks: entry 1 of block 0 is (row 1, col 0)
        assert_eq!((t[1].row, t[1].col, t[1].val), (1, 0, -1.0));
        assert_eq!(dense(&k, 3), [4.0, -2.0, 0.0, -1.0, 8.0, 0.0, 7.0, 0.5, 6.0]);
    }

    #[test]
    fn reduce_is_the_congruence_with_the_expansion() {
        // dof 1 stands for 2 x dof 0 - dof 2: K' = Tᵀ K T with T the 3 x 3 identity but row 1
        let mut k = sample();
        let before = dense(&k, 3);
        let t = |i: usize, j: usize| match (i, j) {
            (1, 0) => 2.0,
            (1, 2) => -1.0,
            (1, 1) => 0.0,
            _ => f64::from(u8::from(i == j)),
        };
        let mut want = vec![0.0; 9];
        for (i, j, a, b) in (0..81).map(|q| (q / 27, (q / 9) % 3, (q / 3) % 3, q % 3)) {
            want[i * 3 + j] += t(a, i) * before[a * 3 + b] * t(b, j);
        }
        let len = k.len();
        k.reduce(
            |d| d == 1,
            |d| {
                let mut e = [(d, 1.0); MAX_EXPANSION];
                if d != 1 {
                    return (e, 1);
                }
                e[0] = (0, 2.0);
                e[1] = (2, -1.0);
                (e, 2)
            },
        );
        let got = dense(&k, 3);
        assert!(got.iter().zip(&want).all(|(a, b)| (a - b).abs() < 1e-12), "{got:?} {want:?}");
        // the blocks keep their slots; the touched ones are zeroed
        assert_eq!(k.n_blocks(), 2);
        assert!(k.len() > len);
        assert!((0..8).all(|i| k.value(i) == 0.0));
    }
}
