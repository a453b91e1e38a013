//! The node phase of the explicit shell loops (`bt4`, `blt3`): element forces into nodal
//! forces over threads, bitwise independent of the thread count.
//!
//! The elements are cut into contiguous chunks, one task each ([`chunk_bounds`]):
//! - a node whose elements all lie in one chunk is *owned* by that chunk: its task adds the
//!   element forces straight into the node, in ascending element order;
//! - a node with elements in several chunks is *shared*: each of its elements writes its force
//!   to a row of a work array, and after the element pass ([`NodeScatter::sum_shared`]) the node
//!   sums its rows in ascending element order.
//!
//! Either way a node's force is the serial sum in ascending element order. One thread is one
//! chunk: no node is shared and no work array is written. With locality-renumbered meshes a
//! few percent of the nodes are shared, so the threaded pass moves little more memory than the
//! serial one.

use std::marker::PhantomData;

use rayon::prelude::*;

/// Chunks per thread of the element pass (room for rayon to even out uneven chunks).
const CHUNKS_PER_THREAD: usize = 8;
/// Fewest elements in a chunk.
const MIN_CHUNK_ELEMENTS: usize = 64;
/// Shared nodes per task of the node phase.
const NODES_PER_TASK: usize = 2048;
/// The slot of an element node owned by its chunk.
const OWNED: u32 = u32::MAX;

/// Element bounds `[0, .., n_elements]` of the chunks of the element pass on `threads`
/// threads, each a whole number of `align` elements but the last.
pub fn chunk_bounds(n_elements: usize, align: usize, threads: usize) -> Vec<usize> {
    let units = n_elements.div_ceil(align);
    let chunks = if threads <= 1 {
        1
    } else {
        (threads * CHUNKS_PER_THREAD).min(n_elements / MIN_CHUNK_ELEMENTS).max(1)
    };
    let per = units.div_ceil(chunks).max(1);
    let mut bounds: Vec<usize> = (0..units).step_by(per).map(|u| u * align).collect();
    bounds.push(n_elements);
    bounds
}

/// `a` cut at the unit bounds `bounds` (as from [`chunk_bounds`], in units of `per_unit`
/// values), one slice a chunk.
pub(crate) fn split_at_bounds<'a, T>(
    mut a: &'a mut [T],
    bounds: &[usize],
    per_unit: usize,
) -> Vec<&'a mut [T]> {
    bounds
        .windows(2)
        .map(|b| {
            let (head, tail) = std::mem::take(&mut a).split_at_mut((b[1] - b[0]) * per_unit);
            a = tail;
            head
        })
        .collect()
}

/// The chunks of an element pass, with the nodes they share and the rows those nodes sum.
#[derive(Debug, Clone, Default)]
pub(crate) struct NodeScatter {
    n_nodes: usize,
    nodes_per_element: usize,
    /// Element bounds of the chunks.
    bounds: Vec<usize>,
    /// Per element node: its row in `rows`, or [`OWNED`].
    slot: Vec<u32>,
    /// Row bounds of the chunks (a chunk's rows are contiguous).
    row_bounds: Vec<usize>,
    /// The shared nodes, ascending, and their rows in ascending element order:
    /// `entries[start[s]..start[s + 1]]`.
    shared: Vec<u32>,
    start: Vec<u32>,
    entries: Vec<u32>,
    /// Six forces per row.
    rows: Vec<f64>,
}

