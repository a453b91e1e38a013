//! The bounding box hierarchy over the surface triangles (thesis §4.1, step 2 of Alg. 4.1 and
//! 4.2): axis-aligned boxes swept over the step, so one tree serves every stage time.
//!
//! A triangle's box is the union of its boxes at `t_a` and at `t_b` (it holds the triangle on the
//! straight path between them, the motion the sweep test of [`super::predicates`] assumes),
//! widened by a padding the caller states. The tree is built once per surface topology by median
//! splits along the widest axis of the box centres (so its depth is at most
//! `log2(n / LEAF_SIZE) + 2` and a fixed stack serves every query) and refitted bottom-up when
//! only the positions change. Queries visit the triangles whose box overlaps a given box and
//! allocate nothing.

use super::Surface;

/// Most triangles in a leaf.
pub const LEAF_SIZE: usize = 4;
/// Depth bound of the traversal stack (median splits keep trees of 2^60 triangles below it).
const STACK: usize = 64;

/// A node of the hierarchy: a leaf holds `order[first..first + count]`; an inner node
/// (`count == 0`) has its children at `first` and `first + 1`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Node {
    lo: [f64; 3],
    hi: [f64; 3],
    first: u32,
    count: u32,
}

/// The hierarchy; nodes are stored parents before children, the root first.
#[derive(Debug, Clone, PartialEq)]
pub struct Bvh {
    nodes: Vec<Node>,
    /// Triangle numbers in leaf order.
    order: Vec<u32>,
    /// Swept, padded box of each triangle, lower and upper corner together (one record read).
    boxes: Vec<[[f64; 3]; 2]>,
    /// Padding added on every side of every triangle box.
    pub pad: f64,
    /// Topology the tree was built for ([`Surface::topology_version`]).
    pub topology_version: u64,
}

/// A broken hierarchy invariant, named.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BvhError {
    #[error("bvh node {node} does not contain its child {child}")]
    ChildOutside { node: usize, child: usize },
    #[error("bvh leaf {node} does not contain the box of triangle {triangle}")]
    TriangleOutside { node: usize, triangle: u32 },
    #[error("triangle {triangle} is in {count} leaves of the bvh (expected exactly one)")]
    Membership { triangle: usize, count: usize },
    #[error("bvh node {node} refers to children or triangles past the end of the tree")]
    Dangling { node: usize },
    #[error("the surface has {surface} triangles but the bvh was built for {tree} (topology {version}): rebuild it")]
    Topology { surface: usize, tree: usize, version: u64 },
}

/// Whether the boxes `[alo, ahi]` and `[blo, bhi]` overlap (touching counts).
#[inline]
pub fn overlaps(alo: &[f64; 3], ahi: &[f64; 3], blo: &[f64; 3], bhi: &[f64; 3]) -> bool {
    // Non-short-circuit `&`: six comparisons and no branch.
    let x = (alo[0] <= bhi[0]) & (blo[0] <= ahi[0]);
    let y = (alo[1] <= bhi[1]) & (blo[1] <= ahi[1]);
    let z = (alo[2] <= bhi[2]) & (blo[2] <= ahi[2]);
    x & y & z
}

impl Bvh {
    /// Builds the tree over the triangles of `surface`, with boxes swept from `x_a` to `x_b` and
    /// padded by `pad` (a length, `>= 0`) on every side.
    pub fn build(surface: &Surface, pad: f64) -> Bvh {
        let n = surface.triangles.len();
        let mut bvh = Bvh {
            nodes: Vec::new(),
            order: Vec::new(),
            boxes: vec![[[0.0; 3]; 2]; n],
            pad: pad.max(0.0),
            topology_version: surface.topology_version,
        };
        bvh.triangle_boxes(&surface.triangles, &[&surface.x_a, &surface.x_b]);
        bvh.split();
        bvh
    }

    /// The tree over the given item boxes `[lo[k], hi[k]]` (no padding, topology 0): a static
    /// hierarchy over anything with a box, such as the fluid mesh's nodes.
    pub fn over_boxes(lo: Vec<[f64; 3]>, hi: Vec<[f64; 3]>) -> Bvh {
        debug_assert_eq!(lo.len(), hi.len(), "one upper corner per lower corner");
        let mut bvh = Bvh {
            nodes: Vec::new(),
            order: Vec::new(),
            boxes: lo.into_iter().zip(hi).map(|(lo, hi)| [lo, hi]).collect(),
            pad: 0.0,
            topology_version: 0,
        };
        bvh.split();
        bvh
    }

