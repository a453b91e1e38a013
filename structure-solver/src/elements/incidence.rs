//! The node phase of the explicit shell loops (`bt4`, `blt3`): each element writes its nodal
//! forces to its own rows of a work array, then each node sums the rows of its elements in
//! ascending element order through a node-to-element incidence table built once. That is the
//! order of a serial scatter, so the sum is bitwise independent of the thread count and of
//! rayon's splitting.

use rayon::prelude::*;

/// Nodes per task of the node phase.
const NODES_PER_TASK: usize = 2048;

/// Node-to-element incidence of elements of `K` nodes: the work-array rows
/// `(element * K + local node)` of node `n` are `entries[start[n]..start[n + 1]]`, ascending.
#[derive(Debug, Clone, Default)]
pub(crate) struct Incidence {
    start: Vec<u32>,
    entries: Vec<u32>,
}

impl Incidence {
    pub fn new<const K: usize>(conn: &[[u32; K]], n_nodes: usize) -> Self {
        let mut start = vec![0u32; n_nodes + 1];
        for c in conn {
            for &n in c {
                start[n as usize + 1] += 1;
            }
        }
        for i in 0..n_nodes {
            start[i + 1] += start[i];
        }
        let mut next = start.clone();
        let mut entries = vec![0u32; K * conn.len()];
        for (e, c) in conn.iter().enumerate() {
            for (i, &n) in c.iter().enumerate() {
                entries[next[n as usize] as usize] = (K * e + i) as u32;
                next[n as usize] += 1;
            }
        }
        Incidence { start, entries }
    }

    pub fn n_nodes(&self) -> usize {
        self.start.len().saturating_sub(1)
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        4 * (self.start.len() + self.entries.len())
    }

    /// Adds to node `n`'s six entries of `f` the rows (six values each) of `rows` that belong
    /// to it, in ascending element order, over the threads of the current pool.
    pub fn add_rows(&self, rows: &[f64], f: &mut [f64]) {
        let nn = self.n_nodes();
        f[..6 * nn].par_chunks_mut(6 * NODES_PER_TASK).enumerate().for_each(|(task, fc)| {
            let n0 = task * NODES_PER_TASK;
            for (j, fnode) in fc.chunks_exact_mut(6).enumerate() {
                let n = n0 + j;
                for &c in &self.entries[self.start[n] as usize..self.start[n + 1] as usize] {
                    let src = &rows[6 * c as usize..6 * c as usize + 6];
                    for d in 0..6 {
                        fnode[d] += src[d];
                    }
                }
            }
        });
    }
}