impl NodeScatter {
    /// The chunks `bounds` of the elements `conn` on `n_nodes` nodes.
    pub fn new<const K: usize>(conn: &[[u32; K]], n_nodes: usize, bounds: Vec<usize>) -> Self {
        assert_eq!(bounds.last().copied(), Some(conn.len()), "chunks of every element");
        // the chunk of each node's first element, and whether another chunk touches it
        let mut first = vec![u32::MAX; n_nodes];
        let mut shared = vec![false; n_nodes];
        for (c, w) in bounds.windows(2).enumerate() {
            for nodes in &conn[w[0]..w[1]] {
                for &n in nodes {
                    let n = n as usize;
                    assert!(n < n_nodes, "element node {n} of {n_nodes} nodes");
                    if first[n] == u32::MAX {
                        first[n] = c as u32;
                    } else if first[n] != c as u32 {
                        shared[n] = true;
                    }
                }
            }
        }
        // rows in ascending element order: each chunk's rows are contiguous
        let mut slot = vec![OWNED; K * conn.len()];
        let mut row_bounds = vec![0];
        let mut count = vec![0u32; n_nodes];
        let mut rows = 0u32;
        for w in bounds.windows(2) {
            for e in w[0]..w[1] {
                for (i, &n) in conn[e].iter().enumerate() {
                    if shared[n as usize] {
                        slot[K * e + i] = rows;
                        rows += 1;
                        count[n as usize] += 1;
                    }
                }
            }
            row_bounds.push(rows as usize);
        }
        let shared_nodes: Vec<u32> = (0..n_nodes as u32).filter(|&n| shared[n as usize]).collect();
        let mut start = Vec::with_capacity(shared_nodes.len() + 1);
        start.push(0u32);
        for &n in &shared_nodes {
            start.push(start.last().unwrap() + count[n as usize]);
        }
        // the place of each shared node's next row
        let mut next = vec![0u32; n_nodes];
        for (s, &n) in shared_nodes.iter().enumerate() {
            next[n as usize] = start[s];
        }
        let mut entries = vec![0u32; rows as usize];
        for (e, nodes) in conn.iter().enumerate() {
            for (i, &n) in nodes.iter().enumerate() {
                let r = slot[K * e + i];
                if r != OWNED {
                    entries[next[n as usize] as usize] = r;
                    next[n as usize] += 1;
                }
            }
        }
        NodeScatter {
            n_nodes,
            nodes_per_element: K,
            bounds,
            slot,
            row_bounds,
            shared: shared_nodes,
            start,
            entries,
            rows: vec![0.0; 6 * rows as usize],
        }
    }

    /// `true` when this was built for `n_nodes` nodes and the chunks `bounds`.
    pub fn fits(&self, n_nodes: usize, bounds: &[usize]) -> bool {
        self.n_nodes == n_nodes && self.bounds == bounds
    }

    /// Element bounds of the chunks.
    pub fn bounds(&self) -> &[usize] {
        &self.bounds
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        8 * (self.bounds.len() + self.row_bounds.len() + self.rows.len())
            + 4 * (self.slot.len() + self.shared.len() + self.start.len() + self.entries.len())
    }

    /// Shared nodes.
    #[cfg(test)]
    pub fn n_shared(&self) -> usize {
        self.shared.len()
    }

    /// One sink per chunk, adding into the nodal forces `f` (6 per node).
    pub fn sinks<'a>(&'a mut self, f: &'a mut [f64]) -> Vec<ChunkSink<'a>> {
        assert!(f.len() >= 6 * self.n_nodes, "6 forces per node");
        let f_ptr = f.as_mut_ptr();
        let k = self.nodes_per_element;
        let mut rest: &mut [f64] = &mut self.rows;
        let mut sinks = Vec::with_capacity(self.bounds.len() - 1);
        for (w, r) in self.bounds.windows(2).zip(self.row_bounds.windows(2)) {
            let (rows, tail) = std::mem::take(&mut rest).split_at_mut(6 * (r[1] - r[0]));
            rest = tail;
            sinks.push(ChunkSink {
                f: f_ptr,
                first_element: w[0],
                slot: &self.slot[k * w[0]..k * w[1]],
                nodes_per_element: k,
                first_row: r[0],
                rows,
                nodes: PhantomData,
            });
        }
        sinks
    }

    /// Adds the rows of each shared node to its force, in ascending element order, over the
    /// threads of the current pool (after every sink of [`NodeScatter::sinks`] is done).
    pub fn sum_shared(&self, f: &mut [f64]) {
        let nodes = NodePtr(f.as_mut_ptr());
        assert!(f.len() >= 6 * self.n_nodes, "6 forces per node");
        let rows = &self.rows;
        self.shared.par_chunks(NODES_PER_TASK).enumerate().for_each(|(task, shared)| {
            let nodes = &nodes;
            for (j, &n) in shared.iter().enumerate() {
                let s = task * NODES_PER_TASK + j;
                let mut sum = [0.0; 6];
                // SAFETY: `n < n_nodes` (checked at build) and `f` holds 6 per node; each
                // shared node appears once in `shared`, so no other task reads or writes
                // these six entries.
                let fnode =
                    unsafe { std::slice::from_raw_parts_mut(nodes.0.add(6 * n as usize), 6) };
                sum.copy_from_slice(fnode);
                for &r in &self.entries[self.start[s] as usize..self.start[s + 1] as usize] {
                    let src = &rows[6 * r as usize..6 * r as usize + 6];
                    for d in 0..6 {
                        sum[d] += src[d];
                    }
                }
                fnode.copy_from_slice(&sum);
            }
        });
    }
}

/// The nodal forces, written by several tasks at disjoint nodes.
struct NodePtr(*mut f64);
// SAFETY: the tasks that share a `NodePtr` write disjoint nodes (see its uses).
unsafe impl Sync for NodePtr {}

