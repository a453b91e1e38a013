//! Locality renumbering at model build: nodes stored in the order of a 3D Hilbert curve
//! through their reference positions, cells by their lowest node slot. The user's numbering
//! (gmsh file order and tags, generator ids) stays in [`Numbering`], a plain pair of vectors
//! slot -> user number and user number -> slot, so outputs, probes and the protocol speak
//! the user's numbers while every loop of the solver runs in storage order.
//!
//! Why a Hilbert curve rather than reverse Cuthill-McKee: (1) the storage order is a function
//! of the geometry alone (ties broken by the exact coordinates, then, for coincident nodes
//! only, by the user's number), so a mesh given in any numbering is stored the same way and
//! runs bitwise the same; RCM's order depends on its start node and the order neighbours are
//! met in, that is on the input numbering. (2) The curve is hierarchical: every sub-cube of
//! the bounding cube is one run of slots, so the explicit element loop finds its nodes in
//! cache at every level (L1 for a block of elements, L2 for a thread's share), and the two
//! threads' halves of the element list touch disjoint node ranges but for a seam. (3) It
//! needs no graph, and orders disconnected parts (beams beside shells) as well as connected
//! ones. Its bandwidth is large (sub-cubes meet along seams whose slots are far apart), but
//! no solver here depends on it: the explicit loop gathers by element, and the sparse
//! factorisation orders its own pivots (faer's fill-reducing ordering). Its profile stays
//! within a small factor of a structured grid's row-by-row numbering (tested, numbers in the
//! tests of this module).
//!
//! Cells are sorted by their lowest node slot (ties by their sorted node slots, their kind,
//! then the user's number), so consecutive elements share nodes and the element order follows
//! the node order; a cell's own node order (its orientation) is never changed.

use super::{Cell, Mesh};

/// A numbering apart from storage: `user[slot]` is the user's number of a slot (its position
/// in the input: gmsh file order, generator id) and `slot[user]` the slot of a user number.
/// Empty: the identity (a mesh never renumbered).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Numbering {
    pub user: Vec<usize>,
    pub slot: Vec<usize>,
}

impl Numbering {
    /// The numbering whose slot `s` holds user number `user[s]`; `user` is a permutation.
    pub fn from_user_order(user: Vec<usize>) -> Numbering {
        let mut slot = vec![usize::MAX; user.len()];
        for (s, &u) in user.iter().enumerate() {
            slot[u] = s;
        }
        debug_assert!(slot.iter().all(|&s| s != usize::MAX), "not a permutation");
        Numbering { user, slot }
    }

    /// Whether this is the identity (no renumbering).
    pub fn is_identity(&self) -> bool {
        self.user.is_empty()
    }

    /// The user's number of slot `s`.
    pub fn user_of(&self, s: usize) -> usize {
        self.user.get(s).copied().unwrap_or(s)
    }

    /// The slot of user number `u`.
    pub fn slot_of(&self, u: usize) -> usize {
        self.slot.get(u).copied().unwrap_or(u)
    }

    /// Appends slot `n` (the current count) with the next user number, `n` too.
    pub fn push(&mut self, n: usize) {
        if !self.is_identity() {
            self.user.push(n);
            self.slot.push(n);
        }
    }

    /// The slots of `n` entries in the user's order.
    pub fn slots_in_user_order(&self, n: usize) -> Vec<usize> {
        (0..n).map(|u| self.slot_of(u)).collect()
    }

    /// This numbering followed by the storage permutation `order` (`order[new] = old` slot).
    fn then(&self, order: &[usize]) -> Numbering {
        Numbering::from_user_order(order.iter().map(|&old| self.user_of(old)).collect())
    }
}

/// Bits per axis of the curve's grid: `3 x 21 = 63` bits of key.
const BITS: u32 = 21;

/// The index along the 3D Hilbert curve of grid point `x` (`BITS` bits per axis): Skilling's
/// axes-to-transpose (AIP Conf. Proc. 707, 2004, "Programming the Hilbert curve"), its
/// transposed form read out bit by bit, most significant first.
pub fn hilbert_index(mut x: [u32; 3], bits: u32) -> u64 {
    let m = 1u32 << (bits - 1);
    // inverse undo of the excess work
    let mut q = m;
    while q > 1 {
        let p = q - 1;
        for i in 0..3 {
            if x[i] & q != 0 {
                x[0] ^= p; // invert
            } else {
                let t = (x[0] ^ x[i]) & p; // exchange
                x[0] ^= t;
                x[i] ^= t;
            }
        }
        q >>= 1;
    }
    // Gray encode
    for i in 1..3 {
        x[i] ^= x[i - 1];
    }
    let mut t = 0;
    let mut q = m;
    while q > 1 {
        if x[2] & q != 0 {
            t ^= q - 1;
        }
        q >>= 1;
    }
    x.iter_mut().for_each(|v| *v ^= t);
    let mut key = 0u64;
    for b in (0..bits).rev() {
        for v in x {
            key = (key << 1) | u64::from((v >> b) & 1);
        }
    }
    key
}

