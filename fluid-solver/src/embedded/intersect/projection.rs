//! Alg. 4.1 (thesis §4.2, projection and flood fill) for closed surfaces whose inside the grid
//! resolves; the surface is wound so that `(b - a) × (c - a)` points out of the body.
//!
//! - Steps 1-3: a node whose box (the node and its neighbours, widened by `ρ`: its reach box of
//!   [`super::near`], read from the node hierarchy) meets a triangle box is near the surface
//!   (the widening, `1e-8` edge lengths, only decides a few more nodes); it is inside when
//!   `(x_i - x'_i) · N ≤ 0`, with `x'_i` its closest surface point (§4.2.1) and `N` the normal
//!   of the feature holding `x'_i`: the face normal inside a face, and on an edge or a vertex
//!   the angle-weighted pseudo-normal (Bærentzen & Aanæs, IEEE TVCG 2005; the sum of the two
//!   face normals on an edge, the corner-angle-weighted sum on a vertex). This replaces the case
//!   analysis of §4.2.2 (b) and (c) by one rule with the same answer on a closed, consistently
//!   wound surface.
//! - Step 4: the other nodes take the side of the nearest decided node by a flood fill over the
//!   adjacency; a part of the mesh with no decided node is outside.
//! - Step 5: an edge whose ends are on different sides is cut where it crosses the triangles near
//!   it (the crossing nearest to node `i`). If rounding put the ends on different sides without
//!   an exact crossing, the cut is the surface point nearest to the edge's midpoint (within one
//!   edge length), projected onto the edge.
//!
//! An edge that crosses a thin body twice has both ends on one side and is not cut (thesis
//! Fig. 4.5, Case II): [`super::collision()`] is the algorithm for such bodies. Phi is not used:
//! a cracked surface is not closed.

use super::closest::Nearest;
use super::crossings::GROUP;
use super::pseudo_normals::PseudoNormals;
use super::{Intersections, Near, NodeBoxes, ReachBoxes, SurfaceAt};
use crate::embedded::adjacency::NodeEdges;
use crate::embedded::predicates::{closest_point, Closest};
use crate::embedded::step::union_sorted;
use crate::embedded::CutEdge;
use crate::mesh::geometry::{add, dot, norm, scale, sub};
use crate::mesh::Mesh;
use rayon::prelude::*;

/// Edges per parallel task of step 5.
const CHUNK: usize = 256;

/// Cut edges and occluded nodes by Alg. 4.1; the inside test is [`projection_inside`]. Tests
/// every node.
pub fn projection(mesh: &Mesh, adjacency: &NodeEdges, at: SurfaceAt<'_>) -> Intersections {
    projection_near(mesh, adjacency, at, &Near::all(mesh))
}

/// [`projection()`] testing only the nodes of `near` against the surface ([`Near::find`]); the
/// flood fill and the comparison of the sides of each edge still run over the whole mesh (the
/// reference of [`KeptInside`], which does not).
pub fn projection_near(
    mesh: &Mesh,
    adjacency: &NodeEdges,
    at: SurfaceAt<'_>,
    near: &Near,
) -> Intersections {
    whole_mesh(mesh, adjacency, ReachBoxes::computed(mesh, adjacency), at, near).3
}

/// Per node: inside the closed surface (Alg. 4.1 steps 1-4).
pub fn projection_inside(mesh: &Mesh, adjacency: &NodeEdges, at: SurfaceAt<'_>) -> Vec<bool> {
    let all = Near::all(mesh);
    let reach = ReachBoxes::computed(mesh, adjacency);
    flood(mesh, adjacency, &all.nodes, sides(&decide(mesh, reach, at, &all, &all.nodes)))
}

/// A near node's side (`true`: inside) and its distance to the surface, if decided.
type Decision = Option<(bool, f64)>;

/// Steps 1-4 over the whole mesh from the near nodes: the decisions of the near nodes (with
/// their distances to the surface), the inside of every node, the edges whose ends differ
/// (ascending) and the cut edges.
fn whole_mesh(
    mesh: &Mesh,
    adjacency: &NodeEdges,
    reach: ReachBoxes<'_>,
    at: SurfaceAt<'_>,
    near: &Near,
) -> (Vec<Decision>, Vec<bool>, Vec<Ends>, Intersections) {
    let decided = decide(mesh, reach, at, near, &near.nodes);
    let inside = flood(mesh, adjacency, &near.nodes, sides(&decided));
    let differ = differing(mesh, &inside);
    let cuts = cut_edges(mesh, adjacency, at, near, &differ);
    (decided, inside, differ, cuts)
}

