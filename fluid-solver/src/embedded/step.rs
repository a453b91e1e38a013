//! What the residual needs from the embedded boundary in one fluid step (DESIGN §5.1): the
//! special edges of every block (the two-material edges of the scheme merged with the cut edges,
//! the uncut edges that touch a node that is not active, and the dead edges between two such
//! nodes, which carry no flux: a closed body's inside costs no edge work), the gradient operator
//! with those edges masked out (flow gradients never cross the surface or a material interface),
//! and the wall fluxes of Alg. 5.1 ([`super::riemann_fs`]). Built from the tracker at the first
//! step and updated at each later one only where the tracking changed something (the gradient
//! rebuilt at the ends of the edges whose status changed), read by the residual at each stage
//! time.

use super::riemann_fs::{one_sided, wall_states, End, WallFluxError, WallFluxView};
use super::riemann_fs::{WallMaterial, WallPressures};
use super::tracker::Tracker;
use crate::flux::wall_flux;
use crate::mesh::blocks::Window;
use crate::reconstruct::gradient::LsqGradient;
use crate::riemann::PressureCutoff;
use crate::semidiscretization::{FluidError, Semidiscretization};
use crate::special_edges::{SpecialEdge, SpecialEdges, SpecialKind};
use interface_protocol::case::InterfaceTreatment;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Duration;

/// The embedded boundary as one step's residuals read it.
#[derive(Debug, Clone, PartialEq)]
pub struct EmbeddedStep {
    /// The dead, frozen and cut edges, per block.
    ours: SpecialEdges,
    /// Those merged with the scheme's two-material edges, when it has any.
    merged: Option<SpecialEdges>,
    /// Least-squares gradients through the ordinary edges only.
    pub gradient: LsqGradient,
    /// The wall material of each fluid (EOS and cavitation cut-off).
    pub materials: Vec<WallMaterial>,
    /// Number of uncut edges with exactly one active end (taken as slip walls).
    pub frozen_edges: usize,
    /// What the step was built from, for [`EmbeddedStep::update`]: the active nodes and the cut
    /// edges (ascending).
    active: Vec<bool>,
    cut: Vec<u32>,
    /// The states of the cut-edge fluxes ([`super::riemann_fs::interface`]); the second-order
    /// form needs the scheme's gradients (a first-order scheme takes the first-order form).
    pub interface: InterfaceTreatment,
    /// Time spent in the special edges' fluxes (cut and frozen; two-material ones with a level
    /// set) since it was last taken.
    pub wall_flux_clock: FluxClock,
}

/// Nanoseconds summed over the threads that add to it; no part of a step view's state (any two
/// compare equal, a clone starts from the same count).
#[derive(Debug, Default)]
pub struct FluxClock(AtomicU64);

impl FluxClock {
    /// Adds `d` (called once per block and stage).
    pub fn add(&self, d: Duration) {
        let ns = u64::try_from(d.as_nanos()).unwrap_or(u64::MAX);
        self.0.fetch_add(ns, Ordering::Relaxed);
    }

    /// The seconds counted so far, resetting the count.
    pub fn take_seconds(&self) -> f64 {
        self.0.swap(0, Ordering::Relaxed) as f64 * 1e-9
    }
}

impl Clone for FluxClock {
    fn clone(&self) -> Self {
        FluxClock(AtomicU64::new(self.0.load(Ordering::Relaxed)))
    }
}

