//! The discretised structure as the integrators and static solvers see it.
//!
//! Degrees of freedom: 6 per node, `[ux, uy, uz, θx, θy, θz]`, node-major. Translations add;
//! rotations are finite and the model composes them (an increment's rotational part is an
//! incremental rotation vector in the global frame), so integrators never add rotation vectors.

use faer::sparse::Triplet;

pub use crate::linsolve::Tangent;

/// A structure model: mass, constraints, internal and external forces and their tangent.
pub trait Model: Send {
    /// Number of nodes; dofs are `6 * n_nodes()`.
    fn n_nodes(&self) -> usize;

    /// Number of degrees of freedom.
    fn n_dof(&self) -> usize {
        6 * self.n_nodes()
    }

    /// Lumped mass per dof (mass on translations, rotary inertia on rotations).
    fn lumped_mass(&self) -> &[f64];

    /// `true` where a dof's motion is prescribed (fixed dofs are prescribed to zero).
    fn constrained(&self) -> &[bool];

    /// Total prescribed value of each constrained dof at time `t` (others left untouched).
    fn prescribed(&self, t: f64, out: &mut [f64]);

    /// Moves the configuration by `du` (rotational parts composed with the current rotations).
    fn apply_increment(&mut self, du: &[f64]);

    /// Internal force vector at the current configuration; updates the trial material state.
    fn internal_force(&mut self, f: &mut [f64]);

    /// External force vector at time `t` at the current configuration (follower pressure).
    fn external_force(&mut self, t: f64, f: &mut [f64]);

    /// External force at `t` with `extra`, a nodal load from outside the model (6 per node,
    /// the coupling's), both through the model's one constraint reduction (rigid slaves to
    /// their master, skew-plane nodes to their plane). The default adds `extra` to
    /// `external_force`, for models without such constraints.
    fn external_force_with(&mut self, t: f64, extra: Option<&[f64]>, f: &mut [f64]) {
        self.external_force(t, f);
        if let Some(x) = extra {
            for (f, x) in f.iter_mut().zip(x) {
                *f += x;
            }
        }
    }

    /// Consistent tangent (material + geometric) of internal minus external force: element
    /// blocks and loose entries, `out` emptied first.
    fn tangent(&mut self, t: f64, out: &mut Tangent);

    /// A counter the model increases whenever its topology changes at run time (elements or
    /// constraints added, removed or duplicated): sparse solvers then check the pattern of the
    /// tangent's stream again. Constant (0) by default.
    fn topology_epoch(&self) -> u64 {
        0
    }

    /// `false` when some part has no tangent (explicit-only elements): static and implicit
    /// solvers refuse such a model.
    fn has_tangent(&self) -> bool {
        true
    }

    /// Accepts the trial configuration and material state as converged.
    fn commit(&mut self);

    /// Returns to the last committed configuration and material state.
    fn revert(&mut self);

    /// Critical time step of explicit central differences, all stiffness included.
    fn stable_dt(&self) -> f64;

    /// Current displacement of each node (translations only), node-major `[ux, uy, uz]`.
    fn displacement(&self, out: &mut [[f64; 3]]);

    /// Accelerations `a = M⁻¹ f` on the free dofs with mass, 0 elsewhere. The default is the
    /// lumped diagonal; models with rigid bodies solve each master's 6x6 block (mass, offset
    /// centre and full inertia tensor in the current orientation).
    fn apply_inverse_mass(&self, f: &[f64], a: &mut [f64]) {
        let (m, c) = (self.lumped_mass(), self.constrained());
        for (i, a) in a.iter_mut().enumerate() {
            *a = if c[i] || m[i] <= 0.0 { 0.0 } else { f[i] / m[i] };
        }
    }

    /// `out = M v` with the full mass matrix (lumped diagonal by default).
    fn mass_product(&self, v: &[f64], out: &mut [f64]) {
        for ((o, m), v) in out.iter_mut().zip(self.lumped_mass()).zip(v) {
            *o = m * v;
        }
    }

    /// The entries of the mass matrix beyond the diagonal `lumped_mass()` (the mass matrix
    /// is `diag(lumped_mass) + these`), as triplets in the current configuration; none by
    /// default.
    fn nondiagonal_mass(&self, out: &mut Vec<Triplet<usize, usize, f64>>) {
        out.clear();
    }

    /// The drift of explicit central differences over `dt` for dofs whose motion is not
    /// `du = dt v_half` (rigid bodies: the free rigid-body flow of the master at constant
    /// momentum, slaves following). On entry `du = dt v_half` on free dofs and the prescribed
    /// increment on constrained ones, `v_half` the velocity after the first kick; the model may
    /// rewrite both for dofs it owns (`v_half` then holds the velocity at the end
    /// configuration with the same momentum). Nothing by default.
    fn explicit_drift(&self, _dt: f64, _v_half: &mut [f64], _du: &mut [f64]) {}

    /// Writes the velocities and accelerations of dependent dofs from the independent ones
    /// in the current configuration (rigid slaves: `v = v_m + ω × r`,
    /// `a = a_m + α × r + ω × (ω × r)`). Nothing by default.
    fn dependent_motion(&self, _v: &mut [f64], _a: &mut [f64]) {}
}
