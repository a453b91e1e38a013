//! The discretised structure as the integrators and static solvers see it.
//!
//! Degrees of freedom: 6 per node, `[ux, uy, uz, θx, θy, θz]`, node-major. Translations add;
//! rotations are finite and the model composes them (an increment's rotational part is an
//! incremental rotation vector in the global frame), so integrators never add rotation vectors.

use faer::sparse::Triplet;

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

    /// Consistent tangent (material + geometric) of internal minus external force, as triplets.
    fn tangent(&mut self, t: f64, out: &mut Vec<Triplet<usize, usize, f64>>);

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
}
