//! Rigid bodies and links on the model (`rigid`): slaves follow a master node, forces and
//! tangent are reduced to the master (`Tᵀ f`, `Tᵀ K T` plus the geometric term of the rotating
//! offsets), and a master at a point or at the mass centre is a node appended to the mesh.

use faer::sparse::Triplet;
use nalgebra::{Matrix3, Vector3};

use super::FeModel;
use crate::linsolve::{Expansion, Tangent, MAX_EXPANSION};
use crate::model::Model;
use crate::rigid::{ExtraMass, RigidBody, RigidError, RigidReference};

impl FeModel {
    /// Makes `nodes` a rigid body on the master `reference` with the mass and inertia of its
    /// nodes plus `extra`; returns the master node. A two-node set is a rigid link. Each node
    /// belongs to at most one body; slaves may carry no fixed or prescribed dof (define those
    /// before the body: later ones on slaves have no effect), the master may. `Point` and
    /// `MassCentre` append a node (index `n_nodes()` before the call) with six free dofs and no
    /// element; `Node` may name a node outside the set, which then joins the body. Loads on
    /// slaves (point loads, pressure, gravity, the coupling's nodal array) reach the master as
    /// a force and a moment about it.
    pub fn rigid_body(
        &mut self,
        nodes: &[usize],
        reference: RigidReference,
        extra: ExtraMass,
    ) -> Result<usize, RigidError> {
        let nn = self.x0.len();
        let mut set = nodes.to_vec();
        set.sort_unstable();
        set.dedup();
        if set.is_empty() {
            return Err(RigidError::Empty);
        }
        let mut check = set.clone();
        if let RigidReference::Node(m) = reference {
            check.push(m);
        }
        for &n in &check {
            if n >= nn {
                return Err(RigidError::NodeRange { node: n, n: nn });
            }
            if self.skew_of[n].is_some() {
                return Err(RigidError::SymmetryPlane { node: n });
            }
            if let Some(body) = self.body_of[n] {
                return Err(RigidError::TwoBodies { node: n, body });
            }
        }
        let (master, point) = match reference {
            RigidReference::Node(m) => (m, None),
            RigidReference::Point(p) => (nn, Some(Vector3::from(p))),
            RigidReference::MassCentre => {
                let c = RigidBody::centre_of(&set, &self.trial.x, &extra, &self.node_mass);
                (nn, Some(c.ok_or(RigidError::NoMass)?))
            }
        };
        let slaves: Vec<usize> = set.into_iter().filter(|&n| n != master).collect();
        for &s in &slaves {
            if let Some(dof) = (0..6).find(|&c| self.user_fixed[6 * s + c]) {
                return Err(RigidError::ConstrainedSlave { node: s, dof });
            }
        }
        let (mut x, mut r, mut node_mass) =
            (self.trial.x.clone(), self.trial.r.clone(), self.node_mass.clone());
        if let Some(p) = point {
            x.push(p);
            r.push(Matrix3::identity());
            node_mass.extend([0.0; 6]);
        }
        let body = RigidBody::new(master, slaves, &x, &r, &extra, &node_mass)?;
        if let Some(p) = point {
            self.add_node(self.topology.nodes.next_id(), p);
        }
        let id = self.rigid.len();
        self.body_of[master] = Some(id);
        for c in 0..6 {
            // the body gives the master inertia and, through the slaves, stiffness
            self.constrained[6 * master + c] = self.user_fixed[6 * master + c];
        }
        for &s in &body.slaves {
            self.body_of[s] = Some(id);
            self.slave[s] = true;
            self.constrained[6 * s..6 * s + 6].fill(true);
        }
        self.rigid.push(body);
        self.reduce_mass();
        self.fint_valid = false;
        Ok(master)
    }

    /// Appends node `id` (a free id) at `p` (no element, six free dofs, no mass of its own).
    pub(super) fn add_node(&mut self, id: u64, p: Vector3<f64>) {
        self.topology.nodes.push(id).expect("a free node id");
        self.x0.push(p);
        for s in [&mut self.trial, &mut self.committed] {
            s.x.push(p);
            s.r.push(Matrix3::identity());
            s.spin_sum.push(Vector3::zeros());
        }
        self.mass.extend([0.0; 6]);
        self.node_mass.extend([0.0; 6]);
        self.constrained.extend([false; 6]);
        self.user_fixed.extend([false; 6]);
        self.external.extend([0.0; 6]);
        self.body_of.push(None);
        self.skew_of.push(None);
        self.slave.push(false);
        if let Some(b) = &mut self.explicit {
            b.add_node(&p);
        }
    }