/// The sides of decisions with distances.
fn sides(decided: &[Decision]) -> Vec<Option<bool>> {
    decided.iter().map(|d| d.map(|d| d.0)).collect()
}

/// Alg. 4.1 from step to step at the cost of the surface (the tracker's form of
/// [`projection_near`], same result): the inside of every node and the edges whose ends differ
/// are kept, and a step redecides only the near nodes (steps 1-3).
///
/// Why the far nodes keep their inside: let `D` be the near nodes decided by steps 1-3 and `U`
/// the others. The flood fill of step 4 gives each node of `U` a value carried from `D` along
/// paths through `U` only, so if (a) every edge with an end in `U` has equal insides at its ends
/// and (b) every connected part of the mesh holds a node of `D`, each connected patch of `U`
/// takes the one value of the `D` nodes around it: the kept value. A node of `U` is not swept
/// (a swept node lies in a swept triangle box, so it is near), so on a closed, resolved surface
/// whose nodes move less than an edge per step (thesis §4.4) its side does not change, and (a)
/// and (b) hold. They are checked every step, cheaply: an edge that differs now differed at the
/// last step (the kept list holds those) or touches a node that changed side, a node of `D`
/// ([`KeptInside::update_near`]); where one fails the step
/// takes the whole-mesh flood fill instead ([`KeptInside::full_fills`] counts them). Step 5 then
/// tests only the differing edges, all of them near.
///
/// A near node is not redecided while the surface cannot have reached it: a node at distance `d`
/// from a closed surface keeps its side while the surface moves less than `d` (every surface point
/// is a convex combination of the nodes, so it moves at most the largest nodal displacement, and
/// along the straight path between the two positions the surface never touches the node, whose
/// winding number therefore stays). The type keeps the distance travelled by the surface (the sum
/// of the largest nodal displacement of each step) and, per node, the travelled distance up to
/// which its last decision holds; only nodes past it, or never decided, run steps 1-3. Only on
/// surfaces whose every part is closed (on others the projection's side is no winding number).
#[derive(Debug, Clone, PartialEq)]
pub struct KeptInside {
    inside: Vec<bool>,
    /// Per node, the travelled distance up to which its side holds (0: redecide); see above.
    holds_until: Vec<f64>,
    /// The surface's positions at the last step and the distance it travelled since the start.
    last_x: Vec<[f64; 3]>,
    travelled: f64,
    /// Edges whose ends differ, ascending.
    differ: Vec<Ends>,
    /// Connected part of the mesh of each node, and their number.
    part: Vec<u32>,
    n_parts: usize,
    /// Steps that fell back on the whole-mesh flood fill.
    pub full_fills: usize,
    /// Near nodes redecided, and near nodes that kept their side, over the steps.
    pub redecided: usize,
    pub kept: usize,
}

impl KeptInside {
    /// The inside at the first step, by the whole-mesh passes, with the cuts; `boxes` are the
    /// mesh's reach boxes.
    pub fn new(
        mesh: &Mesh,
        adjacency: &NodeEdges,
        boxes: &NodeBoxes,
        at: SurfaceAt<'_>,
        near: &Near,
    ) -> (KeptInside, Intersections) {
        let reach = ReachBoxes::Stored(boxes);
        let (decided, inside, differ, cuts) = whole_mesh(mesh, adjacency, reach, at, near);
        let mut holds_until = vec![0.0; mesh.n_nodes()];
        let closed = at.surface.open_part.iter().all(Option::is_none);
        for (&i, d) in near.nodes.iter().zip(&decided) {
            if let (Some((_, clearance)), true) = (d, closed) {
                holds_until[i as usize] = clearance * (1.0 - 1e-9);
            }
        }
        let (part, n_parts) = connected_parts(mesh, adjacency);
        let last_x = at.x.to_vec();
        let kept = KeptInside {
            inside,
            holds_until,
            last_x,
            travelled: 0.0,
            differ,
            part,
            n_parts,
            full_fills: 0,
            redecided: 0,
            kept: 0,
        };
        (kept, cuts)
    }

