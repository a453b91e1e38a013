//! Node status and sides (thesis Alg. 4.2 step 5 and its t = 0 form 5'; §4.4's step limit).
//!
//! A side is a connected component of the fluid mesh reached without crossing a cut edge or
//! entering an occluded node. At t = 0 the components are found by a flood fill and classified by
//! seeds given by the user (a point and whether its region is fluid); unseeded components are
//! inside the structure (inactive). Occluded nodes are inactive and belong to no side (§4.3:
//! "always considered to be inside S"). Between two steps only the nodes a triangle passed over
//! ([`swept_nodes`]) and the occluded ones are redecided: they take the side of a visible
//! neighbour (one joined by an uncut edge) whose side is known (Alg. 4.2 step 5.2);
//! [`update_sides`] returns the nodes whose side or status changed, for the solver to fill.

use super::adjacency::NodeEdges;
use super::bvh::Bvh;
use super::intersect::{Intersections, Near};
use super::predicates::sweep_over_point;
use super::Surface;
use crate::mesh::geometry::{norm, sub};
use crate::mesh::Mesh;
use rayon::prelude::*;

/// Side of a node that has none (occluded, or left undecided by a step: inside the structure).
pub const NO_SIDE: u32 = u32::MAX;

/// What the solver does with a node.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub enum NodeStatus {
    /// A fluid node: it carries a state and its fluxes are computed.
    Active,
    /// Within the occlusion tolerance of the surface: inactive, no side.
    Occluded,
    /// Inside the structure (a region no fluid seed reaches).
    Inactive,
}

/// A user-given point classifying the region around it at t = 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Seed {
    pub point: [f64; 3],
    /// Whether the region holding the point is fluid (else it is inside a body).
    pub fluid: bool,
}

/// Status and side of every node.
#[derive(Debug, Clone, PartialEq)]
pub struct NodeSides {
    pub status: Vec<NodeStatus>,
    /// Side id per node ([`NO_SIDE`] for occluded and undecided nodes).
    pub side: Vec<u32>,
    /// Per side id: whether it is fluid.
    pub side_fluid: Vec<bool>,
    /// The nodes whose side is [`NO_SIDE`], ascending (a step redecides them).
    pub unsided: Vec<u32>,
}

/// A node whose side or status changed in a step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SideChange {
    pub node: u32,
    pub old_side: u32,
    pub new_side: u32,
    pub old_status: NodeStatus,
    pub new_status: NodeStatus,
}

/// Seeds that cannot classify the mesh, named.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StatusError {
    #[error("seed {seed} at {point:?}: its nearest mesh node {node} is occluded by the surface; move the seed at least one cell away from it")]
    OccludedSeed { seed: usize, point: [f64; 3], node: usize },
    #[error("seeds {first} (fluid: {first_fluid}) and {second} (fluid: {second_fluid}) lie in one connected region of the fluid mesh: the surface does not separate them (a leak, or a misplaced seed)")]
    Conflict { first: usize, first_fluid: bool, second: usize, second_fluid: bool },
    #[error("seed {seed} has a non-finite point {point:?}")]
    BadSeed { seed: usize, point: [f64; 3] },
    #[error("no seed given: at least one point in the fluid is needed")]
    NoSeed,
}

/// Sides and statuses at t = 0 (Alg. 4.2 step 5'): components of the mesh through uncut edges,
/// classified by the seeds (each seed goes to its nearest mesh node).
pub fn flood_fill(
    mesh: &Mesh,
    adjacency: &NodeEdges,
    cuts: &Intersections,
    seeds: &[Seed],
) -> Result<NodeSides, StatusError> {
    if seeds.is_empty() {
        return Err(StatusError::NoSeed);
    }
    let n = mesh.n_nodes();
    debug_assert_eq!(cuts.occluded.len(), n, "intersections of another mesh");
    let cut = cuts.cut_mask(mesh.n_edges());
    let mut side = vec![NO_SIDE; n];
    let mut queue = Vec::new();
    let mut n_sides = 0u32;
    for start in 0..n {
        if side[start] != NO_SIDE || cuts.occluded[start] {
            continue;
        }
        side[start] = n_sides;
        queue.clear();
        queue.push(start);
        let mut head = 0;
        while head < queue.len() {
            let i = queue[head];
            head += 1;
            for (j, e) in adjacency.neighbours(mesh, i) {
                if !cut[e as usize] && !cuts.occluded[j] && side[j] == NO_SIDE {
                    side[j] = n_sides;
                    queue.push(j);
                }
            }
        }
        n_sides += 1;
    }
    let mut classified: Vec<Option<(usize, bool)>> = vec![None; n_sides as usize];
    for (k, s) in seeds.iter().enumerate() {
        if !s.point.iter().all(|v| v.is_finite()) {
            return Err(StatusError::BadSeed { seed: k, point: s.point });
        }
        let node = (0..n)
            .min_by(|&a, &b| {
                let d = |i: usize| norm(sub(mesh.coords[i], s.point));
                d(a).total_cmp(&d(b))
            })
            .ok_or(StatusError::NoSeed)?;
        if cuts.occluded[node] {
            return Err(StatusError::OccludedSeed { seed: k, point: s.point, node });
        }
        match classified[side[node] as usize] {
            Some((first, fluid)) if fluid != s.fluid => {
                return Err(StatusError::Conflict {
                    first,
                    first_fluid: fluid,
                    second: k,
                    second_fluid: s.fluid,
                })
            }
            Some(_) => {}
            None => classified[side[node] as usize] = Some((k, s.fluid)),
        }
    }
    let side_fluid: Vec<bool> = classified.iter().map(|c| c.is_some_and(|(_, f)| f)).collect();
    let status = statuses(&side, &side_fluid, &cuts.occluded);
    let unsided = (0..n as u32).filter(|&i| side[i as usize] == NO_SIDE).collect();
    Ok(NodeSides { status, side, side_fluid, unsided })
}