/// Where one chunk's element forces go: its owned nodes directly, its shared nodes' rows.
pub(crate) struct ChunkSink<'a> {
    f: *mut f64,
    first_element: usize,
    slot: &'a [u32],
    nodes_per_element: usize,
    first_row: usize,
    rows: &'a mut [f64],
    nodes: PhantomData<&'a mut [f64]>,
}

// SAFETY: a sink writes only its chunk's owned nodes of `f` (no other chunk has an element on
// them) and its own rows, so sinks of one `NodeScatter` may run on different threads.
unsafe impl Send for ChunkSink<'_> {}

impl ChunkSink<'_> {
    /// The chunk's elements.
    pub fn elements(&self) -> std::ops::Range<usize> {
        self.first_element..self.first_element + self.slot.len() / self.nodes_per_element
    }

    /// Adds the force `force` of element `e`'s local node `i`, node `n`. The calls of a node
    /// come in ascending element order.
    #[inline(always)]
    pub fn add(&mut self, e: usize, i: usize, n: u32, force: [f64; 6]) {
        let r = self.slot[(e - self.first_element) * self.nodes_per_element + i];
        if r == OWNED {
            // SAFETY: `n < n_nodes` (checked at build) and `f` holds 6 per node (checked in
            // `sinks`); `n` is owned by this chunk, so no other sink touches it, and the
            // node phase touches only shared nodes.
            let fnode = unsafe { std::slice::from_raw_parts_mut(self.f.add(6 * n as usize), 6) };
            for d in 0..6 {
                fnode[d] += force[d];
            }
        } else {
            let r = r as usize - self.first_row;
            self.rows[6 * r..6 * r + 6].copy_from_slice(&force);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A strip of `n` quads, numbered along it, and each element's forces.
    fn strip(n: usize) -> (Vec<[u32; 4]>, impl Fn(usize, usize) -> [f64; 6]) {
        let conn = (0..n as u32).map(|e| [2 * e, 2 * e + 2, 2 * e + 3, 2 * e + 1]).collect();
        let force =
            |e: usize, i: usize| std::array::from_fn(|d| ((e * 4 + i) * 6 + d) as f64 * 0.1 + 0.3);
        (conn, force)
    }

    fn forces(
        conn: &[[u32; 4]],
        force: &impl Fn(usize, usize) -> [f64; 6],
        bounds: Vec<usize>,
    ) -> Vec<f64> {
        let nn = 2 * conn.len() + 2;
        let mut scatter = NodeScatter::new(conn, nn, bounds);
        let mut f = vec![1.0 / 3.0; 6 * nn];
        for mut sink in scatter.sinks(&mut f) {
            for e in sink.elements() {
                for (i, &n) in conn[e].iter().enumerate() {
                    sink.add(e, i, n, force(e, i));
                }
            }
        }
        scatter.sum_shared(&mut f);
        f
    }

    #[test]
    fn chunked_sums_are_the_serial_sums_bitwise() {
        let (conn, force) = strip(1000);
        let serial = forces(&conn, &force, vec![0, 1000]);
        for threads in [2, 3, 8] {
            for align in [1, 8] {
                let bounds = chunk_bounds(1000, align, threads);
                assert!(bounds.len() > 2, "several chunks");
                let f = forces(&conn, &force, bounds);
                assert!(f.iter().zip(&serial).all(|(a, b)| a.to_bits() == b.to_bits()));
            }
        }
    }

    #[test]
    fn only_nodes_between_chunks_are_shared() {
        let (conn, _) = strip(1000);
        let bounds = chunk_bounds(1000, 8, 2);
        let chunks = bounds.len() - 1;
        let scatter = NodeScatter::new(&conn, 2002, bounds);
        // two nodes on each chunk boundary of the strip
        assert_eq!(scatter.n_shared(), 2 * (chunks - 1));
        let one = NodeScatter::new(&conn, 2002, chunk_bounds(1000, 8, 1));
        assert_eq!(one.n_shared(), 0);
        assert!(one.rows.is_empty());
    }

    #[test]
    fn chunks_are_aligned_and_cover_the_elements() {
        for (ne, align, threads) in [(100_000, 8, 2), (1001, 8, 2), (5, 8, 4), (0, 1, 2)] {
            let b = chunk_bounds(ne, align, threads);
            assert_eq!((b[0], *b.last().unwrap()), (0, ne));
            assert!(b.windows(2).all(|w| w[0] < w[1] || ne == 0));
            assert!(b[..b.len() - 1].iter().all(|x| x % align == 0));
        }
    }
}
