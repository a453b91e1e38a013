//! The near part of the mesh ([`Near`]) from node-triangle pairs kept over several steps: a
//! Verlet list with a skin, the classic way particle codes avoid a neighbour search every step.
//!
//! The triangles are kept by *runs* of consecutive numbers, each with the box around its
//! triangles' boxes (the longest runs up to [`MAX_RUN`] whose boxes are on average no wider than
//! twice the skin, chosen at each rebuild). At a rebuild every run box is widened, and the pairs
//! of reach boxes and widened run boxes are found by the search [`Near::find`] uses
//! ([`pairs_by_node`]). The widening follows the motion: a run box moved by `m` since the last
//! call is stretched by `k m` ahead of it and by the slack `σ` on every side, with `k` such that
//! the fastest run is stretched by the skin `δ` (a surface moving at a steady velocity keeps
//! its pairs for as many steps as a skin of `δ` on every side would, with far fewer pairs: the
//! skin lies only where the surface is going). Without a last call of the same runs (the first,
//! a new topology or a new run length) the nodal velocities at `t_b` stand in for the motion
//! (the bounds of each run's nodal velocity components), and where those are all zero every
//! side is widened by `δ`. While each run's current
//! box stays inside its widened one, a triangle whose box meets a reach box now lies in a run
//! kept for that node, so filtering the kept runs by their current boxes, and the triangles of
//! the runs that pass by theirs, gives exactly the pairs of a fresh search, in ascending order:
//! [`NearSkin::find`] equals [`Near::find`] (tested), at the cost of a linear pass. A run that
//! leaves its widened box (a turning surface, one that speeds up), a new topology or a new
//! hierarchy size triggers the next rebuild. Nothing here is state of the run: a restarted run
//! rebuilds at its first step and gets the same [`Near`].

use super::by_node::{pairs_by_node, par_node_chunks};
use super::near::{Lists, Near, NodeBoxes, Split, AHEAD};
use crate::embedded::adjacency::NodeEdges;
use crate::embedded::bvh::{overlaps, Bvh};
use crate::embedded::Surface;
use crate::mesh::Mesh;
use crate::prefetch::prefetch;

/// Skin width `δ` relative to the mean shortest edge at the mesh nodes: a surface moving a
/// tenth of a cell per step rebuilds about every fifth step.
pub const SKIN: f64 = 0.5;

/// Slack `σ` on every side relative to the same edge (module docs): room for a surface that
/// turns a little.
pub const SLACK: f64 = 0.0625;

/// Most consecutive triangles kept together (module docs): surfaces numbered row by row
/// (generated grids, most mesh files) make runs a few triangles across.
pub const MAX_RUN: usize = 16;

/// Node-triangle pairs within the skin, grouped by node (module docs).
#[derive(Debug, Clone, Default)]
pub struct NearSkin {
    /// Width added ahead of the motion ([`SKIN`]) and on every side ([`SLACK`]) of every run
    /// box at a rebuild.
    skin: f64,
    slack: f64,
    /// Triangles per run.
    run: usize,
    /// The widened run boxes of the last rebuild, and the number of triangles then.
    lo: Vec<[f64; 3]>,
    hi: Vec<[f64; 3]>,
    triangles: usize,
    topology_version: u64,
    /// Kept runs of node `i`: `kept[offsets[i]..offsets[i + 1]]`, ascending.
    offsets: Vec<u32>,
    kept: Vec<u32>,
    /// The nodes with kept triangles, ascending.
    kept_nodes: Vec<u32>,
    /// The run boxes of the last call, whose change to the next call's is the motion a rebuild
    /// widens ahead (module docs).
    last: RunBoxes,
    /// Rebuilds so far (run statistics).
    pub rebuilds: usize,
}

impl NearSkin {
    /// An empty skin (the first [`NearSkin::find`] rebuilds) of width [`SKIN`] times the mean
    /// of the finite `h_min` of `adjacency`.
    pub fn new(adjacency: &NodeEdges) -> NearSkin {
        let finite = adjacency.h_min.iter().filter(|h| h.is_finite());
        let (sum, n) = finite.fold((0.0, 0usize), |(s, n), h| (s + h, n + 1));
        let h = if n > 0 { sum / n as f64 } else { 0.0 };
        NearSkin { skin: SKIN * h, slack: SLACK * h, run: 1, ..NearSkin::default() }
    }

