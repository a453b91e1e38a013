//! Per-block lists of the special edges (DESIGN §5.1): the edges the ordinary edge loop must not
//! take, because their two ends need two one-sided fluxes (ends of different fluids, thesis
//! §3.3.2; later edges cut by the structure, Alg. 5.1).
//!
//! Each edge block of [`crate::mesh::EdgeBlocks`] keeps its special edges sorted by edge number
//! (one flat list, cut by per-block offsets). The residual runs the ordinary loop over the gaps
//! between them ([`SpecialEdges::gaps`]) and then the special edges, in the same block closure,
//! so every node still hears from its edges in an order fixed by the mesh and the lists: the
//! result stays bitwise independent of the thread count. A run with no special edge has empty
//! lists and runs the ordinary loop over whole blocks.
//!
//! Kinds: each entry carries a [`SpecialKind`]; lists of different kinds are merged per block
//! ([`SpecialEdges::merge`], O(special edges + blocks)), an edge in both keeping the kind of
//! higher priority (a cut edge takes Alg. 5.1 whatever its fluids, DESIGN §5).

use crate::mesh::{EdgeBlocks, Mesh};
use rayon::prelude::*;
use std::ops::Range;

/// Why an edge is special, in ascending priority (an edge in two lists keeps the larger kind).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[repr(u8)]
pub enum SpecialKind {
    /// Its end nodes hold different fluids: the two-phase ghost-fluid flux (thesis Eq. 3.9).
    TwoMaterial = 0,
    /// Not cut by the embedded surface, and neither end is an active fluid node (inside a closed
    /// body, or occluded): no flux at all, whatever fluids its ends held.
    Dead = 1,
    /// Not cut by the embedded surface, but one end is not an active fluid node: the active end
    /// sees a slip wall on the edge's facet (a fallback the tracking should leave no room for).
    Frozen = 2,
    /// Cut by the embedded surface: Alg. 5.1 for each active end, whatever the fluids.
    Cut = 3,
}

/// One special edge: its index in `mesh.edges` and its kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SpecialEdge {
    pub edge: u32,
    pub kind: SpecialKind,
}

/// The special edges of every edge block, each block's sorted by edge.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct SpecialEdges {
    /// First entry of each block in `list`, then the length (empty: no special edge at all).
    starts: Vec<u32>,
    list: Vec<SpecialEdge>,
}

impl SpecialEdges {
    /// No special edge.
    pub fn none() -> SpecialEdges {
        SpecialEdges::default()
    }

    /// The edges whose end nodes hold different material ids, as [`SpecialKind::TwoMaterial`]:
    /// one pass over the edges, block by block in parallel.
    pub fn two_material(mesh: &Mesh, material: &[u8]) -> SpecialEdges {
        let blocks = &mesh.blocks;
        let per_block: Vec<Vec<SpecialEdge>> = (0..blocks.len())
            .into_par_iter()
            .map(|b| {
                blocks
                    .edges(b)
                    .filter(|&e| {
                        let [i, j] = mesh.edges[e];
                        material[i as usize] != material[j as usize]
                    })
                    .map(|e| SpecialEdge { edge: e as u32, kind: SpecialKind::TwoMaterial })
                    .collect()
            })
            .collect();
        SpecialEdges::from_blocks(per_block)
    }

    /// The special edges `list`, sorted by edge with no repeats, cut into the blocks of `blocks`.
    pub fn from_sorted(blocks: &EdgeBlocks, list: Vec<SpecialEdge>) -> SpecialEdges {
        debug_assert!(list.windows(2).all(|w| w[0].edge < w[1].edge), "unsorted special edges");
        if list.is_empty() {
            return SpecialEdges::none();
        }
        let mut starts: Vec<u32> = (0..blocks.len())
            .map(|b| list.partition_point(|s| (s.edge as usize) < blocks.edges(b).start) as u32)
            .collect();
        starts.push(list.len() as u32);
        SpecialEdges { starts, list }
    }