    /// The cuts of the next step ([`projection_near`] at the surface `at`, whose swept boxes give
    /// `near`).
    pub fn advance(
        &mut self,
        mesh: &Mesh,
        adjacency: &NodeEdges,
        boxes: &NodeBoxes,
        at: SurfaceAt<'_>,
        near: &Near,
    ) -> Intersections {
        let decided = self.decide_moved(mesh, boxes, at, near);
        if !self.update_near(mesh, adjacency, near, &decided) {
            self.full_fills += 1;
            self.inside = flood(mesh, adjacency, &near.nodes, decided);
            self.differ = differing(mesh, &self.inside);
        }
        cut_edges(mesh, adjacency, at, near, &self.differ)
    }

    /// Steps 1-3 at the near nodes the surface may have reached since their last decision (see
    /// the type's docs); the others keep their side.
    fn decide_moved(
        &mut self,
        mesh: &Mesh,
        boxes: &NodeBoxes,
        at: SurfaceAt<'_>,
        near: &Near,
    ) -> Vec<Option<bool>> {
        let closed = at.surface.open_part.iter().all(Option::is_none);
        if !closed || at.x.len() != self.last_x.len() {
            self.holds_until.iter_mut().for_each(|h| *h = 0.0);
        } else {
            let moved = at.x.iter().zip(&self.last_x).map(|(a, b)| norm(sub(*a, *b)));
            // Rounded up: the bound must not fall short.
            self.travelled += moved.fold(0.0, f64::max) * (1.0 + 1e-9);
        }
        self.last_x = at.x.to_vec();
        let travelled = self.travelled;
        let redo: Vec<u32> = near
            .nodes
            .iter()
            .copied()
            .filter(|&i| self.holds_until[i as usize] <= travelled)
            .collect();
        let decided = decide(mesh, ReachBoxes::Stored(boxes), at, near, &redo);
        self.redecided += redo.len();
        self.kept += near.nodes.len() - redo.len();
        for (&i, d) in redo.iter().zip(&decided) {
            let i = i as usize;
            self.holds_until[i] = match (d, closed) {
                (Some((_, clearance)), true) => travelled + clearance * (1.0 - 1e-9),
                _ => 0.0,
            };
        }
        // Back in the order of `near.nodes`: the kept side where not redecided.
        let mut redone = redo.iter().zip(decided).peekable();
        near.nodes
            .iter()
            .map(|&i| match redone.peek() {
                Some((&j, _)) if j == i => redone.next().and_then(|(_, d)| d.map(|d| d.0)),
                _ => Some(self.inside[i as usize]),
            })
            .collect()
    }

    /// Sets the decided near nodes and checks (a) and (b) of the type's docs, updating the
    /// differing edges on success.
    ///
    /// The kept list holds every differing edge of the last step (the whole-mesh passes make it
    /// so, and each step keeps it so), and only decided nodes change side, so an edge differs
    /// now when it did then and still does, or when it touches a node that changed side. Those
    /// are all the differing edges, and (a) holds when each has both ends decided.
    fn update_near(
        &mut self,
        mesh: &Mesh,
        adjacency: &NodeEdges,
        near: &Near,
        decided: &[Option<bool>],
    ) -> bool {
        let mut reached = vec![false; self.n_parts];
        let mut is_decided = vec![false; mesh.n_nodes()];
        let mut changed = Vec::new();
        for (&i, d) in near.nodes.iter().zip(decided) {
            let i = i as usize;
            if let Some(v) = *d {
                if self.inside[i] != v {
                    self.inside[i] = v;
                    changed.push(i);
                }
                reached[self.part[i] as usize] = true;
                is_decided[i] = true;
            }
        }
        if !reached.iter().all(|r| *r) {
            return false;
        }
        let inside = &self.inside;
        let mut new: Vec<Ends> = changed
            .iter()
            .flat_map(|&v| {
                adjacency.neighbours(mesh, v).filter(move |&(u, _)| inside[u] != inside[v])
            })
            .map(|(_, e)| (e, mesh.edges[e as usize]))
            .collect();
        new.sort_unstable();
        let still: Vec<Ends> =
            self.differ.par_iter().copied().filter(|e| differs(inside, e)).collect();
        let differ = union_sorted(&still, &new);
        let both_decided = |(_, ends): &Ends| ends.iter().all(|&i| is_decided[i as usize]);
        if !differ.par_iter().all(both_decided) {
            return false;
        }
        self.differ = differ;
        true
    }

