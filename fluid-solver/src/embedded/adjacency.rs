//! The node-to-edge and node-to-cell adjacency of the fluid mesh (compressed rows), built once per
//! mesh: the connectivity the flood fills of Alg. 4.1 step 4 and Alg. 4.2 step 5 walk, with each
//! node's shortest edge (the length scale of the occlusion tolerance), and the cells around each
//! node, from which the loads of Alg. 5.3 find the cells around the cut edges.

use crate::mesh::geometry::{norm, sub};
use crate::mesh::Mesh;
use crate::prefetch::prefetch;

/// For each node, the edges and the cells that touch it, ascending.
#[derive(Debug, Clone, PartialEq)]
pub struct NodeEdges {
    /// Node `i`'s edges are `edges[offsets[i]..offsets[i + 1]]`.
    offsets: Vec<u32>,
    /// Those node `i` starts (`[i, j]`, `j > i`) are `edges[owned[i]..offsets[i + 1]]`: the
    /// edges are sorted by `(i, j)`, so they are the row's last.
    owned: Vec<u32>,
    edges: Vec<u32>,
    /// Node `i`'s cells are `cells[cell_offsets[i]..cell_offsets[i + 1]]`.
    cell_offsets: Vec<u32>,
    cells: Vec<u32>,
    /// Shortest edge at each node (infinite for a node with no edge).
    pub h_min: Vec<f64>,
}

impl NodeEdges {
    pub fn build(mesh: &Mesh) -> NodeEdges {
        let n = mesh.n_nodes();
        let mut offsets = vec![0u32; n + 1];
        for &[i, j] in &mesh.edges {
            offsets[i as usize + 1] += 1;
            offsets[j as usize + 1] += 1;
        }
        for k in 0..n {
            offsets[k + 1] += offsets[k];
        }
        let mut fill = offsets.clone();
        // A node that starts no edge has an empty tail.
        let mut owned = offsets[1..].to_vec();
        let mut edges = vec![0u32; 2 * mesh.n_edges()];
        let mut h_min = vec![f64::INFINITY; n];
        // Edges are visited in ascending order, so each row comes out sorted.
        for (e, &[i, j]) in mesh.edges.iter().enumerate() {
            let l = norm(sub(mesh.coords[j as usize], mesh.coords[i as usize]));
            if e == 0 || mesh.edges[e - 1][0] != i {
                // The first edge node `i` starts: every edge it ends came before.
                owned[i as usize] = fill[i as usize];
            }
            for v in [i as usize, j as usize] {
                edges[fill[v] as usize] = e as u32;
                fill[v] += 1;
                h_min[v] = h_min[v].min(l);
            }
        }
        let (cell_offsets, cells) = node_cells(mesh);
        NodeEdges { offsets, owned, edges, cell_offsets, cells, h_min }
    }

    /// The cells with node `i` among their corners.
    #[inline]
    pub fn cells_of(&self, i: usize) -> &[u32] {
        &self.cells[self.cell_offsets[i] as usize..self.cell_offsets[i + 1] as usize]
    }

    /// The edges of node `i`.
    #[inline]
    pub fn edges_of(&self, i: usize) -> &[u32] {
        &self.edges[self.offsets[i] as usize..self.offsets[i + 1] as usize]
    }

    /// The edges node `i` starts (`[i, j]`, `j > i`), ascending: consecutive edge numbers.
    #[inline]
    pub fn owned_by(&self, i: usize) -> &[u32] {
        &self.edges[self.owned[i] as usize..self.offsets[i + 1] as usize]
    }

    /// Prefetch hints ([`crate::prefetch`]) for what [`NodeEdges::owned_by`] reads of node `i`:
    /// the row's bounds, then (once those are in cache) the row.
    #[inline]
    pub fn prefetch_owned(&self, i: usize, row: bool) {
        if row {
            prefetch(&self.edges, self.owned[i] as usize);
        } else {
            prefetch(&self.owned, i);
            prefetch(&self.offsets, i + 1);
        }
    }

    /// The neighbours of node `i`, each with the edge that joins them.
    #[inline]
    pub fn neighbours<'a>(
        &'a self,
        mesh: &'a Mesh,
        i: usize,
    ) -> impl Iterator<Item = (usize, u32)> + 'a {
        self.edges_of(i).iter().map(move |&e| {
            let [a, b] = mesh.edges[e as usize];
            (if a as usize == i { b as usize } else { a as usize }, e)
        })
    }

    /// The smallest box holding node `i` and its neighbours (Alg. 4.1 step 1).
    pub fn node_box(&self, mesh: &Mesh, i: usize) -> ([f64; 3], [f64; 3]) {
        let mut lo = mesh.coords[i];
        let mut hi = lo;
        for (j, _) in self.neighbours(mesh, i) {
            let p = mesh.coords[j];
            for d in 0..3 {
                lo[d] = lo[d].min(p[d]);
                hi[d] = hi[d].max(p[d]);
            }
        }
        (lo, hi)
    }

    /// Memory of the arrays in bytes.
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(&self.offsets[..])
            + std::mem::size_of_val(&self.owned[..])
            + std::mem::size_of_val(&self.edges[..])
            + std::mem::size_of_val(&self.h_min[..])
            + std::mem::size_of_val(&self.cell_offsets[..])
            + std::mem::size_of_val(&self.cells[..])
    }
}