    /// The tree structure over the item boxes: median splits, breadth first, then the node boxes.
    fn split(&mut self) {
        let n = self.boxes.len();
        self.nodes = Vec::with_capacity(2 * n.div_ceil(LEAF_SIZE).max(1));
        self.order = (0..n as u32).collect();
        let centres: Vec<[f64; 3]> = (0..n)
            .map(|t| {
                let [lo, hi] = self.boxes[t];
                [lo[0] + hi[0], lo[1] + hi[1], lo[2] + hi[2]]
            })
            .collect();
        self.nodes.push(Node { lo: [0.0; 3], hi: [0.0; 3], first: 0, count: n as u32 });
        // Split breadth-first so that the two children of a node are adjacent.
        let mut k = 0;
        while k < self.nodes.len() {
            let Node { first, count, .. } = self.nodes[k];
            let (first, count) = (first as usize, count as usize);
            if count > LEAF_SIZE {
                let slice = &mut self.order[first..first + count];
                let mut lo = [f64::INFINITY; 3];
                let mut hi = [f64::NEG_INFINITY; 3];
                for &t in slice.iter() {
                    for d in 0..3 {
                        lo[d] = lo[d].min(centres[t as usize][d]);
                        hi[d] = hi[d].max(centres[t as usize][d]);
                    }
                }
                let axis = (0..3).max_by(|&a, &b| (hi[a] - lo[a]).total_cmp(&(hi[b] - lo[b])));
                let axis = axis.unwrap_or(0);
                let half = count / 2;
                slice.select_nth_unstable_by(half, |&a, &b| {
                    centres[a as usize][axis].total_cmp(&centres[b as usize][axis]).then(a.cmp(&b))
                });
                let child = self.nodes.len() as u32;
                self.nodes[k].first = child;
                self.nodes[k].count = 0;
                let (f, h) = (first as u32, half as u32);
                self.nodes.push(Node { lo: [0.0; 3], hi: [0.0; 3], first: f, count: h });
                self.nodes.push(Node {
                    lo: [0.0; 3],
                    hi: [0.0; 3],
                    first: f + h,
                    count: count as u32 - h,
                });
            }
            k += 1;
        }
        self.fit_nodes();
    }

    /// Makes the tree fit `surface`: rebuilt when its topology version or triangle count
    /// changed, refitted otherwise.
    pub fn update(&mut self, surface: &Surface) {
        if surface.topology_version != self.topology_version
            || surface.triangles.len() != self.boxes.len()
        {
            *self = Bvh::build(surface, self.pad);
        } else {
            self.triangle_boxes(&surface.triangles, &[&surface.x_a, &surface.x_b]);
            self.fit_nodes();
        }
    }

    /// Refits the boxes to the surface's new positions (`x_a`, `x_b`) without changing the tree.
    /// A surface of another size needs [`Bvh::build`].
    pub fn refit(&mut self, surface: &Surface) -> Result<(), BvhError> {
        self.refit_with(&surface.triangles, &[&surface.x_a, &surface.x_b])
    }

    /// Refits with the boxes around the triangles at every given set of nodal positions (for
    /// example the positions at a stage time as well as at the ends of the step).
    pub fn refit_with(
        &mut self,
        triangles: &[[u32; 3]],
        positions: &[&[[f64; 3]]],
    ) -> Result<(), BvhError> {
        if triangles.len() != self.boxes.len() {
            return Err(BvhError::Topology {
                surface: triangles.len(),
                tree: self.boxes.len(),
                version: self.topology_version,
            });
        }
        self.triangle_boxes(triangles, positions);
        self.fit_nodes();
        Ok(())
    }

    /// Number of triangles.
    pub fn len(&self) -> usize {
        self.boxes.len()
    }

    pub fn is_empty(&self) -> bool {
        self.boxes.is_empty()
    }

    /// Memory in bytes of the tree and the triangle boxes.
    pub fn memory_bytes(&self) -> usize {
        use std::mem::size_of_val;
        size_of_val(&self.nodes[..]) + size_of_val(&self.order[..]) + size_of_val(&self.boxes[..])
    }

    /// The swept, padded box of triangle `t`.
    #[inline]
    pub fn triangle_box(&self, t: usize) -> ([f64; 3], [f64; 3]) {
        let [lo, hi] = self.boxes[t];
        (lo, hi)
    }

    /// Prefetch hint ([`crate::prefetch`]) for the box of triangle `t`.
    #[inline]
    pub fn prefetch_box(&self, t: usize) {
        crate::prefetch::prefetch(&self.boxes, t);
    }

    /// The box around every triangle (the root's box); an empty tree gives an inverted box.
    pub fn root_box(&self) -> ([f64; 3], [f64; 3]) {
        self.nodes.first().map_or(([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]), |r| (r.lo, r.hi))
    }