/// The nodes a triangle passed over between `x_a` and `x_b` (Alg. 4.2 step 5.1, point against a
/// linearly moving triangle), ascending. The hierarchy must be fitted to the step ([`Bvh::refit`]).
pub fn swept_nodes(mesh: &Mesh, surface: &Surface, bvh: &Bvh) -> Vec<u32> {
    let all: Vec<u32> = (0..mesh.n_nodes() as u32).collect();
    swept_nodes_among(mesh, surface, bvh, &all)
}

/// [`swept_nodes`] among `candidates` (ascending; for example [`Near::nodes`], which holds every
/// node inside a triangle box).
pub fn swept_nodes_among(
    mesh: &Mesh,
    surface: &Surface,
    bvh: &Bvh,
    candidates: &[u32],
) -> Vec<u32> {
    swept_in(
        mesh,
        surface,
        bvh,
        candidates,
        |_| (),
        |p, _, visit| bvh.for_each_overlap(p, p, visit),
    )
}

/// [`swept_nodes`] among the nodes of `near` ([`Near::find`] over `bvh`), each tested against
/// the triangles recorded for it (a node is inside its reach box).
pub fn swept_nodes_near(mesh: &Mesh, surface: &Surface, bvh: &Bvh, near: &Near) -> Vec<u32> {
    swept_in(
        mesh,
        surface,
        bvh,
        &near.nodes,
        |k| near.prefetch_ahead(mesh, &near.nodes, k),
        |p, i, visit| near.for_each_overlap(bvh, i, p, p, p, visit),
    )
}

/// The nodes of `candidates` a triangle passed over, the triangles whose box holds node `i` at
/// `p` given by `query(p, i, visit)`; `ahead(k)` is called before the `k`-th candidate (prefetch
/// hints).
fn swept_in<A, Q>(
    mesh: &Mesh,
    surface: &Surface,
    bvh: &Bvh,
    candidates: &[u32],
    ahead: A,
    query: Q,
) -> Vec<u32>
where
    A: Fn(usize) + Sync,
    Q: Fn(&[f64; 3], usize, &mut dyn FnMut(u32)) + Sync,
{
    debug_assert_eq!(bvh.len(), surface.triangles.len(), "hierarchy of another surface");
    candidates
        .par_iter()
        .enumerate()
        .filter_map(|(k, &i)| {
            ahead(k);
            let p = mesh.coords[i as usize];
            let mut swept = false;
            query(&p, i as usize, &mut |t| {
                if !swept {
                    let tri = surface.triangles[t as usize];
                    let from = tri.map(|n| surface.x_a[n as usize]);
                    let to = tri.map(|n| surface.x_b[n as usize]);
                    swept = sweep_over_point(p, from, to).is_some();
                }
            });
            swept.then_some(i)
        })
        .collect()
}

/// Sides after a step (Alg. 4.2 step 5.2): the swept nodes and the nodes occluded before or now
/// are redecided from their visible neighbours of known side, through the new cut edges, by a
/// flood fill in node order; those that reach none are inactive. Returns the new sides and the
/// nodes whose side or status changed (ascending). Looks at every node: the reference of
/// [`update_sides_among`], which the tracker runs.
pub fn update_sides(
    mesh: &Mesh,
    adjacency: &NodeEdges,
    old: &NodeSides,
    cuts: &Intersections,
    swept: &[u32],
) -> (NodeSides, Vec<SideChange>) {
    let all: Vec<u32> = (0..mesh.n_nodes() as u32).collect();
    let mut sides = old.clone();
    let changes = update_sides_among(mesh, adjacency, &mut sides, cuts, swept, &all);
    (sides, changes)
}

/// The nodes [`update_sides_among`] must look at: the swept ones, those without a side before
/// (occluded or undecided: [`NodeSides::unsided`]) and those of `near` occluded now (every
/// occluded node is near), ascending.
pub fn redecided(sides: &NodeSides, cuts: &Intersections, swept: &[u32], near: &[u32]) -> Vec<u32> {
    let occluded = near.iter().copied().filter(|&i| cuts.occluded[i as usize]);
    let mut nodes: Vec<u32> = swept.iter().chain(&sides.unsided).copied().chain(occluded).collect();
    nodes.sort_unstable();
    nodes.dedup();
    nodes
}