impl PartialEq for FluxClock {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

/// Nodes, and edges, per parallel task of [`EmbeddedStep::update`] (small in the tests, so that
/// their meshes make several).
const UPDATE_CHUNK: usize = if cfg!(test) { 64 } else { 4096 };

/// The sorted union of two ascending lists, each value once.
pub(super) fn union_sorted<T: Ord + Copy>(a: &[T], b: &[T]) -> Vec<T> {
    let mut out = Vec::with_capacity(a.len() + b.len());
    let (mut x, mut y) = (0, 0);
    loop {
        let v = match (a.get(x), b.get(y)) {
            (Some(&p), Some(&q)) => p.min(q),
            (Some(&p), None) => p,
            (None, Some(&q)) => q,
            (None, None) => break,
        };
        while a.get(x) == Some(&v) {
            x += 1;
        }
        while b.get(y) == Some(&v) {
            y += 1;
        }
        out.push(v);
    }
    out
}

impl EmbeddedStep {
    /// The step's view of `tracker` for the scheme `semi` with the cut-off `p_cut` (Pa; `None`:
    /// the EOS defaults of [`PressureCutoff`]) and the interface treatment `interface`.
    pub fn new(
        semi: &Semidiscretization,
        tracker: &Tracker,
        p_cut: Option<f64>,
        interface: InterfaceTreatment,
    ) -> EmbeddedStep {
        let mesh = &semi.mesh;
        let cut: Vec<u32> = tracker.cuts.cuts.iter().map(|c| c.edge).collect();
        let active = tracker.active.clone();
        let material = semi.material();
        let cut_mask = tracker.cuts.cut_mask(mesh.n_edges());
        let mut list = Vec::new();
        let mut used = vec![true; mesh.n_edges()];
        for (e, u) in used.iter_mut().enumerate() {
            let kind = EdgeKind::of(mesh.edges[e], cut_mask[e], &active, material);
            *u = kind.used;
            list.extend(kind.special.map(|kind| SpecialEdge { edge: e as u32, kind }));
        }
        let gradient = LsqGradient::with_planes(mesh, Some(&used), semi.gradient.planes().clone());
        let materials = semi
            .eos
            .iter()
            .map(|eos| WallMaterial {
                eos: *eos,
                cutoff: p_cut.map_or_else(
                    || PressureCutoff::default_for(eos),
                    |p_cut| PressureCutoff { p_cut },
                ),
            })
            .collect();
        let interface = match semi.numerics.second_order() {
            true => interface,
            false => InterfaceTreatment::FirstOrder,
        };
        let frozen_edges = frozen_among(&list);
        let (ours, merged) = special_edges(semi, list);
        EmbeddedStep {
            ours,
            merged,
            gradient,
            materials,
            frozen_edges,
            active,
            cut,
            interface,
            wall_flux_clock: FluxClock::default(),
        }
    }

    /// The step's view after `tracker` moved on: only the edges whose status can have changed
    /// (cut before or now but not both, or touching a node whose activity changed; an edge cut
    /// both times stays a cut, out of the gradient) are looked at, and the gradient is rebuilt
    /// only at the ends of those whose status did change ([`LsqGradient::remask`]). Bitwise the
    /// same as [`EmbeddedStep::new`] on the same scheme.
    pub fn update(&mut self, semi: &Semidiscretization, tracker: &Tracker) {
        let mesh = &semi.mesh;
        let material = semi.material();
        let cut: Vec<u32> = tracker.cuts.cuts.iter().map(|c| c.edge).collect();
        let adjacency = &tracker.adjacency;
        let mut changed: Vec<u32> = (tracker.active.par_chunks(UPDATE_CHUNK))
            .zip(self.active.par_chunks(UPDATE_CHUNK))
            .enumerate()
            .filter(|(_, (now, before))| now != before)
            .flat_map_iter(|(c, (now, before))| {
                let first = c * UPDATE_CHUNK;
                let moved = now.iter().zip(before).enumerate().filter(|(_, (n, b))| n != b);
                moved.flat_map(move |(k, _)| adjacency.edges_of(first + k).iter().copied())
            })
            .collect();
        changed.par_sort_unstable();
        // The cut edges before and now are each sorted: two merges.
        let edges = union_sorted(&symmetric_difference(&self.cut, &cut), &changed);
        // Each run of edges walks the cut list from its first edge.
        let parts: Vec<(Vec<u32>, Vec<SpecialEdge>)> = edges
            .par_chunks(UPDATE_CHUNK)
            .map(|run| {
                let (mut flipped, mut now) = (Vec::new(), Vec::new());
                let mut cut_now = cut[cut.partition_point(|&c| c < run[0])..].iter().peekable();
                for &e in run {
                    while cut_now.next_if(|&&c| c < e).is_some() {}
                    let is_cut = cut_now.peek() == Some(&&e);
                    let kind =
                        EdgeKind::of(mesh.edges[e as usize], is_cut, &tracker.active, material);
                    if kind.used != self.gradient.uses(e as usize) {
                        flipped.push(e);
                    }
                    now.extend(kind.special.map(|kind| SpecialEdge { edge: e, kind }));
                }
                (flipped, now)
            })
            .collect();
        let flipped: Vec<u32> = parts.iter().flat_map(|p| p.0.iter().copied()).collect();
        let now: Vec<SpecialEdge> = parts.iter().flat_map(|p| p.1.iter().copied()).collect();
        self.gradient.remask(mesh, &flipped, |i| tracker.adjacency.edges_of(i));
        // The special edges that were not looked at stay as they were.
        let (list, replaced) = replace_sorted(self.ours.all(), &edges, &now);
        let frozen = self.frozen_edges - replaced + frozen_among(&now);
        (self.ours, self.merged) = special_edges(semi, list);
        self.frozen_edges = frozen;
        self.cut = cut;
        self.active.copy_from_slice(&tracker.active);
    }