    /// Moves every slave with its master (positions, rotations and accumulated spins).
    pub(super) fn place_slaves(&mut self, du: &[f64]) {
        let s = &mut self.trial;
        for b in &self.rigid {
            let (xm, rm) = (s.x[b.master], s.r[b.master]);
            let w = Vector3::new(du[6 * b.master + 3], du[6 * b.master + 4], du[6 * b.master + 5]);
            for (k, &n) in b.slaves.iter().enumerate() {
                (s.x[n], s.r[n]) = b.slave(k, &xm, &rm);
                s.spin_sum[n] += w;
            }
        }
    }

    /// `f ← Tᵀ f`: slave forces and moments move to their master (moment of the force about
    /// the master added); slave entries become zero.
    pub(super) fn reduce_forces(&self, f: &mut [f64]) {
        let x = &self.trial.x;
        for b in &self.rigid {
            let m = b.master;
            for &s in &b.slaves {
                let force = Vector3::new(f[6 * s], f[6 * s + 1], f[6 * s + 2]);
                let moment = (x[s] - x[m]).cross(&force);
                for c in 0..3 {
                    f[6 * m + c] += f[6 * s + c];
                    f[6 * m + 3 + c] += f[6 * s + 3 + c] + moment[c];
                }
                f[6 * s..6 * s + 6].fill(0.0);
            }
        }
    }

    /// `K ← Tᵀ K T` on triplets, plus the geometric term of the rotating offsets
    /// `Σ_s [g_s]× [r_s]×` on the master's rotations (`g_s` the slave's internal minus external
    /// force, `r_s = x_s - x_m`).
    pub(super) fn reduce_tangent(&mut self, t: f64, k: &mut Tangent) {
        use crate::elements::rotation::spin;
        if !self.fint_valid {
            let mut f = vec![0.0; self.n_dof()];
            self.internal_force(&mut f);
        }
        let mut fext = vec![0.0; self.n_dof()];
        self.external_unreduced(t, &mut fext);
        let x = &self.trial.x;
        // per node: (master, r_s) of slaves
        let mut link: Vec<Option<(usize, Vector3<f64>)>> = vec![None; x.len()];
        for b in &self.rigid {
            for &s in &b.slaves {
                link[s] = Some((b.master, x[s] - x[b.master]));
            }
        }
        // column d of T: (reduced dof, coefficient) pairs
        let expand = |d: usize| -> Expansion {
            let (n, c) = (d / 6, d % 6);
            match link[n] {
                None => ([(d, 1.0); MAX_EXPANSION], 1),
                Some((m, _)) if c >= 3 => ([(6 * m + c, 1.0); MAX_EXPANSION], 1),
                Some((m, r)) => {
                    // δu_s = δu_m - [r]× δθ_m
                    let s = -spin(&r);
                    let mut out = [(6 * m + c, 1.0); MAX_EXPANSION];
                    let mut len = 1;
                    for j in 0..3 {
                        if s[(c, j)] != 0.0 {
                            out[len] = (6 * m + 3 + j, s[(c, j)]);
                            len += 1;
                        }
                    }
                    (out, len)
                }
            }
        };
        k.reduce(|d| link[d / 6].is_some(), expand);
        for (s, l) in link.iter().enumerate() {
            if let Some((m, r)) = l {
                let g = Vector3::from_fn(|c, _| self.fint_full[6 * s + c] - fext[6 * s + c]);
                let gr = spin(&g) * spin(r);
                for i in 0..3 {
                    for j in 0..3 {
                        if gr[(i, j)] != 0.0 {
                            let e = Triplet::new(6 * m + 3 + i, 6 * m + 3 + j, gr[(i, j)]);
                            k.entries.push(e);
                        }
                    }
                }
            }
        }
    }
}