/// The compressed node-to-cell rows of `mesh` (offsets, cells), each row ascending.
fn node_cells(mesh: &Mesh) -> (Vec<u32>, Vec<u32>) {
    let n = mesh.n_nodes();
    let mut offsets = vec![0u32; n + 1];
    for cell in &mesh.cells {
        for &v in cell.nodes() {
            offsets[v as usize + 1] += 1;
        }
    }
    for k in 0..n {
        offsets[k + 1] += offsets[k];
    }
    let mut fill = offsets.clone();
    let mut cells = vec![0u32; offsets[n] as usize];
    // Cells are visited in ascending order, so each row comes out sorted.
    for (c, cell) in mesh.cells.iter().enumerate() {
        for &v in cell.nodes() {
            cells[fill[v as usize] as usize] = c as u32;
            fill[v as usize] += 1;
        }
    }
    (offsets, cells)
}

/// The distinct `values` (each `< n`), ascending, through a bit set over `0..n`: one pass over
/// `n / 64` words instead of a sort (node or edge numbers around the surface).
pub fn ascending_once(n: usize, values: impl IntoIterator<Item = u32>) -> Vec<u32> {
    let mut bits = vec![0u64; n.div_ceil(64)];
    for v in values {
        bits[v as usize / 64] |= 1 << (v % 64);
    }
    let mut out = Vec::new();
    for (w, &word) in bits.iter().enumerate() {
        let mut word = word;
        while word != 0 {
            out.push(64 * w as u32 + word.trailing_zeros());
            word &= word - 1;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::boxmesh::{BoxCells, BoxSpec};

    /// The bit set gives what a sort and a dedup give, on repeated values up to the last of a
    /// range that is not a whole number of words.
    #[test]
    fn values_once_ascending_as_sorted() {
        let mut state = 3u64;
        for n in [1usize, 63, 64, 65, 1000] {
            let values: Vec<u32> = (0..3 * n)
                .map(|_| {
                    state =
                        state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                    ((state >> 33) % n as u64) as u32
                })
                .chain([n as u32 - 1, 0])
                .collect();
            let mut want = values.clone();
            want.sort_unstable();
            want.dedup();
            assert_eq!(ascending_once(n, values), want, "n = {n}");
        }
        assert!(ascending_once(10, []).is_empty());
    }

    #[test]
    fn every_edge_is_listed_at_both_ends() {
        let raw = BoxSpec::uniform([0.0; 3], [1.0; 3], [3, 2, 2], BoxCells::Tet).raw().unwrap();
        let mesh = Mesh::build(raw).unwrap();
        let adj = NodeEdges::build(&mesh);
        let mut count = vec![0; mesh.n_edges()];
        for i in 0..mesh.n_nodes() {
            let row = adj.edges_of(i);
            assert!(row.windows(2).all(|w| w[0] < w[1]));
            for (j, e) in adj.neighbours(&mesh, i) {
                let [a, b] = mesh.edges[e as usize];
                assert!((a as usize, b as usize) == (i.min(j), i.max(j)));
                count[e as usize] += 1;
            }
        }
        assert!(count.iter().all(|&c| c == 2));
        assert_eq!(adj.h_min, mesh.min_edge_length());
        // The edges each node starts, and those alone.
        for i in 0..mesh.n_nodes() {
            let want: Vec<u32> = adj
                .edges_of(i)
                .iter()
                .copied()
                .filter(|&e| mesh.edges[e as usize][0] as usize == i)
                .collect();
            assert_eq!(adj.owned_by(i), &want[..], "node {i}");
        }
        let owned: usize = (0..mesh.n_nodes()).map(|i| adj.owned_by(i).len()).sum();
        assert_eq!(owned, mesh.n_edges());
    }

    #[test]
    fn every_cell_is_listed_at_each_corner() {
        let raw = BoxSpec::uniform([0.0; 3], [1.0; 3], [3, 2, 2], BoxCells::Hex).raw().unwrap();
        let mesh = Mesh::build(raw).unwrap();
        let adj = NodeEdges::build(&mesh);
        let mut count = vec![0; mesh.cells.len()];
        for i in 0..mesh.n_nodes() {
            let row = adj.cells_of(i);
            assert!(row.windows(2).all(|w| w[0] < w[1]));
            for &c in row {
                assert!(mesh.cells[c as usize].nodes().contains(&(i as u32)));
                count[c as usize] += 1;
            }
        }
        assert!(count.iter().all(|&c| c == 8), "{count:?}");
    }
}