    fn from_blocks(per_block: Vec<Vec<SpecialEdge>>) -> SpecialEdges {
        let total: usize = per_block.iter().map(Vec::len).sum();
        if total == 0 {
            return SpecialEdges::none();
        }
        let mut starts = Vec::with_capacity(per_block.len() + 1);
        let mut list = Vec::with_capacity(total);
        for b in per_block {
            starts.push(list.len() as u32);
            list.extend(b);
        }
        starts.push(list.len() as u32);
        SpecialEdges { starts, list }
    }

    /// True when no block has a special edge.
    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    /// Number of special edges.
    pub fn len(&self) -> usize {
        self.list.len()
    }

    /// All special edges, ascending.
    pub fn all(&self) -> &[SpecialEdge] {
        &self.list
    }

    /// The special edges of block `b`, ascending.
    #[inline]
    pub fn block(&self, b: usize) -> &[SpecialEdge] {
        if self.list.is_empty() {
            return &[];
        }
        &self.list[self.starts[b] as usize..self.starts[b + 1] as usize]
    }

    /// The ordinary edges of block `b` (whose edges are `edges`): the ranges between its special
    /// edges, in ascending order, empty ones left out.
    pub fn gaps(&self, b: usize, edges: Range<usize>) -> Gaps<'_> {
        Gaps { special: self.block(b), next: edges.start, end: edges.end }
    }

    /// The union of two lists over the same blocks, per block in one merge pass; an edge in
    /// both keeps the larger [`SpecialKind`].
    pub fn merge(&self, other: &SpecialEdges, blocks: &EdgeBlocks) -> SpecialEdges {
        if other.is_empty() {
            return self.clone();
        }
        if self.is_empty() {
            return other.clone();
        }
        let mut starts = Vec::with_capacity(blocks.len() + 1);
        let mut list = Vec::with_capacity(self.len() + other.len());
        for b in 0..blocks.len() {
            starts.push(list.len() as u32);
            let (mut x, mut y) =
                (self.block(b).iter().peekable(), other.block(b).iter().peekable());
            loop {
                let next = match (x.peek(), y.peek()) {
                    (Some(a), Some(c)) if a.edge == c.edge => {
                        let kind = a.kind.max(c.kind);
                        let edge = a.edge;
                        x.next();
                        y.next();
                        SpecialEdge { edge, kind }
                    }
                    (Some(a), Some(c)) if a.edge < c.edge => *x.next().expect("peeked"),
                    (Some(_), Some(_)) | (None, Some(_)) => *y.next().expect("peeked"),
                    (Some(_), None) => *x.next().expect("peeked"),
                    (None, None) => break,
                };
                list.push(next);
            }
        }
        starts.push(list.len() as u32);
        SpecialEdges { starts, list }
    }

    /// Memory in bytes.
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(&self.starts[..]) + std::mem::size_of_val(&self.list[..])
    }
}

/// The ranges of ordinary edges between the special edges of a block ([`SpecialEdges::gaps`]).
pub struct Gaps<'a> {
    special: &'a [SpecialEdge],
    next: usize,
    end: usize,
}

