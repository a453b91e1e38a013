//! Linear springs on the translations of a node (the `spring` of a rigid body's reference
//! node, `[[structure.rigid_bodies]]`): in the global axes, the force on the node is
//! `P - K u` (`K = diag(k)`, `u = x - X` its displacement, `P` the preload, the spring's force
//! at the start). The spring is an element of the model: `K u - P` joins the internal force
//! before the constraint reduction (`FeModel::internal_force`), `K` the tangent, and its
//! frequency the element bound of the critical step: `Δt <= 2/ω`, `ω² = λ_max(K^½ W K^½)` with
//! `W` the translational block of the node's inverse mass (a rigid master's 6x6 block with its
//! constrained dofs held), so `ω = sqrt(k/m)` for a body of mass `m` on one axis.

use faer::sparse::Triplet;

use crate::linsolve::Tangent;
use nalgebra::{Matrix3, SymmetricEigen};

use super::FeModel;

/// A linear spring on the translations of `node`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NodeSpring {
    pub node: usize,
    /// Stiffness per global axis (N/m).
    pub stiffness: [f64; 3],
    /// The spring's force on the node at `u = 0` (N).
    pub preload: [f64; 3],
}

#[derive(Debug, PartialEq, thiserror::Error)]
pub enum SpringError {
    #[error("spring: node {node} out of range ({n} nodes)")]
    NodeRange { node: usize, n: usize },
    #[error(
        "spring: node {node} is a slave of a rigid body; put the spring on its reference node"
    )]
    Slave { node: usize },
    #[error("spring: the stiffness must be finite and >= 0 and the preload finite, got stiffness {stiffness:?}, preload {preload:?}")]
    Bad { stiffness: [f64; 3], preload: [f64; 3] },
}

impl FeModel {
    /// Adds the spring `s` (after the rigid body its node is the reference of, if any).
    pub fn add_spring(&mut self, s: NodeSpring) -> Result<(), SpringError> {
        let n = self.x0.len();
        if s.node >= n {
            return Err(SpringError::NodeRange { node: s.node, n });
        }
        if self.slave[s.node] {
            return Err(SpringError::Slave { node: s.node });
        }
        let ok = s.stiffness.iter().all(|k| k.is_finite() && *k >= 0.0)
            && s.preload.iter().all(|p| p.is_finite());
        if !ok {
            return Err(SpringError::Bad { stiffness: s.stiffness, preload: s.preload });
        }
        self.springs.push(s);
        self.fint_valid = false;
        Ok(())
    }

    /// The springs of the model.
    pub fn springs(&self) -> &[NodeSpring] {
        &self.springs
    }

    /// Adds `K u - P` of every spring to the internal force `f` (unreduced).
    pub(super) fn spring_forces(&self, f: &mut [f64]) {
        for s in &self.springs {
            let u = self.trial.x[s.node] - self.x0[s.node];
            for i in 0..3 {
                f[6 * s.node + i] += s.stiffness[i] * u[i] - s.preload[i];
            }
        }
    }

    /// Adds `K` of every spring to the tangent (unreduced).
    pub(super) fn spring_tangent(&self, out: &mut Tangent) {
        for s in &self.springs {
            for (i, &k) in s.stiffness.iter().enumerate() {
                if k != 0.0 {
                    out.entries.push(Triplet::new(6 * s.node + i, 6 * s.node + i, k));
                }
            }
        }
    }

    /// The springs' bound of the critical step, `2/ω` (infinite without springs).
    pub(super) fn spring_stable_dt(&self) -> f64 {
        let mut dt = f64::INFINITY;
        for s in &self.springs {
            let w = self.translational_inverse_mass(s.node);
            let h = Matrix3::from_diagonal(&nalgebra::Vector3::from(s.stiffness).map(f64::sqrt));
            let omega2 = SymmetricEigen::new(h * w * h).eigenvalues.max();
            if omega2 > 0.0 {
                dt = dt.min(2.0 / omega2.sqrt());
            }
        }
        dt
    }

    /// The translational block of node `n`'s inverse mass (0 on constrained dofs and dofs
    /// without mass); a rigid master's from its 6x6 block in the current orientation.
    fn translational_inverse_mass(&self, n: usize) -> Matrix3<f64> {
        let d = 6 * n;
        let cons = &self.constrained[d..d + 6];
        match self.body_of[n].map(|b| &self.rigid[b]) {
            Some(b) if b.master == n => {
                let mut w = Matrix3::zeros();
                for j in 0..3 {
                    let mut e = [0.0; 6];
                    e[j] = 1.0;
                    let col = b.inverse_mass(&self.trial.r[n], cons, &e);
                    for i in 0..3 {
                        w[(i, j)] = col[i];
                    }
                }
                0.5 * (w + w.transpose())
            }
            _ => Matrix3::from_fn(|i, j| {
                let m = self.mass[d + i];
                if i == j && !cons[i] && m > 0.0 {
                    1.0 / m
                } else {
                    0.0
                }
            }),
        }
    }
}
