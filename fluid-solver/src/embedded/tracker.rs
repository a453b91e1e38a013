//! The embedded boundary through a run (DESIGN §5.1, "Each step"): the surface, its hierarchy,
//! the cut edges and the node sides, advanced one fluid step at a time:
//! surface at `t_b` -> refit -> the mesh nodes and edges the swept boxes reach
//! ([`super::intersect::near`]) -> intersect (Alg. 4.1 or 4.2 at `x_b`) -> swept nodes and new
//! sides (Alg. 4.2 step 5) -> the nodes whose status changed, for the solver to fill
//! ([`super::fill`]). The residual then reads it through [`super::step::Wall`]. Only the flood
//! fill of Alg. 4.1 and a few streaming passes over the node arrays cost what the grid costs.

use super::adjacency::NodeEdges;
use super::bvh::Bvh;
use super::intersect::{collision_near, projection_near, Intersections, Near, NodeBoxes};
use super::intersect::{SurfaceAt, SurfaceAtError};
use super::riemann_fs::WallPressures;
use super::status::{flood_fill, step_ratio, swept_nodes_among, update_sides};
use super::status::{NodeSides, NodeStatus};
use super::status::{SideChange, StatusError};
use super::Surface;
use crate::mesh::Mesh;
use interface_protocol::case::Tracking;

pub use super::status::Seed;

/// Padding of the hierarchy's boxes, relative to the fluid mesh's shortest edge: it covers the
/// gap between the straight sweep the boxes hold and the Hermite path inside a step.
const PAD: f64 = 1e-3;

/// A tracking failure, named.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TrackError {
    #[error("embedded surface: {0}")]
    Surface(#[from] SurfaceAtError),
    #[error("embedded surface, node status: {0}")]
    Status(#[from] StatusError),
    #[error("embedded surface: {got} nodal positions for a surface of {expected} nodes")]
    Positions { expected: usize, got: usize },
}

/// The embedded boundary's state.
#[derive(Debug, Clone)]
pub struct Tracker {
    pub surface: Surface,
    pub bvh: Bvh,
    pub adjacency: NodeEdges,
    /// The hierarchy over the mesh nodes' reach boxes.
    pub node_boxes: NodeBoxes,
    pub tracking: Tracking,
    /// Cut edges at the end of the current step (`surface.t_b`).
    pub cuts: Intersections,
    pub sides: NodeSides,
    /// Per node: an active fluid node.
    pub active: Vec<bool>,
    /// `p*` on both sides of each cut edge, from the last residual (the loads read it).
    pub p_star: Vec<WallPressures>,
}

impl Tracker {
    /// The tracker at `t = surface.t_b` (the surface at rest there): cut edges and the sides of
    /// the flood fill from `seeds` (Alg. 4.2 step 5').
    pub fn new(
        mesh: &Mesh,
        surface: Surface,
        tracking: Tracking,
        seeds: &[Seed],
    ) -> Result<Tracker, TrackError> {
        let adjacency = NodeEdges::build(mesh);
        let h = adjacency.h_min.iter().copied().fold(f64::INFINITY, f64::min);
        let bvh = Bvh::build(&surface, PAD * if h.is_finite() { h } else { 0.0 });
        let node_boxes = NodeBoxes::build(mesh, &adjacency);
        let near = Near::find(mesh, &adjacency, &node_boxes, &bvh);
        let cuts = intersect(mesh, &adjacency, &surface, &bvh, tracking, &near)?;
        let sides = flood_fill(mesh, &adjacency, &cuts, seeds)?;
        let active = sides.status.iter().map(|s| *s == NodeStatus::Active).collect();
        let p_star = vec![[f64::NAN; 2]; cuts.cuts.len()];
        Ok(Tracker { surface, bvh, adjacency, node_boxes, tracking, cuts, sides, active, p_star })
    }

    /// Moves the surface to `(x_b, v_b)` at `t_b` and re-tracks it: returns the nodes whose side
    /// or status changed (ascending), which the solver must fill before the step.
    pub fn advance(
        &mut self,
        mesh: &Mesh,
        t_b: f64,
        x_b: &[[f64; 3]],
        v_b: &[[f64; 3]],
    ) -> Result<Vec<SideChange>, TrackError> {
        let n = self.surface.n_nodes();
        if x_b.len() != n || v_b.len() != n {
            return Err(TrackError::Positions { expected: n, got: x_b.len().min(v_b.len()) });
        }
        self.surface.advance(t_b, x_b, v_b);
        self.bvh.update(&self.surface);
        let near = Near::find(mesh, &self.adjacency, &self.node_boxes, &self.bvh);
        let cuts =
            intersect(mesh, &self.adjacency, &self.surface, &self.bvh, self.tracking, &near)?;
        let swept = swept_nodes_among(mesh, &self.surface, &self.bvh, &near.nodes);
        let (sides, changes) = update_sides(mesh, &self.adjacency, &self.sides, &cuts, &swept);
        self.cuts = cuts;
        self.sides = sides;
        for (a, s) in self.active.iter_mut().zip(&self.sides.status) {
            *a = *s == NodeStatus::Active;
        }
        self.p_star = vec![[f64::NAN; 2]; self.cuts.cuts.len()];
        Ok(changes)
    }

    /// Thesis §4.4: the largest distance a surface node moved over the step, in fluid edge
    /// lengths near it (keep it `<= 1`).
    pub fn step_ratio(&self, mesh: &Mesh) -> f64 {
        step_ratio(mesh, &self.surface, &self.cuts)
    }

    /// Memory in bytes of the per-node and per-cut arrays and the hierarchy over the mesh nodes
    /// (the surface and its tree not counted).
    pub fn memory_bytes(&self) -> usize {
        use std::mem::size_of_val;
        self.adjacency.memory_bytes()
            + self.node_boxes.memory_bytes()
            + size_of_val(&self.cuts.cuts[..])
            + size_of_val(&self.cuts.occluded[..])
            + size_of_val(&self.sides.status[..])
            + size_of_val(&self.sides.side[..])
            + size_of_val(&self.active[..])
            + size_of_val(&self.p_star[..])
    }
}

/// The cut edges of the surface at `x_b` by the case's algorithm, testing the nodes and edges of
/// `near` ([`Near::find`] over `bvh`).
pub fn intersect(
    mesh: &Mesh,
    adjacency: &NodeEdges,
    surface: &Surface,
    bvh: &Bvh,
    tracking: Tracking,
    near: &Near,
) -> Result<Intersections, TrackError> {
    let at = SurfaceAt::at_end(surface, bvh)?;
    Ok(match tracking {
        Tracking::Collision => collision_near(mesh, adjacency, at, near),
        Tracking::Projection => projection_near(mesh, adjacency, at, near),
    })
}
