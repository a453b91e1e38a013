//! Edge blocks for a deterministic parallel scatter over the edges (DESIGN §5, "sort edges by node
//! for locality").
//!
//! The nodes are cut into consecutive ranges `[s_b, s_{b+1})`; block `b` holds the edges whose
//! first node `i` lies in its range (a contiguous run of the edge list, which is sorted by
//! `(i, j)`). The cuts are chosen so that every edge of block `b` has its second node below
//! `s_{b+2}`: the edges of block `b` touch only the window `[s_b, s_{b+2})`. The windows of the
//! even blocks are then disjoint, and so are those of the odd blocks, so a loop over the edges
//! can add each edge's contribution straight into both end nodes: even blocks in parallel, then
//! odd blocks in parallel ([`EdgeBlocks::scatter`]). Within a block the edges go in ascending
//! order, so every node receives its contributions in an order fixed by the mesh alone: the
//! result is bitwise the same for any number of threads, with no per-edge buffer and no gather
//! pass.
//!
//! The cuts follow the reverse Cuthill-McKee numbering: a pair of consecutive blocks spans at
//! least the bandwidth of the node range, so the blocks are as small as that allows (but at least
//! [`MIN_BLOCK_NODES`] nodes), which keeps a block's nodes in cache and gives the threads many
//! blocks to share.

use rayon::prelude::*;
use std::ops::{Index, IndexMut, Range};

/// Smallest number of nodes of a block (the last one may be smaller).
pub const MIN_BLOCK_NODES: usize = 256;

/// Node cuts and edge ranges of the blocks.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct EdgeBlocks {
    /// `s_0 = 0 < s_1 < ... < s_B = n`.
    node_starts: Vec<u32>,
    /// First edge of each block, then the number of edges.
    edge_starts: Vec<u32>,
}

/// The part `[first, first + data.len())` of a nodal array that one block may write, indexed by
/// global node number.
pub struct Window<'a, T> {
    first: usize,
    data: &'a mut [T],
}

impl<'a, T> Window<'a, T> {
    /// The window over `data`, whose first entry is node `first`.
    pub fn new(first: usize, data: &'a mut [T]) -> Window<'a, T> {
        Window { first, data }
    }
}

impl<T> Index<usize> for Window<'_, T> {
    type Output = T;

    #[inline(always)]
    fn index(&self, node: usize) -> &T {
        &self.data[node - self.first]
    }
}

impl<T> IndexMut<usize> for Window<'_, T> {
    #[inline(always)]
    fn index_mut(&mut self, node: usize) -> &mut T {
        &mut self.data[node - self.first]
    }
}

impl EdgeBlocks {
    /// The blocks of `n` nodes joined by `edges` (sorted by `(i, j)`, `i < j`).
    pub fn new(n: usize, edges: &[[u32; 2]]) -> EdgeBlocks {
        // reach[i]: the largest second node of the edges of the nodes up to i (or i itself).
        let mut reach: Vec<u32> = (0..n as u32).collect();
        for &[i, j] in edges {
            reach[i as usize] = reach[i as usize].max(j);
        }
        for i in 1..n {
            reach[i] = reach[i].max(reach[i - 1]);
        }
        let mut node_starts = vec![0u32, n.min(MIN_BLOCK_NODES) as u32];
        while (*node_starts.last().expect("two cuts") as usize) < n {
            let k = node_starts.len();
            let (prev, last) = (node_starts[k - 2] as usize, node_starts[k - 1] as usize);
            // The block [prev, last) reaches reach[last - 1]: the next cut must lie beyond it.
            let next = (last + MIN_BLOCK_NODES).max(reach[last - 1] as usize + 1).min(n);
            debug_assert!(prev < last && last < next);
            node_starts.push(next as u32);
        }
        if n == 0 {
            node_starts.truncate(1);
        }
        let edge_starts =
            node_starts.iter().map(|&s| edges.partition_point(|e| e[0] < s) as u32).collect();
        EdgeBlocks { node_starts, edge_starts }
    }