impl Iterator for Gaps<'_> {
    type Item = Range<usize>;

    fn next(&mut self) -> Option<Range<usize>> {
        while self.next < self.end {
            let stop = self.special.first().map_or(self.end, |s| s.edge as usize);
            let gap = self.next..stop;
            if let Some((_, rest)) = self.special.split_first().filter(|_| stop < self.end) {
                self.special = rest;
                self.next = stop + 1;
            } else {
                self.next = self.end;
            }
            if !gap.is_empty() {
                return Some(gap);
            }
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::boxmesh::{BoxCells, BoxSpec};

    fn mesh() -> Mesh {
        let spec = BoxSpec::uniform([0.0; 3], [1.0; 3], [12, 10, 9], BoxCells::Tet);
        Mesh::build(spec.raw().unwrap()).unwrap()
    }

    /// The gaps and the special edges of each block tile its edges exactly once, in order.
    fn assert_tiles(mesh: &Mesh, special: &SpecialEdges) {
        let blocks = &mesh.blocks;
        let mut seen = Vec::new();
        for b in 0..blocks.len() {
            let mut in_block: Vec<usize> = special.gaps(b, blocks.edges(b)).flatten().collect();
            in_block.extend(special.block(b).iter().map(|s| s.edge as usize));
            in_block.sort_unstable();
            assert_eq!(in_block, blocks.edges(b).collect::<Vec<_>>(), "block {b}");
            assert!(special.block(b).windows(2).all(|w| w[0].edge < w[1].edge));
            seen.extend(in_block);
        }
        assert_eq!(seen, (0..mesh.n_edges()).collect::<Vec<_>>());
    }

    #[test]
    fn two_material_edges_are_exactly_those_joining_different_ids() {
        let mesh = mesh();
        assert!(mesh.blocks.len() >= 4, "{} blocks", mesh.blocks.len());
        // An oblique interface.
        let material: Vec<u8> =
            mesh.coords.iter().map(|x| u8::from(x[0] + 0.7 * x[1] - 0.3 * x[2] > 0.6)).collect();
        let special = SpecialEdges::two_material(&mesh, &material);
        let expected: Vec<u32> = (0..mesh.n_edges() as u32)
            .filter(|&e| {
                let [i, j] = mesh.edges[e as usize];
                material[i as usize] != material[j as usize]
            })
            .collect();
        assert!(!expected.is_empty());
        let got: Vec<u32> = special.all().iter().map(|s| s.edge).collect();
        assert_eq!(got, expected);
        assert_tiles(&mesh, &special);
        // The same list cut by `from_sorted`.
        assert_eq!(SpecialEdges::from_sorted(&mesh.blocks, special.all().to_vec()), special);
        // One material: nothing special, each block one gap.
        let none = SpecialEdges::two_material(&mesh, &vec![3; mesh.n_nodes()]);
        assert!(none.is_empty() && none == SpecialEdges::none());
        for b in 0..mesh.blocks.len() {
            let gaps: Vec<_> = none.gaps(b, mesh.blocks.edges(b)).collect();
            assert_eq!(gaps, vec![mesh.blocks.edges(b)]);
        }
    }

    /// Gaps around special edges at a block's first and last edge and side by side.
    #[test]
    fn gaps_skip_adjacent_and_boundary_specials() {
        let mesh = mesh();
        let blocks = &mesh.blocks;
        let e = blocks.edges(1);
        let picks = [e.start, e.start + 1, e.start + 5, e.end - 1];
        let list = picks
            .iter()
            .map(|&k| SpecialEdge { edge: k as u32, kind: SpecialKind::TwoMaterial })
            .collect();
        let special = SpecialEdges::from_sorted(blocks, list);
        let gaps: Vec<_> = special.gaps(1, e.clone()).collect();
        assert_eq!(gaps, vec![e.start + 2..e.start + 5, e.start + 6..e.end - 1]);
        assert!(special.block(0).is_empty() && special.block(2).is_empty());
        assert_tiles(&mesh, &special);
    }

    #[test]
    fn merge_is_the_sorted_union_with_the_larger_kind() {
        let mesh = mesh();
        let a_ids: Vec<u8> = mesh.coords.iter().map(|x| u8::from(x[0] > 0.5)).collect();
        let b_ids: Vec<u8> = mesh.coords.iter().map(|x| u8::from(x[1] > 0.3)).collect();
        let a = SpecialEdges::two_material(&mesh, &a_ids);
        let b = SpecialEdges::two_material(&mesh, &b_ids);
        let merged = a.merge(&b, &mesh.blocks);
        let mut expected: Vec<u32> = a.all().iter().chain(b.all()).map(|s| s.edge).collect();
        expected.sort_unstable();
        expected.dedup();
        let got: Vec<u32> = merged.all().iter().map(|s| s.edge).collect();
        assert_eq!(got, expected);
        assert!(got.len() < a.len() + b.len(), "the lists share edges");
        assert_tiles(&mesh, &merged);
        assert_eq!(a.merge(&SpecialEdges::none(), &mesh.blocks), a);
        assert_eq!(SpecialEdges::none().merge(&b, &mesh.blocks), b);
    }
}