    /// Memory in bytes.
    pub fn memory_bytes(&self) -> usize {
        use std::mem::size_of_val;
        size_of_val(&self.inside[..])
            + size_of_val(&self.holds_until[..])
            + size_of_val(&self.last_x[..])
            + size_of_val(&self.differ[..])
            + size_of_val(&self.part[..])
    }
}

/// An edge with its ends.
type Ends = (u32, [u32; 2]);

/// The edges of `mesh` whose ends differ in `inside`, ascending.
fn differing(mesh: &Mesh, inside: &[bool]) -> Vec<Ends> {
    let ends = mesh.edges.iter().copied().zip(0..);
    ends.map(|(ends, e)| (e, ends)).filter(|e| differs(inside, e)).collect()
}

/// Whether the ends of an edge differ in `inside`.
#[inline]
fn differs(inside: &[bool], (_, [i, j]): &Ends) -> bool {
    inside[*i as usize] != inside[*j as usize]
}

/// The connected parts of the mesh through its edges: the part of each node and their number.
fn connected_parts(mesh: &Mesh, adjacency: &NodeEdges) -> (Vec<u32>, usize) {
    let n = mesh.n_nodes();
    let mut part = vec![u32::MAX; n];
    let mut queue = Vec::new();
    let mut n_parts = 0u32;
    for start in 0..n {
        if part[start] != u32::MAX {
            continue;
        }
        part[start] = n_parts;
        queue.clear();
        queue.push(start);
        while let Some(i) = queue.pop() {
            for (j, _) in adjacency.neighbours(mesh, i) {
                if part[j] == u32::MAX {
                    part[j] = n_parts;
                    queue.push(j);
                }
            }
        }
        n_parts += 1;
    }
    (part, n_parts as usize)
}

/// Step 5 over `differ` (the edges whose ends differ, ascending): each is cut where it crosses
/// the triangles near it, else at the surface point nearest to its midpoint; the occluded nodes
/// among the near ones.
fn cut_edges(
    mesh: &Mesh,
    adjacency: &NodeEdges,
    at: SurfaceAt<'_>,
    near: &Near,
    differ: &[Ends],
) -> Intersections {
    let occluded = at.occluded(mesh, &adjacency.h_min, false, near);
    let cuts: Vec<CutEdge> = differ
        .par_chunks(CHUNK)
        .flat_map_iter(|chunk| {
            let (mut cuts, mut ends) = (Vec::new(), Vec::new());
            // The edges of one node together: their crossings from one pass over its list.
            for run in chunk.chunk_by(|(_, a), (_, b)| a[0] == b[0]) {
                ends.clear();
                ends.extend(run.iter().map(|&(e, [_, j])| (e as usize, j as usize)));
                let i = run[0].1[0] as usize;
                at.for_each_crossing_from::<GROUP>(mesh, near, i, &ends, false, |e, c| {
                    cuts.extend(c.map(|c| c.cut(&at, e)).or_else(|| nearest_to_middle(mesh, at, e)))
                });
            }
            cuts
        })
        .collect();
    Intersections::from_sorted(mesh, cuts, occluded)
}

/// The cut of edge `e`, whose ends differ but which crosses no triangle (by rounding): the
/// surface point nearest to its midpoint (within one edge length), projected onto the edge.
fn nearest_to_middle(mesh: &Mesh, at: SurfaceAt<'_>, e: usize) -> Option<CutEdge> {
    let [i, j] = mesh.edges[e].map(|v| v as usize);
    let (p, q) = (mesh.coords[i], mesh.coords[j]);
    let d = sub(q, p);
    let l2 = dot(d, d);
    let mid = add(p, scale(d, 0.5));
    let (t, cp) = at.nearest_point(mid, l2.sqrt(), false, None, None)?;
    let [a, b, c] = at.corners(t);
    let x = add(add(scale(a, cp.bary[0]), scale(b, cp.bary[1])), scale(c, cp.bary[2]));
    let alpha = (dot(sub(x, p), d) / l2).clamp(0.0, 1.0);
    Some(at.cut(e, t, alpha, cp.bary))
}

