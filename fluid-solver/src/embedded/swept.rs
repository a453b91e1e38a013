//! The nodes a step's surface motion changes (thesis §4.4, DESIGN §5 "swept nodes") and where
//! each takes what it needs from: a node that changes side or becomes active draws its fluid
//! ([`super::side_fluid`]), level set and state ([`super::fill`]) from its *sources*, the
//! neighbours through an edge the surface does not cut now, on the same side, active before and
//! after the step and not changed in it. Built once per step and shared by all three.

use super::adjacency::NodeEdges;
use super::intersect::Intersections;
use super::status::{NodeSides, NodeStatus, SideChange};
use super::tracker::Tracker;
use crate::mesh::Mesh;

/// A step's side changes with the mesh, the new sides and cut edges and the old activity.
pub struct Swept<'a> {
    pub mesh: &'a Mesh,
    adjacency: &'a NodeEdges,
    changes: &'a [SideChange],
    pub sides: &'a NodeSides,
    was_active: &'a [bool],
    cuts: &'a Intersections,
    changed: std::collections::HashSet<u32>,
}

impl<'a> Swept<'a> {
    /// `changes` of the step `tracker` just took (its new sides and cut edges, the cuts searched
    /// edge by edge only around the few changed nodes), and each node's status before the step,
    /// `was_active`.
    pub fn new(
        mesh: &'a Mesh,
        tracker: &'a Tracker,
        changes: &'a [SideChange],
        was_active: &'a [bool],
    ) -> Swept<'a> {
        let changed = changes.iter().map(|c| c.node).collect();
        let (adjacency, sides, cuts) = (&tracker.adjacency, &tracker.sides, &tracker.cuts);
        Swept { mesh, adjacency, changes, sides, was_active, cuts, changed }
    }

    /// The changed nodes that are active now, in the order of the changes.
    pub fn nodes(&self) -> impl Iterator<Item = usize> + '_ {
        self.changes.iter().filter(|c| c.new_status == NodeStatus::Active).map(|c| c.node as usize)
    }

    /// The neighbours of `i` through edges the surface does not cut now, on `i`'s side, in the
    /// adjacency's order.
    pub fn same_side(&self, i: usize) -> impl Iterator<Item = usize> + '_ {
        let side = self.sides.side[i];
        self.adjacency.neighbours(self.mesh, i).filter_map(move |(j, e)| {
            (self.sides.side[j] == side && self.cuts.find(e).is_none()).then_some(j)
        })
    }

    /// Whether `j` keeps its state through the step: active before and after, not changed.
    pub fn keeps(&self, j: usize) -> bool {
        self.was_active[j]
            && !self.changed.contains(&(j as u32))
            && self.sides.status[j] == NodeStatus::Active
    }

    /// The sources of node `i` (module docs).
    pub fn sources(&self, i: usize) -> impl Iterator<Item = usize> + '_ {
        self.same_side(i).filter(move |&j| self.keeps(j))
    }
}
