//! A level set together with an embedded surface (DESIGN §5; thesis §3.3.2 with Ch. 4-5): the
//! interface between two fluids moves with the flow while a structure sits in it, e.g. water and
//! a gas bubble around a shell.
//!
//! Each edge is treated by what meets there: an edge the surface cuts takes Alg. 5.1 on each
//! active end with that end's own EOS, whatever fluids its ends hold (the cut edges outrank the
//! two-material edges in the special-edge lists, [`crate::special_edges`]); an uncut edge between
//! the two fluids takes the exact two-phase flux (thesis Eq. 3.9). `φ` is advected by the same RK2
//! stages as the flow ([`crate::time::rk2::rk2_step_embedded`]) through the edges [`PhiWall`]
//! lets through: uncut, both ends active fluid nodes. So `∇φ`, the upwind fluxes of `φ`, the ghost
//! states of the nodes that change fluid and the reinitialisation's distance never cross the
//! structure, and a sign change of `φ` across a cut edge (water on one side of a shell, air on
//! the other) is no interface of `φ`. The nodes the surface sweeps take their new side's fluid
//! ([`super::side_fluid::side_materials`]) and the mean `φ` of their sources of that fluid
//! ([`super::side_fluid::side_phi`]), so their `φ` and material agree; nodes that are not active
//! keep their `φ`.

use super::tracker::Tracker;
use crate::levelset::LevelSet;
use crate::mesh::Mesh;
use crate::reconstruct::gradient::LsqGradient;
use crate::time::rk2::PhiAdvection;

/// The edges `φ` is taken through in a step and the operator of `∇φ` on them.
#[derive(Debug, Clone)]
pub struct PhiWall {
    /// Per edge: uncut and both ends active.
    pub through: Vec<bool>,
    /// Least-squares gradients of `φ` through those edges only (the level set's mirror planes;
    /// across the material interface, [`crate::levelset::gradient`]).
    pub gradient: LsqGradient,
}

/// Per edge: not cut by the surface of `tracker` and both ends active.
fn through(mesh: &Mesh, tracker: &Tracker) -> Vec<bool> {
    let mut t = vec![true; mesh.n_edges()];
    for c in &tracker.cuts.cuts {
        t[c.edge as usize] = false;
    }
    let active = &tracker.active;
    for (e, &[i, j]) in mesh.edges.iter().enumerate() {
        t[e] &= active[i as usize] && active[j as usize];
    }
    t
}

impl PhiWall {
    /// The edges of `tracker`'s surface now, for the level set `ls`.
    pub fn new(mesh: &Mesh, ls: &LevelSet, tracker: &Tracker) -> PhiWall {
        let through = through(mesh, tracker);
        let gradient = LsqGradient::with_planes(mesh, Some(&through), ls.gradient.planes().clone());
        PhiWall { through, gradient }
    }

    /// The edges after the tracking moved on: the operator is rebuilt only at the ends of the
    /// edges that changed ([`LsqGradient::remask`]), bitwise the one [`PhiWall::new`] builds.
    pub fn update(&mut self, mesh: &Mesh, tracker: &Tracker) {
        let through = through(mesh, tracker);
        let flipped: Vec<u32> = (0..mesh.n_edges())
            .filter(|&e| through[e] != self.through[e])
            .map(|e| e as u32)
            .collect();
        self.gradient.remask(mesh, &flipped, |i| tracker.adjacency.edges_of(i));
        self.through = through;
    }

    /// How `φ` is advected: through these edges with this operator.
    pub fn advection<'a>(&'a self, ls: &'a LevelSet) -> PhiAdvection<'a> {
        PhiAdvection { gradient: &self.gradient, open: &ls.open, through: Some(&self.through) }
    }
}