    /// Memory in bytes of the operator, the special edges and the lists kept for the update.
    pub fn memory_bytes(&self) -> usize {
        use std::mem::size_of_val;
        self.gradient.memory_bytes()
            + self.ours.memory_bytes()
            + self.merged.as_ref().map_or(0, SpecialEdges::memory_bytes)
            + size_of_val(&self.active[..])
            + size_of_val(&self.cut[..])
    }

    /// The special edges the residual reads: the scheme's two-material edges merged with the
    /// dead, frozen and cut ones, per block.
    pub fn special(&self) -> &SpecialEdges {
        self.merged.as_ref().unwrap_or(&self.ours)
    }
}

/// The values in exactly one of two ascending lists (each value at most once in each),
/// ascending.
fn symmetric_difference(a: &[u32], b: &[u32]) -> Vec<u32> {
    let mut out = Vec::new();
    let (mut a, mut b) = (a.iter().peekable(), b.iter().peekable());
    loop {
        match (a.peek(), b.peek()) {
            (Some(&&x), Some(&&y)) if x == y => {
                a.next();
                b.next();
            }
            (Some(&&x), Some(&&y)) if x < y => out.extend(a.next()),
            (Some(_), Some(_)) => out.extend(b.next()),
            (Some(_), None) => out.extend(a.next()),
            (None, Some(_)) => out.extend(b.next()),
            (None, None) => return out,
        }
    }
}

/// The entries of `old` whose edge is not in `looked`, merged with `now` (entries of edges of
/// `looked`): all ascending by edge, and how many frozen entries of `old` were replaced. The
/// entries between two looked-at edges are copied as one stretch, found by galloping from the
/// last one, so a few looked-at edges cost little more than one copy of `old`.
fn replace_sorted(
    old: &[SpecialEdge],
    looked: &[u32],
    now: &[SpecialEdge],
) -> (Vec<SpecialEdge>, usize) {
    let mut out = Vec::with_capacity(old.len() + now.len());
    let (mut from, mut replaced) = (0, 0);
    let mut now = now.iter().peekable();
    for &e in looked {
        let k = from + gallop(&old[from..], e);
        out.extend_from_slice(&old[from..k]);
        from = k;
        if let Some(s) = old.get(k).filter(|s| s.edge == e) {
            replaced += usize::from(s.kind == SpecialKind::Frozen);
            from += 1;
        }
        out.extend(now.next_if(|n| n.edge == e));
    }
    debug_assert!(now.next().is_none(), "a new entry of an edge not looked at");
    out.extend_from_slice(&old[from..]);
    (out, replaced)
}

/// The number of leading entries of `items` (ascending by edge) whose edge is below `e`: steps
/// doubling from the front, then a binary search within the last.
fn gallop(items: &[SpecialEdge], e: u32) -> usize {
    let mut end = 1;
    while end < items.len() && items[end - 1].edge < e {
        end *= 2;
    }
    // Every entry before `end / 2` is below `e`, and none from `end` on.
    let start = end / 2;
    start + items[start..end.min(items.len())].partition_point(|s| s.edge < e)
}

/// The number of frozen entries of `list`.
fn frozen_among(list: &[SpecialEdge]) -> usize {
    list.iter().filter(|s| s.kind == SpecialKind::Frozen).count()
}

/// What one edge is in a step.
struct EdgeKind {
    /// In the masked gradient: uncut, both ends active and of one material.
    used: bool,
    /// Cut; else frozen (exactly one active end) or dead (no active end).
    special: Option<SpecialKind>,
}

impl EdgeKind {
    #[inline]
    fn of([i, j]: [u32; 2], cut: bool, active: &[bool], material: &[u8]) -> EdgeKind {
        let (i, j) = (i as usize, j as usize);
        let (ai, aj) = (active[i], active[j]);
        let special = match (cut, ai, aj) {
            (true, ..) => Some(SpecialKind::Cut),
            (false, true, true) => None,
            (false, false, false) => Some(SpecialKind::Dead),
            (false, ..) => Some(SpecialKind::Frozen),
        };
        EdgeKind { used: !cut && ai && aj && material[i] == material[j], special }
    }
}

/// The dead, frozen and cut edges of `list` (ascending) per block, merged with the scheme's
/// special edges when it has any.
fn special_edges(
    semi: &Semidiscretization,
    list: Vec<SpecialEdge>,
) -> (SpecialEdges, Option<SpecialEdges>) {
    let blocks = &semi.mesh.blocks;
    let ours = SpecialEdges::from_sorted(blocks, list);
    let scheme = semi.special_edges();
    let merged = (!scheme.is_empty()).then(|| scheme.merge(&ours, blocks));
    (ours, merged)
}

/// The embedded boundary at one stage time, as the residual reads it.
#[derive(Clone, Copy)]
pub struct Wall<'a> {
    pub step: &'a EmbeddedStep,
    pub tracker: &'a Tracker,
    /// Stage time (the wall velocity is taken there).
    pub t: f64,
}