    /// Number of blocks.
    pub fn len(&self) -> usize {
        self.node_starts.len() - 1
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The nodes of block `b` (the first nodes of its edges).
    pub fn nodes(&self, b: usize) -> Range<usize> {
        self.node_starts[b] as usize..self.node_starts[b + 1] as usize
    }

    /// The edges of block `b`.
    pub fn edges(&self, b: usize) -> Range<usize> {
        self.edge_starts[b] as usize..self.edge_starts[b + 1] as usize
    }

    /// The nodes block `b` may write: `[s_b, s_{b+2})`.
    pub fn window(&self, b: usize) -> Range<usize> {
        let end = self.node_starts[(b + 2).min(self.len())];
        self.node_starts[b] as usize..end as usize
    }

    /// The nodes no block has written yet when block `b` starts: its whole window for an even
    /// block (the even windows tile all nodes and run first), none for an odd one. A loop that
    /// accumulates into a nodal array clears these first, so it needs no separate clearing pass.
    pub fn fresh(&self, b: usize) -> Range<usize> {
        if b % 2 == 0 {
            self.window(b)
        } else {
            0..0
        }
    }

    /// The nodes whose accumulation is complete once block `b` is done (node `k` of block `c`
    /// hears only from blocks `c - 1` and `c`): the whole window of an odd block, the nodes of
    /// block 0 after block 0, none otherwise. Every node is complete after exactly one block, so
    /// a loop can finish its nodes (e.g. apply a time step) inside the same pass.
    pub fn completed(&self, b: usize) -> Range<usize> {
        if b % 2 == 1 {
            self.window(b)
        } else if b == 0 {
            self.nodes(0)
        } else {
            0..0
        }
    }

    /// Memory in bytes.
    pub fn memory_bytes(&self) -> usize {
        (self.node_starts.len() + self.edge_starts.len()) * 4
    }

    /// Runs `f(b, window of b)` for every block `b`: the even blocks in parallel, then the odd
    /// ones, each given the part of `data` (one entry per node) it may write. Returns the first
    /// error in that order (the later blocks of the failing phase still run; the next phase does
    /// not).
    pub fn scatter<T: Send, E: Send>(
        &self,
        data: &mut [T],
        f: impl Fn(usize, &mut Window<'_, T>) -> Result<(), E> + Sync,
    ) -> Result<(), E> {
        let mut none = vec![(); data.len()];
        self.scatter2(data, &mut none, |b, w, _| f(b, w))
    }

    /// [`EdgeBlocks::scatter`] over two nodal arrays at once.
    pub fn scatter2<T: Send, U: Send, E: Send>(
        &self,
        a: &mut [T],
        c: &mut [U],
        f: impl Fn(usize, &mut Window<'_, T>, &mut Window<'_, U>) -> Result<(), E> + Sync,
    ) -> Result<(), E> {
        for phase in 0..2 {
            let mut windows = Vec::with_capacity(self.len() / 2 + 1);
            let (mut rest_a, mut rest_c) = (&mut a[..], &mut c[..]);
            let mut offset = 0;
            for b in (phase..self.len()).step_by(2) {
                let w = self.window(b);
                let (_, tail_a) = rest_a.split_at_mut(w.start - offset);
                let (mine_a, tail_a) = tail_a.split_at_mut(w.len());
                let (_, tail_c) = rest_c.split_at_mut(w.start - offset);
                let (mine_c, tail_c) = tail_c.split_at_mut(w.len());
                windows.push((
                    b,
                    Window { first: w.start, data: mine_a },
                    Window { first: w.start, data: mine_c },
                ));
                (rest_a, rest_c) = (tail_a, tail_c);
                offset = w.end;
            }
            let results: Vec<Result<(), E>> =
                windows.par_iter_mut().with_max_len(1).map(|(b, wa, wc)| f(*b, wa, wc)).collect();
            results.into_iter().collect::<Result<(), E>>()?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A band graph: node `i` joined to `i + 1` and `i + width`.
    fn band(n: u32, width: u32) -> Vec<[u32; 2]> {
        let mut edges = Vec::new();
        for i in 0..n {
            for j in [i + 1, i + width] {
                if j < n {
                    edges.push([i, j]);
                }
            }
        }
        edges
    }

    /// Every edge stays in its block's window, the windows of one parity are disjoint, and every
    /// node is fresh once and completed once, for one block, a few and many.
    #[test]
    fn windows_fresh_and_completed_partition_the_nodes() {
        for (n, width) in [(100, 7), (1000, 300), (5000, 40), (5000, 1500)] {
            let edges = band(n, width);
            let blocks = EdgeBlocks::new(n as usize, &edges);
            let mut fresh = vec![0; n as usize];
            let mut completed = vec![0; n as usize];
            for b in 0..blocks.len() {
                for &[i, j] in &edges[blocks.edges(b)] {
                    assert!(blocks.nodes(b).contains(&(i as usize)));
                    assert!(blocks.window(b).contains(&(j as usize)));
                }
                if b >= 2 {
                    assert_eq!(blocks.window(b - 2).end, blocks.window(b).start);
                }
                blocks.fresh(b).for_each(|i| fresh[i] += 1);
                blocks.completed(b).for_each(|i| completed[i] += 1);
            }
            assert!(fresh.iter().chain(&completed).all(|&c| c == 1), "n {n} width {width}");
            assert_eq!(blocks.edges(blocks.len() - 1).end, edges.len());
        }
        assert!(EdgeBlocks::new(0, &[]).is_empty());
    }

    /// A scatter that counts each edge at both ends gives the node degrees, whatever the pool.
    #[test]
    fn scatter_adds_every_edge_once() {
        let edges = band(3000, 90);
        let blocks = EdgeBlocks::new(3000, &edges);
        assert!(blocks.len() > 4);
        let mut degree = vec![0u32; 3000];
        let result = blocks.scatter(&mut degree, |b, d| {
            for i in blocks.fresh(b) {
                d[i] = 0;
            }
            for &[i, j] in &edges[blocks.edges(b)] {
                d[i as usize] += 1;
                d[j as usize] += 1;
            }
            Ok::<(), ()>(())
        });
        assert_eq!(result, Ok(()));
        let mut expected = vec![0u32; 3000];
        for &[i, j] in &edges {
            expected[i as usize] += 1;
            expected[j as usize] += 1;
        }
        assert_eq!(degree, expected);
    }
}