    /// Whether the kept pairs hold every overlapping pair of `bvh`'s current boxes, whose run
    /// boxes are `runs`.
    fn holds(&self, bvh: &Bvh, runs: &RunBoxes) -> bool {
        bvh.topology_version == self.topology_version
            && bvh.len() == self.triangles
            && runs.lo.iter().zip(&runs.hi).enumerate().all(|(r, (lo, hi))| {
                (0..3).all(|d| lo[d] >= self.lo[r][d] && hi[d] <= self.hi[r][d])
            })
    }

    /// Widens the current run boxes of `bvh` (over `surface`) and keeps the pairs they make with
    /// the reach boxes: by [`SLACK`] on every side and by the motion scaled to [`SKIN`] for the
    /// fastest run (module docs): the motion since the last call, or without a last call of the
    /// same runs (the first, a new topology or a new run length) the nodal velocities; by
    /// [`SKIN`] on every side where that motion is zero.
    fn rebuild(&mut self, boxes: &NodeBoxes, bvh: &Bvh, surface: &Surface) {
        let last_run = self.run;
        self.run = 1;
        let mut runs = RunBoxes::new(bvh, 1);
        while self.run < MAX_RUN {
            let longer = RunBoxes::new(bvh, 2 * self.run);
            if longer.mean_width() > 2.0 * self.skin {
                break;
            }
            (self.run, runs) = (2 * self.run, longer);
        }
        let same = self.run == last_run
            && self.last.lo.len() == runs.lo.len()
            && self.topology_version == bvh.topology_version;
        let (down, up) =
            if same { runs.motion_since(&self.last) } else { velocity_bounds(surface, self.run) };
        (self.lo, self.hi) = runs.widened_ahead(&down, &up, self.skin, self.slack);
        self.triangles = bvh.len();
        self.topology_version = bvh.topology_version;
        let (lo, hi) = (&self.lo, &self.hi);
        (self.kept_nodes, self.offsets, self.kept) =
            pairs_by_node(boxes, lo.len(), |r| (lo[r], hi[r]));
        self.rebuilds += 1;
    }

    /// [`Near::find`] for `bvh`'s current boxes (the hierarchy of `surface`), from the kept
    /// pairs (rebuilt when they no longer hold every pair).
    pub fn find(&mut self, mesh: &Mesh, boxes: &NodeBoxes, bvh: &Bvh, surface: &Surface) -> Near {
        debug_assert_eq!(boxes.len(), mesh.n_nodes(), "node boxes of another mesh");
        debug_assert_eq!(bvh.len(), surface.triangles.len(), "hierarchy of another surface");
        let mut runs = RunBoxes::new(bvh, self.run);
        if !self.holds(bvh, &runs) {
            self.rebuild(boxes, bvh, surface);
            runs = RunBoxes::new(bvh, self.run);
        }
        self.last = runs;
        let runs = &self.last;
        let run = self.run;
        let rho = boxes.rho;
        let n = bvh.len();
        let chunks: Vec<Lists> = par_node_chunks(&self.kept_nodes, |nodes| {
            let mut lists = Lists::default();
            for (k, &i) in nodes.iter().enumerate() {
                if let Some(&ahead) = nodes.get(k + AHEAD) {
                    let ahead = ahead as usize;
                    boxes.tree.prefetch_box(ahead);
                    prefetch(&mesh.coords, ahead);
                    prefetch(&self.offsets, ahead);
                }
                let i_ = i as usize;
                let start = lists.len();
                let (lo, hi) = boxes.tree.triangle_box(i_);
                let split = Split::new(&mesh.coords[i_], rho);
                let kept = &self.kept[self.offsets[i_] as usize..self.offsets[i_ + 1] as usize];
                let box_of = |t| bvh.triangle_box(t);
                if run == 1 {
                    // Each run is one triangle, its box the run box.
                    lists.push_overlapping(kept.iter().copied(), &split, &lo, &hi, box_of);
                } else {
                    for &r in kept {
                        let r = r as usize;
                        if overlaps(&lo, &hi, &runs.lo[r], &runs.hi[r]) {
                            let triangles = (r * run) as u32..((r + 1) * run).min(n) as u32;
                            lists.push_overlapping(triangles, &split, &lo, &hi, box_of);
                        }
                    }
                }
                lists.close(i, start);
            }
            lists
        });
        Near::from_lists(mesh.n_nodes(), &self.kept_nodes, rho, chunks)
    }