/// Nodal gradients of the primitive states, `grad[i][k] = ∇W_k` at node `i`.
pub type Gradients = [[[f64; 3]; 5]];

impl Wall<'_> {
    /// The wall fluxes' view of the states `prim` and their gradients `grad` (read only by the
    /// second-order interface).
    fn view<'b>(
        &'b self,
        semi: &'b Semidiscretization,
        prim: &'b [[f64; 5]],
        grad: &'b Gradients,
    ) -> WallFluxView<'b> {
        let second_order = self.step.interface == InterfaceTreatment::SecondOrder;
        WallFluxView {
            mesh: &semi.mesh,
            surface: &self.tracker.surface,
            t: self.t,
            scheme: semi.numerics.flux,
            active: &self.tracker.active,
            material: semi.material(),
            materials: &self.step.materials,
            prim,
            grad: second_order.then_some(grad),
            limiter: semi.numerics.limiter,
        }
    }

    /// Adds the fluxes of the special edge `s` of kind `Cut` or `Frozen` to the residuals of its
    /// active ends: Alg. 5.1 at a cut edge; a slip wall on the facet at a frozen edge.
    pub fn edge_flux(
        &self,
        semi: &Semidiscretization,
        s: SpecialEdge,
        prim: &[[f64; 5]],
        grad: &Gradients,
        r: &mut Window<'_, [f64; 5]>,
    ) -> Result<(), FluidError> {
        let mesh = &semi.mesh;
        let e = s.edge as usize;
        let [i, j] = mesh.edges[e].map(|v| v as usize);
        let active = &self.tracker.active;
        match s.kind {
            SpecialKind::Cut => {
                let cut = self.tracker.cuts.find(s.edge).expect("a cut special edge is cut");
                let view = self.view(semi, prim, grad);
                for (end, node) in [(End::I, i), (End::J, j)] {
                    if active[node] {
                        let f = one_sided(&view, cut, end).map_err(FluidError::Wall)?;
                        for k in 0..5 {
                            r[node][k] += f.flux[k];
                        }
                    }
                }
            }
            SpecialKind::Frozen => {
                let nu = mesh.edge_normals[e];
                let (node, n) = if active[i] { (i, nu) } else { (j, nu.map(|c| -c)) };
                let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
                let unit = n.map(|c| c / len);
                let f = wall_flux(
                    semi.numerics.flux,
                    semi.eos_at(node),
                    &prim[node],
                    &n,
                    &unit,
                    &[0.0; 3],
                )
                .map_err(|error| FluidError::FrozenEdge {
                    edge: e,
                    node,
                    position: mesh.coords[node],
                    error,
                })?;
                for k in 0..5 {
                    r[node][k] += f.flux[k];
                }
            }
            SpecialKind::TwoMaterial | SpecialKind::Dead => {
                unreachable!("two-material and dead edges are the residual's")
            }
        }
        Ok(())
    }

    /// `p*` on both sides of every cut edge from the states `prim` and their gradients `grad`
    /// through the step's gradient operator (the loads' input, Alg. 5.3 and 5.4), and the number
    /// of cavitation clips.
    pub fn pressures(
        &self,
        semi: &Semidiscretization,
        prim: &[[f64; 5]],
        grad: &Gradients,
    ) -> Result<(Vec<WallPressures>, usize), WallFluxError> {
        let view = self.view(semi, prim, grad);
        let mesh = &semi.mesh;
        // Each cut edge on its own, in parallel; the first failing edge (in edge order) is named.
        let per_edge: Vec<Result<(WallPressures, usize), WallFluxError>> = self
            .tracker
            .cuts
            .cuts
            .par_iter()
            .map(|cut| {
                let [i, j] = mesh.edges[cut.edge as usize].map(|v| v as usize);
                let (mut ps, mut clips) = ([f64::NAN; 2], 0);
                for (k, (end, node)) in [(End::I, i), (End::J, j)].into_iter().enumerate() {
                    if self.tracker.active[node] {
                        let star = wall_states(&view, cut, end)?.star;
                        ps[k] = star.w[4];
                        clips += star.clipped as usize;
                    }
                }
                Ok((ps, clips))
            })
            .collect();
        let mut clips = 0;
        let mut out = Vec::with_capacity(per_edge.len());
        for r in per_edge {
            let (ps, c) = r?;
            out.push(ps);
            clips += c;
        }
        Ok((out, clips))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bc::BoundaryCondition;
    use crate::embedded::tests::{cube_mesh, plane, sphere};
    use crate::embedded::tracker::Seed;
    use crate::eos::Eos;
    use crate::mesh::boxmesh::FACE_NAMES;
    use crate::semidiscretization::Numerics;
    use interface_protocol::case::Tracking;

    /// Replacing the looked-at edges by stretches equals a plain replacement (kept entries not
    /// looked at, then the new ones, sorted), from few looked-at edges to all of them, and
    /// counts the frozen entries replaced.
    #[test]
    fn replacing_looked_at_edges_is_a_plain_merge() {
        let mut state = 99u64;
        let mut next = |m: u64| {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 33) % m
        };
        let kinds = [SpecialKind::Dead, SpecialKind::Frozen, SpecialKind::Cut];
        for round in 0..30 {
            let n = 1 + next(3000) as u32;
            let every = [1, 2, 5, 50, 400][round % 5];
            let mut old = Vec::new();
            let (mut looked, mut now) = (Vec::new(), Vec::new());
            for e in 0..n {
                if next(3) == 0 {
                    old.push(SpecialEdge { edge: e, kind: kinds[next(3) as usize] });
                }
                if next(every) == 0 {
                    looked.push(e);
                    if next(2) == 0 {
                        now.push(SpecialEdge { edge: e, kind: kinds[next(3) as usize] });
                    }
                }
            }
            let mut want: Vec<SpecialEdge> =
                old.iter().filter(|s| looked.binary_search(&s.edge).is_err()).copied().collect();
            want.extend(&now);
            want.sort_by_key(|s| s.edge);
            let replaced = old
                .iter()
                .filter(|s| s.kind == SpecialKind::Frozen && looked.binary_search(&s.edge).is_ok())
                .count();
            assert_eq!(replace_sorted(&old, &looked, &now), (want, replaced), "round {round}");
        }
    }

    /// Bitwise equality of two step views: `{:?}` prints every f64 exactly (shortest round trip,
    /// with the sign of zero).
    fn assert_bitwise(a: &EmbeddedStep, b: &EmbeddedStep, label: &str) {
        assert_eq!(a, b, "{label}");
        assert!(
            format!("{:?}", a.gradient) == format!("{:?}", b.gradient),
            "{label}: gradient bits"
        );
    }

    /// Every edge is special exactly as its ends and cut say, brute force: cut edges `Cut`;
    /// uncut ones with one active end `Frozen`, with none `Dead`; the others ordinary (one fluid).
    fn assert_kinds(
        semi: &Semidiscretization,
        tracker: &Tracker,
        step: &EmbeddedStep,
        label: &str,
    ) {
        let mesh = &semi.mesh;
        let cut = tracker.cuts.cut_mask(mesh.n_edges());
        let expected: Vec<SpecialEdge> = (0..mesh.n_edges())
            .filter_map(|e| {
                let [i, j] = mesh.edges[e].map(|v| tracker.active[v as usize]);
                let kind = match (cut[e], i, j) {
                    (true, _, _) => SpecialKind::Cut,
                    (false, false, false) => SpecialKind::Dead,
                    (false, a, b) if a != b => SpecialKind::Frozen,
                    _ => return None,
                };
                Some(SpecialEdge { edge: e as u32, kind })
            })
            .collect();
        assert_eq!(step.special().all(), &expected[..], "{label}");
    }

    #[test]
    fn union_and_symmetric_difference_of_sorted_lists() {
        assert_eq!(union_sorted(&[1, 4, 9], &[0, 4, 4, 10]), vec![0, 1, 4, 9, 10]);
        assert_eq!(union_sorted(&[], &[2, 2, 3]), vec![2, 3]);
        assert_eq!(union_sorted(&[5, 7], &[]), vec![5, 7]);
        assert!(union_sorted::<u32>(&[], &[]).is_empty());
        assert_eq!(
            symmetric_difference(&[1, 4, 9, 12], &[0, 4, 10, 12, 13]),
            vec![0, 1, 9, 10, 13]
        );
        assert_eq!(symmetric_difference(&[], &[2, 3]), vec![2, 3]);
        assert_eq!(symmetric_difference(&[5, 7], &[]), vec![5, 7]);
        assert!(symmetric_difference(&[3, 8], &[3, 8]).is_empty());
        // Edges with their ends, as Alg. 4.1 keeps them.
        let (a, b) = ([(1, [1, 2]), (4, [2, 5])], [(0, [0, 3]), (1, [1, 2])]);
        assert_eq!(union_sorted(&a, &b), vec![(0, [0, 3]), (1, [1, 2]), (4, [2, 5])]);
    }

    /// A sphere (Alg. 4.1 and 4.2) and a plane through the slip walls (Alg. 4.2, so the mirror
    /// planes of the boundary nodes take part) moving for several steps: the step view updated
    /// from step to step is bitwise the one built anew, and so are the gradients it gives; only
    /// a few nodes' matrices are rebuilt.
    #[test]
    fn updated_step_views_equal_new_ones_bitwise() {
        let mesh = cube_mesh(10, 0.25, 11);
        let walls: Vec<(String, BoundaryCondition)> =
            FACE_NAMES.iter().map(|f| (f.to_string(), BoundaryCondition::SlipWall)).collect();
        let semi = Semidiscretization::new(
            mesh,
            Eos::PerfectGas { gamma: 1.4 },
            Numerics::default(),
            &walls,
        )
        .unwrap();
        assert!(!semi.gradient.planes().is_empty());
        let mesh = &semi.mesh;
        let field: Vec<[f64; 5]> = mesh
            .coords
            .iter()
            .map(|x| [1.0 + x[0] * x[1], x[2].sin(), x[0] - x[2], 0.3 * x[1], 2.0 + x[0].cos()])
            .collect();
        let inside = Seed { point: [0.45, 0.5, 0.5], fluid: false };
        let outside = Seed { point: [0.0; 3], fluid: true };
        let cases = [
            (
                "sphere, Alg. 4.2",
                sphere([0.45, 0.5, 0.5], 0.25, 6),
                Tracking::Collision,
                vec![outside, inside],
                [0.03, 0.0, 0.01],
            ),
            (
                "sphere, Alg. 4.1",
                sphere([0.45, 0.5, 0.5], 0.25, 6),
                Tracking::Projection,
                vec![outside, inside],
                [0.03, 0.01, 0.0],
            ),
            (
                "plane, Alg. 4.2",
                plane(-0.5, 1.5, -0.5, 1.5, 0.33),
                Tracking::Collision,
                vec![outside],
                [0.0, 0.0, 0.035],
            ),
        ];
        for (label, rest, tracking, seeds, shift) in cases {
            let mut tracker = Tracker::new(mesh, rest.clone(), tracking, &seeds).unwrap();
            let mut step =
                EmbeddedStep::new(&semi, &tracker, Some(10.0), InterfaceTreatment::SecondOrder);
            let mut flipped_nodes = 0;
            for k in 1..=6 {
                let f = k as f64;
                let x: Vec<[f64; 3]> =
                    rest.x_b.iter().map(|p| [0, 1, 2].map(|d| p[d] + f * shift[d])).collect();
                let v = vec![shift.map(|c| c / 0.01); x.len()];
                tracker.advance(mesh, 0.01 * f, &x, &v).unwrap();
                let before = step.gradient.clone();
                step.update(&semi, &tracker);
                let fresh =
                    EmbeddedStep::new(&semi, &tracker, Some(10.0), InterfaceTreatment::SecondOrder);
                assert_bitwise(&step, &fresh, &format!("{label}, step {k}"));
                assert!(step.special().all().iter().any(|s| s.kind == SpecialKind::Cut));
                assert_kinds(&semi, &tracker, &step, &format!("{label}, step {k}"));
                let (mut g1, mut g2) =
                    (vec![[[0.0; 3]; 5]; mesh.n_nodes()], vec![[[0.0; 3]; 5]; mesh.n_nodes()]);
                step.gradient.compute(mesh, &field, &mut g1);
                fresh.gradient.compute(mesh, &field, &mut g2);
                assert!(g1
                    .iter()
                    .flatten()
                    .flatten()
                    .zip(g2.iter().flatten().flatten())
                    .all(|(a, b)| a.to_bits() == b.to_bits()));
                // The nodes whose matrix changed are few, and they did change.
                before.compute(mesh, &field, &mut g2);
                let changed = g1.iter().zip(&g2).filter(|(a, b)| a != b).count();
                assert!(changed < mesh.n_nodes() / 2, "{label}: {changed} nodes");
                flipped_nodes += changed;
            }
            println!("{label}: {flipped_nodes} node gradients changed over 6 steps");
            assert!(flipped_nodes > 20, "{label}: {flipped_nodes}");
        }
    }
}