    /// Calls `visit` with every triangle whose box overlaps `[lo, hi]`, in leaf order.
    #[inline]
    pub fn for_each_overlap(&self, lo: &[f64; 3], hi: &[f64; 3], mut visit: impl FnMut(u32)) {
        self.for_each_overlap_pruned(
            lo,
            hi,
            &mut (),
            |_, _, _| true,
            |_, _, _| 0.0,
            |_, t| visit(t),
        )
    }

    /// [`Bvh::for_each_overlap`] skipping the subtrees whose box fails `keep(state, lo, hi)`, a
    /// test that `visit(state, t)` may tighten (a nearest-point search prunes by its best so
    /// far); the nearer child first, by the squared distance `order(state, lo, hi)`.
    #[inline]
    pub fn for_each_overlap_pruned<S>(
        &self,
        lo: &[f64; 3],
        hi: &[f64; 3],
        state: &mut S,
        keep: impl Fn(&S, &[f64; 3], &[f64; 3]) -> bool,
        order: impl Fn(&S, &[f64; 3], &[f64; 3]) -> f64,
        mut visit: impl FnMut(&mut S, u32),
    ) {
        if self.boxes.is_empty() {
            return;
        }
        let mut stack = [0u32; STACK];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let node = &self.nodes[stack[top] as usize];
            if !overlaps(&node.lo, &node.hi, lo, hi) || !keep(state, &node.lo, &node.hi) {
                continue;
            }
            if node.count > 0 {
                let leaf = &self.order[node.first as usize..(node.first + node.count) as usize];
                for &t in leaf {
                    let [a, b] = &self.boxes[t as usize];
                    if overlaps(a, b, lo, hi) {
                        visit(state, t);
                    }
                }
            } else {
                let (a, b) = (node.first, node.first + 1);
                let (na, nb) = (&self.nodes[a as usize], &self.nodes[b as usize]);
                let near_first = order(state, &na.lo, &na.hi) <= order(state, &nb.lo, &nb.hi);
                // Depth is bounded by the median build, so two more slots always fit.
                (stack[top], stack[top + 1]) = if near_first { (b, a) } else { (a, b) };
                top += 2;
            }
        }
    }

    /// Checks the invariants: every parent box contains its children, every leaf box contains its
    /// triangles' boxes, every triangle is in exactly one leaf.
    pub fn validate(&self) -> Result<(), BvhError> {
        let contains = |lo: &[f64; 3], hi: &[f64; 3], clo: &[f64; 3], chi: &[f64; 3]| {
            (0..3).all(|d| lo[d] <= clo[d] && chi[d] <= hi[d])
        };
        let mut seen = vec![0usize; self.boxes.len()];
        for (k, node) in self.nodes.iter().enumerate() {
            let (first, count) = (node.first as usize, node.count as usize);
            if count > 0 {
                let leaf =
                    self.order.get(first..first + count).ok_or(BvhError::Dangling { node: k })?;
                for &t in leaf {
                    let tu = t as usize;
                    if tu >= seen.len() {
                        return Err(BvhError::Dangling { node: k });
                    }
                    seen[tu] += 1;
                    if !contains(&node.lo, &node.hi, &self.boxes[tu][0], &self.boxes[tu][1]) {
                        return Err(BvhError::TriangleOutside { node: k, triangle: t });
                    }
                }
            } else if !self.boxes.is_empty() {
                for child in [first, first + 1] {
                    let c = self.nodes.get(child).ok_or(BvhError::Dangling { node: k })?;
                    if child <= k {
                        return Err(BvhError::Dangling { node: k });
                    }
                    if !contains(&node.lo, &node.hi, &c.lo, &c.hi) {
                        return Err(BvhError::ChildOutside { node: k, child });
                    }
                }
            }
        }
        match seen.iter().enumerate().find(|(_, &c)| c != 1) {
            Some((triangle, &count)) => Err(BvhError::Membership { triangle, count }),
            None => Ok(()),
        }
    }

    /// The padded union of each triangle's boxes over the position sets.
    fn triangle_boxes(&mut self, triangles: &[[u32; 3]], positions: &[&[[f64; 3]]]) {
        for (t, tri) in triangles.iter().enumerate() {
            let mut lo = [f64::INFINITY; 3];
            let mut hi = [f64::NEG_INFINITY; 3];
            for x in positions {
                for &n in tri {
                    let p = x[n as usize];
                    for d in 0..3 {
                        lo[d] = lo[d].min(p[d]);
                        hi[d] = hi[d].max(p[d]);
                    }
                }
            }
            self.boxes[t] = [lo.map(|v| v - self.pad), hi.map(|v| v + self.pad)];
        }
    }

    /// Node boxes from the triangle boxes, children before parents.
    fn fit_nodes(&mut self) {
        for k in (0..self.nodes.len()).rev() {
            let Node { first, count, .. } = self.nodes[k];
            let mut lo = [f64::INFINITY; 3];
            let mut hi = [f64::NEG_INFINITY; 3];
            let mut grow = |clo: [f64; 3], chi: [f64; 3]| {
                for d in 0..3 {
                    lo[d] = lo[d].min(clo[d]);
                    hi[d] = hi[d].max(chi[d]);
                }
            };
            if count > 0 {
                for &t in &self.order[first as usize..(first + count) as usize] {
                    let [lo, hi] = self.boxes[t as usize];
                    grow(lo, hi);
                }
            } else if !self.boxes.is_empty() {
                for c in [first as usize, first as usize + 1] {
                    grow(self.nodes[c].lo, self.nodes[c].hi);
                }
            }
            self.nodes[k].lo = lo;
            self.nodes[k].hi = hi;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::sphere;
    use super::*;

    fn brute(bvh: &Bvh, lo: [f64; 3], hi: [f64; 3]) -> Vec<u32> {
        (0..bvh.len() as u32)
            .filter(|&t| {
                let (a, b) = bvh.triangle_box(t as usize);
                overlaps(&a, &b, &lo, &hi)
            })
            .collect()
    }

    /// Well formed after the build and after every refit of a moving, deforming sphere, and every
    /// query returns exactly the triangles a brute-force scan of the boxes finds.
    #[test]
    fn hierarchy_stays_valid_through_refits_and_queries_are_exact() {
        let mut s = sphere([0.0; 3], 1.0, 10);
        let mut bvh = Bvh::build(&s, 1e-9);
        bvh.validate().unwrap();
        assert!(bvh.len() > 1000);
        for step in 1..=6 {
            let t = step as f64 * 0.1;
            let x: Vec<[f64; 3]> = s
                .x_b
                .iter()
                .map(|p| {
                    [
                        p[0] * (1.0 + 0.3 * t * p[2]) + t,
                        p[1] - 0.2 * t * p[0] * p[0],
                        p[2] * (1.0 - 0.1 * t),
                    ]
                })
                .collect();
            let v = vec![[0.0; 3]; x.len()];
            s.advance(t, &x, &v);
            bvh.refit(&s).unwrap();
            bvh.validate().unwrap();
            for q in 0..20 {
                let c =
                    [(q as f64 * 0.77).sin() * 1.2 + t, (q as f64 * 1.3).cos(), (q as f64).sin()];
                let (lo, hi) = (c.map(|v| v - 0.15), c.map(|v| v + 0.15));
                let mut got = Vec::new();
                bvh.for_each_overlap(&lo, &hi, |t| got.push(t));
                got.sort_unstable();
                assert_eq!(got, brute(&bvh, lo, hi));
            }
        }
        // Every triangle's box holds both of its positions.
        for (t, tri) in s.triangles.iter().enumerate() {
            let (lo, hi) = bvh.triangle_box(t);
            for x in [&s.x_a, &s.x_b] {
                for &n in tri {
                    assert!((0..3).all(|d| lo[d] <= x[n as usize][d] && x[n as usize][d] <= hi[d]));
                }
            }
        }
    }

    #[test]
    fn broken_trees_and_surfaces_are_named() {
        let s = sphere([0.0; 3], 1.0, 1);
        let mut bvh = Bvh::build(&s, 0.0);
        bvh.order[0] = bvh.order[1];
        assert!(matches!(bvh.validate(), Err(BvhError::Membership { .. })));
        let mut bvh = Bvh::build(&s, 0.0);
        bvh.nodes[1].hi[0] += 10.0;
        assert_eq!(bvh.validate(), Err(BvhError::ChildOutside { node: 0, child: 1 }));
        let mut other = sphere([0.0; 3], 1.0, 2);
        assert!(matches!(bvh.refit(&other), Err(BvhError::Topology { .. })));
        other.topology_version = 2;
        bvh.update(&other);
        assert_eq!((bvh.len(), bvh.topology_version), (other.triangles.len(), 2));
        bvh.validate().unwrap();
        let empty = Surface::new(&[], vec![], 0).unwrap();
        let bvh = Bvh::build(&empty, 0.0);
        bvh.validate().unwrap();
        bvh.for_each_overlap(&[0.0; 3], &[1.0; 3], |_| panic!("empty tree"));
    }
}
