//! A [`Model`] made of BT4 shells alone: the explicit driver of `structure-solver bench` and of
//! structure-only explicit runs. Boundary conditions: fixed dofs and dofs moving at a
//! prescribed constant velocity; loads: constant nodal forces plus whatever an integrator adds.
//!
//! BT4 is an explicit element: `tangent` is empty and `has_tangent` false, so static and
//! implicit solvers refuse this model (use MITC4/DKT shells in `assembly::FeModel`, which also
//! holds BT4 shells as `Part::Bt4` next to other parts); the critical step comes from the
//! elements and from the matrix-free power iteration of
//! [`time::critical_dt`](crate::time::critical_dt).

use faer::sparse::Triplet;

use crate::elements::bt4::Bt4;
use crate::model::Model;

/// BT4 shells with their nodes.
#[derive(Debug, Clone)]
pub struct ShellModel {
    /// Reference positions.
    pub x0: Vec<[f64; 3]>,
    pub bt4: Bt4,
    /// Constant nodal loads, 6 per node.
    pub loads: Vec<f64>,
    /// Prescribed velocity of constrained dofs (0 = fixed), 6 per node.
    pub prescribed_velocity: Vec<f64>,
    x: Vec<[f64; 3]>,
    x_committed: Vec<[f64; 3]>,
    /// Increment since the last commit (translations and rotation increments).
    pending: Vec<f64>,
    mass: Vec<f64>,
    constrained: Vec<bool>,
}

impl ShellModel {
    /// A model with every dof free and no load.
    pub fn new(x0: Vec<[f64; 3]>, bt4: Bt4) -> Self {
        let n = x0.len();
        let mut mass = vec![0.0; 6 * n];
        bt4.lumped_mass(&x0, &mut mass);
        ShellModel {
            x: x0.clone(),
            x_committed: x0.clone(),
            x0,
            bt4,
            loads: vec![0.0; 6 * n],
            prescribed_velocity: vec![0.0; 6 * n],
            pending: vec![0.0; 6 * n],
            mass,
            constrained: vec![false; 6 * n],
        }
    }

    /// Fixes (or prescribes the velocity of, with `prescribed_velocity`) a dof.
    pub fn constrain(&mut self, dof: usize) {
        self.constrained[dof] = true;
    }

    /// Current positions.
    pub fn positions(&self) -> &[[f64; 3]] {
        &self.x
    }

    /// Committed positions (checkpoints).
    pub fn committed_positions(&self) -> &[[f64; 3]] {
        &self.x_committed
    }

    /// Restores positions (checkpoints); the element state is restored through `bt4`.
    pub fn set_positions(&mut self, x: Vec<[f64; 3]>) {
        self.x_committed.clone_from(&x);
        self.x = x;
        self.pending.fill(0.0);
    }
}

impl Model for ShellModel {
    fn n_nodes(&self) -> usize {
        self.x0.len()
    }

    fn lumped_mass(&self) -> &[f64] {
        &self.mass
    }

    fn constrained(&self) -> &[bool] {
        &self.constrained
    }

    fn prescribed(&self, t: f64, out: &mut [f64]) {
        for ((o, v), &c) in out.iter_mut().zip(&self.prescribed_velocity).zip(&self.constrained) {
            if c {
                *o = v * t;
            }
        }
    }

    fn apply_increment(&mut self, du: &[f64]) {
        for (i, x) in self.x.iter_mut().enumerate() {
            for k in 0..3 {
                x[k] += du[6 * i + k];
            }
        }
        for (p, d) in self.pending.iter_mut().zip(du) {
            *p += d;
        }
    }

    fn internal_force(&mut self, f: &mut [f64]) {
        f.fill(0.0);
        self.bt4.internal_force(&self.x, &self.pending, f);
    }

    fn external_force(&mut self, _t: f64, f: &mut [f64]) {
        f.copy_from_slice(&self.loads);
    }

    fn tangent(&mut self, _t: f64, _out: &mut Vec<Triplet<usize, usize, f64>>) {}

    fn has_tangent(&self) -> bool {
        false
    }

    fn commit(&mut self) {
        self.bt4.commit();
        self.x_committed.clone_from(&self.x);
        self.pending.fill(0.0);
    }

    fn revert(&mut self) {
        self.x.clone_from(&self.x_committed);
        self.pending.fill(0.0);
    }

    fn stable_dt(&self) -> f64 {
        self.bt4.stable_dt(&self.x)
    }

    fn displacement(&self, out: &mut [[f64; 3]]) {
        for ((o, x), x0) in out.iter_mut().zip(&self.x).zip(&self.x0) {
            *o = [x[0] - x0[0], x[1] - x0[1], x[2] - x0[2]];
        }
    }
}