    /// Memory in bytes.
    pub fn memory_bytes(&self) -> usize {
        use std::mem::size_of_val;
        size_of_val(&self.lo[..])
            + size_of_val(&self.hi[..])
            + size_of_val(&self.offsets[..])
            + size_of_val(&self.kept[..])
            + size_of_val(&self.kept_nodes[..])
            + size_of_val(&self.last.lo[..])
            + size_of_val(&self.last.hi[..])
    }
}

/// The box around the triangle boxes of each run of `run` triangles of a hierarchy.
#[derive(Debug, Clone, Default)]
struct RunBoxes {
    lo: Vec<[f64; 3]>,
    hi: Vec<[f64; 3]>,
}

impl RunBoxes {
    fn new(bvh: &Bvh, run: usize) -> RunBoxes {
        let n = bvh.len();
        let (lo, hi) = (0..n.div_ceil(run))
            .map(|r| {
                let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
                for t in r * run..((r + 1) * run).min(n) {
                    let (a, b) = bvh.triangle_box(t);
                    for d in 0..3 {
                        lo[d] = lo[d].min(a[d]);
                        hi[d] = hi[d].max(b[d]);
                    }
                }
                (lo, hi)
            })
            .unzip();
        RunBoxes { lo, hi }
    }

    /// The motion of the lower and of the upper corner of each box since `last` (the same
    /// runs).
    fn motion_since(&self, last: &RunBoxes) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
        let motion = |now: &[[f64; 3]], then: &[[f64; 3]]| -> Vec<[f64; 3]> {
            now.iter().zip(then).map(|(a, b)| [0, 1, 2].map(|d| a[d] - b[d])).collect()
        };
        (motion(&self.lo, &last.lo), motion(&self.hi, &last.hi))
    }

    /// Every box widened by `slack` on every side and stretched ahead by the motion of its
    /// corners (`down` for the lower, `up` for the upper), scaled so the fastest moves `skin`;
    /// by `skin` on every side where no corner moves (or a motion is not finite).
    fn widened_ahead(
        &self,
        down: &[[f64; 3]],
        up: &[[f64; 3]],
        skin: f64,
        slack: f64,
    ) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
        let fastest = down.iter().chain(up).flatten().fold(0.0, |m: f64, v| m.max(v.abs()));
        if !(fastest > 0.0 && fastest.is_finite()) {
            let lo = self.lo.iter().map(|lo| lo.map(|v| v - skin)).collect();
            let hi = self.hi.iter().map(|hi| hi.map(|v| v + skin)).collect();
            return (lo, hi);
        }
        let scale = skin / fastest;
        let lo = self.lo.iter().zip(down);
        let lo = lo.map(|(lo, m)| [0, 1, 2].map(|d| lo[d] - slack + (scale * m[d]).min(0.0)));
        let hi = self.hi.iter().zip(up);
        let hi = hi.map(|(hi, m)| [0, 1, 2].map(|d| hi[d] + slack + (scale * m[d]).max(0.0)));
        (lo.collect(), hi.collect())
    }

    /// The mean over the runs of the widest side of the box (0 for none).
    fn mean_width(&self) -> f64 {
        let widths = self.lo.iter().zip(&self.hi);
        let sum: f64 =
            widths.map(|(lo, hi)| (0..3).map(|d| hi[d] - lo[d]).fold(0.0, f64::max)).sum();
        sum / self.lo.len().max(1) as f64
    }
}