/// [`update_sides`] in place, looking only at `candidates` (ascending; at least
/// [`redecided`]). Any other node has a side, is not occluded before or now and is not swept, so
/// neither its side nor its status can change and it is not in the fill; the fill starts from
/// the known neighbours of the undecided nodes and walks only what it reaches. Its cost follows
/// the surface.
pub fn update_sides_among(
    mesh: &Mesh,
    adjacency: &NodeEdges,
    sides: &mut NodeSides,
    cuts: &Intersections,
    swept: &[u32],
    candidates: &[u32],
) -> Vec<SideChange> {
    let n = mesh.n_nodes();
    debug_assert!(sides.side.len() == n && cuts.occluded.len() == n, "sides of another mesh");
    let before: Vec<(u32, NodeStatus)> =
        candidates.iter().map(|&i| (sides.side[i as usize], sides.status[i as usize])).collect();
    let uncut = |e: u32| cuts.find(e).is_none();
    let side = &mut sides.side;
    for &i in swept {
        side[i as usize] = NO_SIDE;
    }
    for &i in candidates {
        if cuts.occluded[i as usize] {
            side[i as usize] = NO_SIDE;
        }
    }
    // Unknown: no side now and not occluded (a candidate; the fill only assigns such nodes).
    let unknown = |side: &[u32], i: usize| side[i] == NO_SIDE && !cuts.occluded[i];
    // The known nodes next to an unknown one through an uncut edge, in node order.
    let mut queue: Vec<usize> = Vec::new();
    for &u in candidates.iter().filter(|&&u| unknown(&side[..], u as usize)) {
        for (j, e) in adjacency.neighbours(mesh, u as usize) {
            if side[j] != NO_SIDE && uncut(e) {
                queue.push(j);
            }
        }
    }
    queue.sort_unstable();
    queue.dedup();
    let mut head = 0;
    while head < queue.len() {
        let i = queue[head];
        head += 1;
        for (j, e) in adjacency.neighbours(mesh, i) {
            if unknown(&side[..], j) && uncut(e) {
                side[j] = side[i];
                queue.push(j);
            }
        }
    }
    let mut changes = Vec::new();
    for (&i, &(old_side, old_status)) in candidates.iter().zip(&before) {
        let iu = i as usize;
        let status = status_of(sides.side[iu], &sides.side_fluid, cuts.occluded[iu]);
        sides.status[iu] = status;
        if sides.side[iu] != old_side || status != old_status {
            changes.push(SideChange {
                node: i,
                old_side,
                new_side: sides.side[iu],
                old_status,
                new_status: status,
            });
        }
    }
    sides.unsided =
        candidates.iter().copied().filter(|&i| sides.side[i as usize] == NO_SIDE).collect();
    changes
}

fn statuses(side: &[u32], side_fluid: &[bool], occluded: &[bool]) -> Vec<NodeStatus> {
    (0..side.len()).map(|i| status_of(side[i], side_fluid, occluded[i])).collect()
}

#[inline]
fn status_of(side: u32, side_fluid: &[bool], occluded: bool) -> NodeStatus {
    if occluded {
        NodeStatus::Occluded
    } else if side != NO_SIDE && side_fluid[side as usize] {
        NodeStatus::Active
    } else {
        NodeStatus::Inactive
    }
}

/// The step limit of thesis §4.4: the largest ratio, over the surface nodes, of the distance the
/// node moves from `x_a` to `x_b` to the shortest fluid edge near it. "Near" is the shortest
/// edge cut by a triangle touching the node; a node whose triangles cut no edge takes the
/// shortest cut edge of all (the whole mesh's shortest edge if nothing is cut). A ratio `<= 1`
/// keeps every surface node within one edge length per step.
pub fn step_ratio(mesh: &Mesh, surface: &Surface, cuts: &Intersections) -> f64 {
    let length = |e: u32| {
        let [i, j] = mesh.edges[e as usize];
        norm(sub(mesh.coords[j as usize], mesh.coords[i as usize]))
    };
    let mut h = vec![f64::INFINITY; surface.n_nodes()];
    let mut h_all = f64::INFINITY;
    for c in &cuts.cuts {
        let l = length(c.edge);
        h_all = h_all.min(l);
        for &v in &surface.triangles[c.triangle as usize] {
            h[v as usize] = h[v as usize].min(l);
        }
    }
    if !h_all.is_finite() {
        h_all = (0..mesh.n_edges() as u32).map(length).fold(f64::INFINITY, f64::min);
    }
    (0..surface.n_nodes())
        .map(|v| {
            let hv = if h[v].is_finite() { h[v] } else { h_all };
            norm(sub(surface.x_b[v], surface.x_a[v])) / hv
        })
        .fold(0.0, f64::max)
}