/// The storage order of `nodes`: `order[slot]` is the input index, sorted by the Hilbert index
/// of the position on a `2^21` grid over the bounding cube (one scale on every axis, so a plate
/// or a beam is a section of the same curve), ties by the exact coordinates, then the input.
pub fn node_order(nodes: &[[f64; 3]]) -> Vec<usize> {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in nodes {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let extent = (0..3).map(|k| hi[k] - lo[k]).fold(0.0, f64::max);
    let top = f64::from((1u32 << BITS) - 1);
    let scale = if extent > 0.0 { top / extent } else { 0.0 };
    let keys: Vec<u64> = nodes
        .iter()
        .map(|p| {
            let q =
                std::array::from_fn(|k| ((p[k] - lo[k]) * scale).round().clamp(0.0, top) as u32);
            hilbert_index(q, BITS)
        })
        .collect();
    let mut order: Vec<usize> = (0..nodes.len()).collect();
    order.sort_unstable_by(|&a, &b| {
        let exact = || (0..3).map(|k| nodes[a][k].total_cmp(&nodes[b][k])).find(|o| o.is_ne());
        keys[a].cmp(&keys[b]).then_with(|| exact().unwrap_or(a.cmp(&b)))
    });
    order
}

/// The storage order of `cells` (nodes already in storage slots): `order[slot]` is the input
/// index, sorted by the lowest node slot, then the sorted node slots, the kind, the input.
pub fn cell_order(cells: &[Cell]) -> Vec<usize> {
    let sorted: Vec<Vec<usize>> = cells
        .iter()
        .map(|c| {
            let mut s = c.nodes.clone();
            s.sort_unstable();
            s
        })
        .collect();
    let kind = |c: usize| cells[c].kind as u8;
    let mut order: Vec<usize> = (0..cells.len()).collect();
    order.sort_unstable_by(|&a, &b| {
        sorted[a].cmp(&sorted[b]).then(kind(a).cmp(&kind(b))).then(a.cmp(&b))
    });
    order
}

/// `mesh` stored in locality order: nodes along the Hilbert curve, cells by lowest node slot;
/// connectivity, node ids and sets follow, and the mesh's numberings record the user's numbers
/// (composed with any it held). Sets are stored in ascending slot order, so what sums over a
/// set does so in an order independent of the input numbering.
pub fn renumber(mesh: Mesh) -> Mesh {
    let nodes_old = node_order(&mesh.nodes);
    let mut new_slot = vec![0; nodes_old.len()];
    for (s, &old) in nodes_old.iter().enumerate() {
        new_slot[old] = s;
    }
    let cells: Vec<Cell> = mesh
        .cells
        .iter()
        .map(|c| Cell { kind: c.kind, nodes: c.nodes.iter().map(|&n| new_slot[n]).collect() })
        .collect();
    let cells_old = cell_order(&cells);
    let mut new_cell = vec![0; cells_old.len()];
    for (s, &old) in cells_old.iter().enumerate() {
        new_cell[old] = s;
    }
    let remap = |v: &Vec<usize>, to: &[usize]| {
        let mut out: Vec<usize> = v.iter().map(|&i| to[i]).collect();
        out.sort_unstable();
        out
    };
    Mesh {
        nodes: nodes_old.iter().map(|&i| mesh.nodes[i]).collect(),
        cells: cells_old.iter().map(|&c| cells[c].clone()).collect(),
        node_sets: mesh.node_sets.iter().map(|(k, v)| (k.clone(), remap(v, &new_slot))).collect(),
        cell_sets: mesh.cell_sets.iter().map(|(k, v)| (k.clone(), remap(v, &new_cell))).collect(),
        node_ids: if mesh.node_ids.is_empty() {
            Vec::new()
        } else {
            nodes_old.iter().map(|&i| mesh.node_ids[i]).collect()
        },
        node_numbering: mesh.node_numbering.then(&nodes_old),
        cell_numbering: mesh.cell_numbering.then(&cells_old),
    }
}

/// A fixed-seed random permutation of `0..n` (Fisher-Yates with a xorshift sequence).
pub fn shuffled_permutation(n: usize, seed: u64) -> Vec<usize> {
    let mut p: Vec<usize> = (0..n).collect();
    let mut r = seed | 1;
    for i in (1..n).rev() {
        r ^= r << 13;
        r ^= r >> 7;
        r ^= r << 17;
        p.swap(i, (r % (i as u64 + 1)) as usize);
    }
    p
}

/// `mesh` with its nodes and cells numbered by fixed-seed random permutations (node sets
/// follow; a cell keeps its own node order): the input of a user who numbered at random.
pub fn shuffle_numbering(mesh: &Mesh, seed: u64) -> Mesh {
    let node_of = shuffled_permutation(mesh.nodes.len(), seed); // new -> old
    let cell_of = shuffled_permutation(mesh.cells.len(), seed.rotate_left(17));
    let mut new_node = vec![0; node_of.len()];
    node_of.iter().enumerate().for_each(|(new, &old)| new_node[old] = new);
    let mut new_cell = vec![0; cell_of.len()];
    cell_of.iter().enumerate().for_each(|(new, &old)| new_cell[old] = new);
    let sets = |sets: &std::collections::BTreeMap<String, Vec<usize>>, to: &[usize]| {
        sets.iter().map(|(k, v)| (k.clone(), v.iter().map(|&i| to[i]).collect())).collect()
    };
    let cell = |old: usize| {
        let c = &mesh.cells[old];
        Cell { kind: c.kind, nodes: c.nodes.iter().map(|&n| new_node[n]).collect() }
    };
    Mesh {
        nodes: node_of.iter().map(|&old| mesh.nodes[old]).collect(),
        cells: cell_of.iter().map(|&old| cell(old)).collect(),
        node_sets: sets(&mesh.node_sets, &new_node),
        cell_sets: sets(&mesh.cell_sets, &new_cell),
        node_ids: node_of.iter().map(|&old| mesh.node_id(old)).collect(),
        ..Mesh::default()
    }
}

/// Bandwidth and profile of the node graph (nodes joined when they share a cell): the largest
/// `|i - j|` over joined slots, and `Σ_i (i - min{j ≤ i joined to i})`, the envelope a
/// row-by-row factorisation or a sweep over nodes would touch.
pub fn bandwidth_profile(mesh: &Mesh) -> (usize, usize) {
    let mut first = (0..mesh.nodes.len()).collect::<Vec<usize>>();
    let mut band = 0;
    for c in &mesh.cells {
        let lo = c.nodes.iter().copied().min().unwrap_or(0);
        let hi = c.nodes.iter().copied().max().unwrap_or(0);
        band = band.max(hi - lo);
        for &n in &c.nodes {
            first[n] = first[n].min(lo);
        }
    }
    (band, first.iter().enumerate().map(|(i, &f)| i - f).sum())
}

/// The mean over cells of the spread of their node slots (`max - min`): how far apart in
/// memory the nodes an element gathers lie.
pub fn mean_cell_spread(mesh: &Mesh) -> f64 {
    let spread = |c: &Cell| {
        let lo = c.nodes.iter().copied().min().unwrap_or(0);
        c.nodes.iter().copied().max().unwrap_or(0) - lo
    };
    mesh.cells.iter().map(spread).sum::<usize>() as f64 / mesh.cells.len().max(1) as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The curve visits the `8^3` grid points once each, each step to a face neighbour.
    #[test]
    fn hilbert_index_is_a_continuous_curve() {
        let bits = 3;
        let n = 1u32 << bits;
        let mut by_key = vec![None; (n * n * n) as usize];
        for x in 0..n {
            for y in 0..n {
                for z in 0..n {
                    let k = hilbert_index([x, y, z], bits) as usize;
                    assert!(by_key[k].is_none(), "index {k} twice");
                    by_key[k] = Some([x, y, z]);
                }
            }
        }
        let pts: Vec<[u32; 3]> = by_key.into_iter().map(|p| p.expect("every index")).collect();
        for w in pts.windows(2) {
            let d: u32 = (0..3).map(|k| w[0][k].abs_diff(w[1][k])).sum();
            assert_eq!(d, 1, "{:?} -> {:?}", w[0], w[1]);
        }
    }

    #[test]
    fn numbering_round_trips() {
        let n = Numbering::from_user_order(vec![2, 0, 3, 1]);
        for s in 0..4 {
            assert_eq!(n.slot_of(n.user_of(s)), s);
        }
        assert_eq!(n.slots_in_user_order(4), vec![1, 3, 0, 2]);
        let id = Numbering::default();
        assert_eq!((id.user_of(5), id.slot_of(5)), (5, 5));
    }
}