/// Steps 1-3 at the near nodes `nodes` (ascending, all in `near`): each decided by its closest
/// point, with its distance to the surface (`None` for a node whose reach box meets no triangle
/// box: left to the flood fill).
fn decide(
    mesh: &Mesh,
    reach: ReachBoxes<'_>,
    at: SurfaceAt<'_>,
    near: &Near,
    nodes: &[u32],
) -> Vec<Decision> {
    if nodes.is_empty() {
        return Vec::new();
    }
    // The closest points first, then the normals of the features they lie on.
    let closest: Vec<Option<(u32, Closest)>> = nodes
        .par_iter()
        .map(|&i| {
            let i = i as usize;
            let p = mesh.coords[i];
            let (lo, hi) = reach.of(i);
            // The candidate whose box is nearest first, then the others that may beat it.
            let mut nearest = Nearest::new(p);
            let mut first: Option<(f64, u32)> = None;
            near.for_each_overlap(at.bvh, i, &p, &lo, &hi, |t| {
                let (a, b) = at.bvh.triangle_box(t as usize);
                let d2 = nearest.box_dist2(&a, &b);
                if first.is_none_or(|f| (d2, t) < f) {
                    first = Some((d2, t));
                }
            });
            let (_, t0) = first?;
            let [a, b, c] = at.corners(t0);
            nearest.offer(t0, closest_point(p, a, b, c));
            near.for_each_overlap(at.bvh, i, &p, &lo, &hi, |t| {
                let (a, b) = at.bvh.triangle_box(t as usize);
                if t != t0 && nearest.may_beat(&a, &b) {
                    let [a, b, c] = at.corners(t);
                    nearest.offer(t, closest_point(p, a, b, c));
                }
            });
            let (mut t, mut cp) = nearest.best?;
            // The nearest triangle lies within that distance; unless the ball of that radius is
            // inside b_i, look for it beyond b_i.
            let r = cp.dist2.sqrt();
            if (0..3).any(|d| p[d] - r < lo[d] || p[d] + r > hi[d]) {
                let radius = r * (1.0 + 1e-12) + f64::MIN_POSITIVE;
                (t, cp) = at.nearest_point(p, radius, false, None, Some((t, cp)))?;
            }
            Some((t, cp))
        })
        .collect();
    let normals = PseudoNormals::of(at, closest.iter().flatten().map(|&(t, cp)| (t, cp.feature)));
    closest
        .par_iter()
        .zip(nodes)
        .map(|(closest, &i)| {
            let (t, cp) = (*closest)?;
            let p = mesh.coords[i as usize];
            let [a, b, c] = at.corners(t);
            let x = add(add(scale(a, cp.bary[0]), scale(b, cp.bary[1])), scale(c, cp.bary[2]));
            Some((dot(sub(p, x), normals.at(t, cp.feature)) <= 0.0, cp.dist2.sqrt()))
        })
        .collect()
}