/// The bounds of the nodal velocity components at `t_b` over each run of `run` triangles of
/// `surface`: the motion of the lower and of the upper corner of each run box per unit time.
fn velocity_bounds(surface: &Surface, run: usize) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
    let triangles = &surface.triangles;
    (0..triangles.len().div_ceil(run))
        .map(|r| {
            let (mut down, mut up) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
            let nodes = triangles[r * run..((r + 1) * run).min(triangles.len())].iter().flatten();
            for &n in nodes {
                let v = surface.v_b[n as usize];
                for d in 0..3 {
                    down[d] = down[d].min(v[d]);
                    up[d] = up[d].max(v[d]);
                }
            }
            (down, up)
        })
        .unzip()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::embedded::tests::{cube_mesh, sphere};

    /// A sphere moving a small and then a large distance per step: the skin's near part equals a
    /// fresh traversal every step, it rebuilds only when a box leaves the skin, and a jump of
    /// several cells rebuilds at once.
    #[test]
    fn the_skin_gives_the_fresh_near_part_and_rebuilds_only_when_a_box_leaves_it() {
        let mesh = cube_mesh(12, 0.3, 4);
        let adj = NodeEdges::build(&mesh);
        let boxes = NodeBoxes::build(&mesh, &adj);
        let rest = sphere([0.45, 0.5, 0.48], 0.25, 8);
        let mut surface = rest.clone();
        let mut bvh = Bvh::build(&surface, 1e-4);
        let mut skin = NearSkin::new(&adj);
        let h = 1.0 / 12.0;
        let mut shift = 0.0;
        for step in 1..=14 {
            shift += if step < 12 { 0.01 * h } else { 3.0 * h };
            let x: Vec<[f64; 3]> =
                rest.x_b.iter().map(|p| [p[0] + shift, p[1] - 0.5 * shift, p[2]]).collect();
            surface.advance(0.01 * step as f64, &x, &vec![[0.0; 3]; x.len()]);
            bvh.update(&surface);
            let fresh = Near::find(&mesh, &boxes, &bvh);
            assert!(!fresh.nodes.is_empty());
            assert_eq!(skin.find(&mesh, &boxes, &bvh, &surface), fresh, "step {step}");
            if step == 11 {
                // 0.11 h moved against a skin of half the mean shortest edge: one rebuild, the first.
                assert_eq!(skin.rebuilds, 1, "step {step}");
            }
        }
        // Each of the three jumps left the skin.
        assert_eq!(skin.rebuilds, 4);
    }

    /// A sphere moving at a steady velocity and one circling an axis: the skin's near part equals
    /// a fresh traversal every step; the steady one keeps its pairs as many steps as a skin on
    /// every side would (no more rebuilds) with far fewer pairs kept: from the first rebuild on
    /// when its nodal velocities are given, from the second (the first motion seen) when not.
    #[test]
    fn the_skin_ahead_of_the_motion_keeps_fewer_pairs_for_as_long() {
        let mesh = cube_mesh(14, 0.3, 5);
        let adj = NodeEdges::build(&mesh);
        let boxes = NodeBoxes::build(&mesh, &adj);
        let rest = sphere([0.4, 0.45, 0.5], 0.2, 10);
        let h = 1.0 / 14.0;
        let dt = 0.01;
        let steady = |k: f64| [0.04 * h * k, 0.01 * h * k, 0.0];
        let circling = |k: f64| {
            let a = 0.05 * k;
            [0.1 * (a.cos() - 1.0), 0.1 * a.sin(), 0.0]
        };
        // `ahead`: widen ahead of the motion seen since the last call; `velocities`: give the
        // nodal velocities (else zero).
        let run =
            |motion: &dyn Fn(f64) -> [f64; 3], steps: usize, ahead: bool, velocities: bool| {
                let mut surface = rest.clone();
                let mut bvh = Bvh::build(&surface, 1e-4);
                let mut skin = NearSkin::new(&adj);
                let mut kept = Vec::new();
                for k in 1..=steps {
                    let m = motion(k as f64);
                    let x: Vec<[f64; 3]> =
                        rest.x_b.iter().map(|p| [0, 1, 2].map(|d| p[d] + m[d])).collect();
                    // The rigid motion's velocity at the step's end, by a central difference.
                    let (after, before) = (motion(k as f64 + 1e-4), motion(k as f64 - 1e-4));
                    let v = [0, 1, 2].map(|d| (after[d] - before[d]) / (2e-4 * dt));
                    let v = if velocities { v } else { [0.0; 3] };
                    surface.advance(dt * k as f64, &x, &vec![v; x.len()]);
                    bvh.update(&surface);
                    if !ahead {
                        // No last call: every rebuild widens by the velocities, or every side.
                        skin.last = RunBoxes::default();
                    }
                    let fresh = Near::find(&mesh, &boxes, &bvh);
                    assert_eq!(skin.find(&mesh, &boxes, &bvh, &surface), fresh, "step {k}");
                    kept.push(skin.kept.len());
                }
                (skin.rebuilds, kept)
            };
        let mean = |k: &[usize]| k.iter().sum::<usize>() as f64 / k.len() as f64;
        let (rebuilds, kept) = run(&steady, 60, true, false);
        let (rebuilds_around, kept_around) = run(&steady, 60, false, false);
        assert!(rebuilds > 2 && rebuilds <= rebuilds_around, "{rebuilds} vs {rebuilds_around}");
        // The steps after the first rebuild ahead of the motion.
        let after = kept.iter().position(|&k| k != kept[0]).unwrap();
        let ratio = mean(&kept[after..]) / mean(&kept_around[after..]);
        assert!(ratio < 0.8, "kept {ratio} of the pairs");
        // With the velocities, ahead from the first step on, by either estimate of the motion.
        for ahead in [true, false] {
            let (rebuilds_v, kept_v) = run(&steady, 60, ahead, true);
            assert!(rebuilds_v <= rebuilds_around, "{rebuilds_v} vs {rebuilds_around}");
            let ratio = mean(&kept_v) / mean(&kept_around);
            assert!(ratio < 0.8, "ahead {ahead}: kept {ratio} of the pairs");
            let first = kept_v[0] as f64 / kept_around[0] as f64;
            assert!(first < 0.8, "ahead {ahead}: kept {first} of the pairs at the first step");
        }
        for velocities in [false, true] {
            let (turning, _) = run(&circling, 60, true, velocities);
            assert!(turning > 2, "{turning} rebuilds");
        }
    }

    /// A finely meshed plate (runs of several triangles) and the same plate with its triangles
    /// numbered at random (runs without locality): the skin's near part equals a fresh traversal
    /// at every step of a slow drift.
    #[test]
    fn runs_of_any_numbering_give_the_fresh_near_part() {
        let mesh = cube_mesh(10, 0.3, 6);
        let adj = NodeEdges::build(&mesh);
        let boxes = NodeBoxes::build(&mesh, &adj);
        let fine = crate::embedded::generate::plate(
            [0.2, 0.25, 0.4],
            [0.6, 0.0, 0.1],
            [0.0, 0.5, 0.05],
            [40, 30],
        );
        let mut shuffled = fine.elements.clone();
        let mut state = 12345u64;
        for k in (1..shuffled.len()).rev() {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            shuffled.swap(k, (state >> 33) as usize % (k + 1));
        }
        for (label, elements, run) in [("rows", &fine.elements, 4), ("shuffled", &shuffled, 1)] {
            let rest = crate::embedded::Surface::new(elements, fine.x.clone(), 0).unwrap();
            let mut surface = rest.clone();
            let mut bvh = Bvh::build(&surface, 1e-4);
            let mut skin = NearSkin::new(&adj);
            for step in 1..=8 {
                let shift = 0.02 * step as f64;
                let x: Vec<[f64; 3]> =
                    rest.x_b.iter().map(|p| [p[0] + shift, p[1], p[2] + 0.5 * shift]).collect();
                surface.advance(0.01 * step as f64, &x, &vec![[0.0; 3]; x.len()]);
                bvh.update(&surface);
                let fresh = Near::find(&mesh, &boxes, &bvh);
                assert!(!fresh.nodes.is_empty());
                assert_eq!(skin.find(&mesh, &boxes, &bvh, &surface), fresh, "{label}, step {step}");
            }
            assert!(skin.run >= run, "{label}: runs of {}", skin.run);
            assert!(skin.rebuilds > 1, "{label}: {} rebuilds", skin.rebuilds);
        }
    }
}
