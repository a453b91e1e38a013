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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bc::BoundaryCondition;
    use crate::embedded::tests::{cube_mesh, plane};
    use crate::embedded::tracker::Seed;
    use crate::eos::Eos;
    use crate::mesh::boxmesh::FACE_NAMES;
    use crate::semidiscretization::{Numerics, Semidiscretization};
    use interface_protocol::case::Tracking;

    /// A plane through the slip walls moving across the mesh for several steps: the edges
    /// updated from step to step are those built anew, none of them cut, and the operator is
    /// bitwise the new one's.
    #[test]
    fn updated_phi_edges_equal_new_ones_bitwise() {
        let walls: Vec<(String, BoundaryCondition)> =
            FACE_NAMES.iter().map(|f| (f.to_string(), BoundaryCondition::SlipWall)).collect();
        let eos = vec![Eos::PerfectGas { gamma: 1.4 }, Eos::PerfectGas { gamma: 1.67 }];
        let mesh = cube_mesh(8, 0.25, 3);
        let material = mesh.coords.iter().map(|x| u8::from(x[0] > 0.5)).collect();
        let semi =
            Semidiscretization::with_materials(mesh, eos, material, Numerics::default(), &walls)
                .unwrap();
        let ls = LevelSet::new(&semi, [0, 1], 5);
        let mesh = &semi.mesh;
        let rest = plane(-0.5, 1.5, -0.5, 1.5, 0.31);
        let seeds = [Seed { point: [0.0; 3], fluid: true }];
        let mut tracker = Tracker::new(mesh, rest.clone(), Tracking::Collision, &seeds).unwrap();
        let mut wall = PhiWall::new(mesh, &ls, &tracker);
        for k in 1..=5 {
            let x: Vec<[f64; 3]> =
                rest.x_b.iter().map(|p| [p[0], p[1], p[2] + 0.04 * k as f64]).collect();
            let v = vec![[0.0, 0.0, 4.0]; x.len()];
            tracker.advance(mesh, 0.01 * k as f64, &x, &v).unwrap();
            wall.update(mesh, &tracker);
            let fresh = PhiWall::new(mesh, &ls, &tracker);
            assert_eq!(wall.through, fresh.through, "step {k}");
            assert!(!tracker.cuts.cuts.is_empty());
            assert!(tracker.cuts.cuts.iter().all(|c| !wall.through[c.edge as usize]));
            assert_eq!(format!("{:?}", wall.gradient), format!("{:?}", fresh.gradient), "step {k}");
        }
    }
}