/// Step 4: the nodes of `candidates` take their `decided` side, the others that of the nearest
/// decided node by a flood fill in node order; a part of the mesh with no decided node is
/// outside.
fn flood(
    mesh: &Mesh,
    adjacency: &NodeEdges,
    candidates: &[u32],
    decided: Vec<Option<bool>>,
) -> Vec<bool> {
    let mut inside: Vec<Option<bool>> = vec![None; mesh.n_nodes()];
    for (&i, d) in candidates.iter().zip(decided) {
        inside[i as usize] = d;
    }
    let mut queue: Vec<usize> = (0..mesh.n_nodes()).filter(|&i| inside[i].is_some()).collect();
    let mut head = 0;
    while head < queue.len() {
        let i = queue[head];
        head += 1;
        for (j, _) in adjacency.neighbours(mesh, i) {
            if inside[j].is_none() {
                inside[j] = inside[i];
                queue.push(j);
            }
        }
    }
    inside.into_iter().map(|s| s.unwrap_or(false)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::embedded::bvh::Bvh;
    use crate::embedded::intersect::pseudo_normals::corner_angle;
    use crate::embedded::intersect::NodeBoxes;
    use crate::embedded::predicates::{unit_normal, Feature};
    use crate::embedded::tests::{box_surface, cube_mesh, sphere};

    /// Steps 1-3 before the search was pruned: every triangle whose box meets the node box, then
    /// every triangle whose box meets the ball's box, each closest point computed.
    fn decide_unpruned(
        mesh: &Mesh,
        adjacency: &NodeEdges,
        at: SurfaceAt<'_>,
        i: usize,
    ) -> Option<bool> {
        let p = mesh.coords[i];
        let nearest = |lo, hi| crate::embedded::intersect::closest::brute_nearest(&at, p, lo, hi);
        let (lo, hi) = adjacency.node_box(mesh, i);
        let (mut t, mut cp) = nearest(lo, hi)?;
        let r = cp.dist2.sqrt();
        if (0..3).any(|d| p[d] - r < lo[d] || p[d] + r > hi[d]) {
            let radius = r * (1.0 + 1e-12) + f64::MIN_POSITIVE;
            (t, cp) = nearest(p.map(|v| v - radius), p.map(|v| v + radius))?;
        }
        let [a, b, c] = at.corners(t);
        let x = add(add(scale(a, cp.bary[0]), scale(b, cp.bary[1])), scale(c, cp.bary[2]));
        Some(dot(sub(p, x), every_normal(at, t, cp.feature)) <= 0.0)
    }

    /// The pseudo-normal of `feature` of triangle `t` from the normals of every feature.
    fn every_normal(at: SurfaceAt<'_>, t: u32, feature: Feature) -> [f64; 3] {
        let tris = &at.surface.triangles;
        let face: Vec<[f64; 3]> = (0..tris.len() as u32)
            .map(|t| {
                let [a, b, c] = at.corners(t);
                unit_normal(a, b, c)
            })
            .collect();
        match feature {
            Feature::Face => face[t as usize],
            Feature::Edge(k) => {
                let run = at.surface.edges.runs().find(|run| run.contains(&(t, k))).unwrap();
                run.iter().fold([0.0; 3], |s, &(t, _)| add(s, face[t as usize]))
            }
            Feature::Vertex(k) => {
                let v = tris[t as usize][k as usize];
                let mut n = [0.0; 3];
                for (t, tri) in tris.iter().enumerate() {
                    for k in (0..3).filter(|&k| tri[k] == v) {
                        n = add(n, scale(face[t], corner_angle(&at.corners(t as u32), k)));
                    }
                }
                n
            }
        }
    }

    /// The normals of a few features, from the triangles around them, are bitwise those made
    /// from the normals of every feature.
    #[test]
    fn normals_of_some_features_are_those_of_all() {
        for s in [sphere([0.5; 3], 0.3, 5), box_surface([0.3, 0.3, 0.4], [0.7, 0.6, 0.8], 2)] {
            let bvh = Bvh::build(&s, 1e-4);
            let at = SurfaceAt::at_end(&s, &bvh).unwrap();
            let n = s.triangles.len() as u32;
            let features = [Feature::Face, Feature::Edge(1), Feature::Vertex(2), Feature::Edge(0)];
            let wanted: Vec<(u32, Feature)> =
                (0..n).step_by(3).zip(features.iter().cycle().copied()).collect();
            let normals = PseudoNormals::of(at, wanted.iter().copied());
            for &(t, feature) in &wanted {
                assert_eq!(normals.at(t, feature), every_normal(at, t, feature), "{t} {feature:?}");
            }
            assert!(wanted.len() > 10);
        }
    }

    /// The pruned steps 1-3 decide every near node as the unpruned search does, over the
    /// recorded triangles and over the whole mesh.
    #[test]
    fn pruned_decisions_equal_the_unpruned_search() {
        let mesh = cube_mesh(10, 0.3, 3);
        let adj = NodeEdges::build(&mesh);
        let boxes = NodeBoxes::build(&mesh, &adj);
        for s in
            [sphere([0.52, 0.47, 0.5], 0.3, 6), box_surface([0.3, 0.3, 0.4], [0.7, 0.6, 0.8], 2)]
        {
            let bvh = Bvh::build(&s, 1e-4);
            let at = SurfaceAt::at_end(&s, &bvh).unwrap();
            let near = Near::find(&mesh, &boxes, &bvh);
            let want: Vec<Option<bool>> =
                near.nodes.iter().map(|&i| decide_unpruned(&mesh, &adj, at, i as usize)).collect();
            assert!(want.iter().filter(|d| d.is_some()).count() > 100);
            let reach = ReachBoxes::computed(&mesh, &adj);
            assert_eq!(sides(&decide(&mesh, reach, at, &near, &near.nodes)), want);
            let stored = ReachBoxes::Stored(&boxes);
            assert_eq!(sides(&decide(&mesh, stored, at, &near, &near.nodes)), want);
            let all = Near::all(&mesh);
            let full = sides(&decide(&mesh, reach, at, &all, &all.nodes));
            for (&i, w) in near.nodes.iter().zip(&want) {
                assert_eq!(full[i as usize], *w, "node {i}");
            }
        }
    }
}
