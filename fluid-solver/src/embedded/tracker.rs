//! The embedded boundary through a run (DESIGN §5.1, "Each step"): the surface, its hierarchy,
//! the cut edges and the node sides, advanced one fluid step at a time:
//! surface at `t_b` -> refit -> the mesh nodes and edges the swept boxes reach
//! ([`super::intersect::near`]) -> intersect (Alg. 4.1 or 4.2 at `x_b`) -> swept nodes and new
//! sides (Alg. 4.2 step 5) -> the nodes whose status changed, for the solver to fill
//! ([`super::fill`]). The residual then reads it through [`super::step::Wall`]. Each pass looks
//! only at the near part: Alg. 4.1 keeps its inside ([`KeptInside`]) and the sides are redecided
//! only at the swept, occluded and unsided nodes ([`update_sides_among`]).

use super::adjacency::{ascending_once, NodeEdges};
use super::bvh::Bvh;
use super::intersect::{
    collision_near, projection_near, Intersections, KeptInside, Near, NearSkin, NodeBoxes,
};
use super::intersect::{SurfaceAt, SurfaceAtError};
use super::riemann_fs::WallPressures;
use super::status::{flood_fill, redecided, step_ratio, swept_nodes_near, update_sides_among};
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
    /// The node-triangle pairs kept over several steps ([`NearSkin`]; not run state).
    pub near_skin: NearSkin,
    pub tracking: Tracking,
    /// Cut edges at the end of the current step (`surface.t_b`).
    pub cuts: Intersections,
    pub sides: NodeSides,
    /// Per node: an active fluid node.
    pub active: Vec<bool>,
    /// `p*` on both sides of each cut edge, from the last residual (the loads read it).
    pub p_star: Vec<WallPressures>,
    /// Alg. 4.1's inside of every node, kept from step to step (`None` for Alg. 4.2).
    pub kept_inside: Option<KeptInside>,
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
        let near = Near::find(mesh, &node_boxes, &bvh);
        let (cuts, kept_inside) = match tracking {
            Tracking::Collision => {
                (intersect(mesh, &adjacency, &surface, &bvh, tracking, &near)?, None)
            }
            Tracking::Projection => {
                let at = SurfaceAt::at_end(&surface, &bvh)?;
                let (kept, cuts) = KeptInside::new(mesh, &adjacency, &node_boxes, at, &near);
                (cuts, Some(kept))
            }
        };
        let sides = flood_fill(mesh, &adjacency, &cuts, seeds)?;
        let active = sides.status.iter().map(|s| *s == NodeStatus::Active).collect();
        let p_star = vec![[f64::NAN; 2]; cuts.cuts.len()];
        Ok(Tracker {
            near_skin: NearSkin::new(&adjacency),
            surface,
            bvh,
            adjacency,
            node_boxes,
            tracking,
            cuts,
            sides,
            active,
            p_star,
            kept_inside,
        })
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
        let near = self.near(mesh);
        let cuts = self.cuts_near(mesh, &near)?;
        let swept = swept_nodes_near(mesh, &self.surface, &self.bvh, &near);
        Ok(self.move_sides(mesh, cuts, &swept, &near))
    }

    /// The part of the mesh the refitted hierarchy reaches ([`Near::find`], through the kept
    /// pairs of [`NearSkin`]).
    pub fn near(&mut self, mesh: &Mesh) -> Near {
        self.near_skin.find(mesh, &self.node_boxes, &self.bvh, &self.surface)
    }

    /// The cut edges of the surface at `x_b` (Alg. 4.1 or 4.2), testing the nodes and edges of
    /// `near` ([`Near::find`] over the refitted hierarchy); Alg. 4.1 updates its kept inside.
    pub fn cuts_near(&mut self, mesh: &Mesh, near: &Near) -> Result<Intersections, TrackError> {
        let at = SurfaceAt::at_end(&self.surface, &self.bvh)?;
        Ok(match &mut self.kept_inside {
            Some(kept) => kept.advance(mesh, &self.adjacency, &self.node_boxes, at, near),
            None => collision_near(mesh, &self.adjacency, at, near),
        })
    }

    /// Takes the step's `cuts` and redecides the sides of the `swept` nodes and the occluded
    /// ones (Alg. 4.2 step 5) among `near`, updating the active flags where they changed: the
    /// nodes whose side or status changed (ascending).
    pub fn move_sides(
        &mut self,
        mesh: &Mesh,
        cuts: Intersections,
        swept: &[u32],
        near: &Near,
    ) -> Vec<SideChange> {
        let candidates = redecided(&self.sides, &cuts, swept, &near.nodes);
        let changes =
            update_sides_among(mesh, &self.adjacency, &mut self.sides, &cuts, swept, &candidates);
        self.cuts = cuts;
        for c in &changes {
            self.active[c.node as usize] = c.new_status == NodeStatus::Active;
        }
        self.p_star = vec![[f64::NAN; 2]; self.cuts.cuts.len()];
        changes
    }

    /// The active end nodes of the cut edges, ascending, each once (the nodes whose states and
    /// gradients the wall pressures read).
    pub fn cut_edge_ends(&self, mesh: &Mesh) -> Vec<u32> {
        let ends = self.cuts.cuts.iter().flat_map(|c| mesh.edges[c.edge as usize]);
        ascending_once(mesh.n_nodes(), ends.filter(|&i| self.active[i as usize]))
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
            + self.near_skin.memory_bytes()
            + size_of_val(&self.cuts.cuts[..])
            + size_of_val(&self.cuts.occluded[..])
            + size_of_val(&self.sides.status[..])
            + size_of_val(&self.sides.side[..])
            + size_of_val(&self.active[..])
            + size_of_val(&self.p_star[..])
            + size_of_val(&self.sides.unsided[..])
            + self.kept_inside.as_ref().map_or(0, KeptInside::memory_bytes)
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
