//! The moving interface between two fluids (thesis §3.3.2, Eq. 3.8; DESIGN §5): a level set `φ`
//! per node, advected with the flow, whose sign gives each node's fluid; the ghost-fluid fluxes
//! of [`crate::two_phase`] then act at the edges whose ends hold different fluids.
//!
//! One step ([`LevelSet::step`]):
//! 1. the flow and `φ` advance together by one RK2 step on the material layout of `t^n`
//!    ([`crate::time::rk2::rk2_step_level_set`], `φ` by [`advect`]), the two-phase problems of
//!    the edges between the fluids solved along the interface normal of `∇φ^n`
//!    ([`crate::two_phase`]);
//! 2. each node's material becomes the side of `φ^{n+1}` ([`LevelSet::material_of`]); a node
//!    whose material changed takes the ghost state of the exact two-phase Riemann problem on its
//!    edges to nodes of its new fluid ([`ghost`]), its conserved variables recomputed with the new
//!    EOS, and the operator's layout (special edges, masked gradients) is rebuilt;
//!    Within each RK2 stage a node below its material's cavitation cut-off (DESIGN §5.1: the
//!    vapour pressure of water for a liquid, none for a perfect gas; the cut-off of the
//!    two-phase Riemann problems too, [`crate::two_phase::cutoff`]) is clipped to it
//!    ([`crate::eos::Eos::cut_off`]: a gas at fixed density and velocity, a Tait liquid to the
//!    density of `p_cut`), each clip counted ([`InterfaceStep::clips`]);
//! 3. every `reinit_every` steps `φ` is reset to a signed distance with the nodes of
//!    sign-changing edges frozen ([`reinit`]), so reinitialisation never moves the interface and
//!    never changes a material.
//!
//! With an embedded surface the step is the surface's ([`crate::embedded::advance`]): the same
//! RK2 stages carry `φ`, and steps 2 and 3 ([`LevelSet::after_flow`]) never look across the
//! structure ([`crate::embedded::level_set`]).
//!
//! Form: `φ_t + u·∇φ = 0` (Eq. 3.8), not the conservative `(ρφ)_t + ∇·(ρφu) = 0`. The ghost-fluid
//! method carries two different fluxes on each interface edge and lets the density jump by three
//! orders of magnitude there, so a mass flux of `ρφ` is neither single-valued at the interface nor
//! smooth across it, while `φ` and `u` are both continuous there: the advective form needs only
//! the velocity, takes its gradient straight across the interface, and keeps `φ` a distance
//! between reinitialisations. Its edge form (see [`advect`]) is upwind MUSCL on `φ` with the
//! scheme's limiter, second order where `φ` and `u` are smooth.

pub mod advect;
pub mod ghost;
pub mod gradient;
pub mod init;
pub mod reinit;
#[cfg(test)]
mod strain_tests;

use crate::bc::BoundaryCondition;
use crate::embedded::adjacency::NodeEdges;
use crate::reconstruct::gradient::LsqGradient;
use crate::riemann::PressureCutoff;
use crate::semidiscretization::{FluidError, InterfaceNormals, Semidiscretization};
use crate::state::{MaterialId, State, Workspace};
use crate::time::rk2::rk2_step_level_set;
use crate::time::TimeStepping;

/// The level set of one interface between two fluids, its settings and the operators built
/// once per mesh.
#[derive(Debug, Clone)]
pub struct LevelSet {
    /// The material where `φ < 0` and where `φ >= 0`.
    pub materials: [MaterialId; 2],
    /// Steps between reinitialisations (0: never).
    pub reinit_every: u64,
    /// Least-squares gradients of `φ`: through every edge (across the material interface), with
    /// the mirror planes of the flow's operator ([`gradient`]).
    pub gradient: LsqGradient,
    /// Node-to-edge adjacency, for the ghost states and the reinitialisation.
    pub adjacency: NodeEdges,
    /// The nodes on far-field, inflow and outflow boundaries (first-order `φ` there, [`advect`]).
    pub open: Vec<bool>,
    /// The nodal cavitation cut-off of every material id
    /// ([`crate::riemann::PressureCutoff::default_for`]; `-∞`: none).
    pub p_cut: Vec<f64>,
}

/// Scratch arrays of the level set, allocated once per mesh.
#[derive(Debug, Clone)]
pub struct LevelSetWorkspace {
    /// `φ` of the current stage, as the gradient operator reads it.
    pub phi: Vec<[f64; 1]>,
    /// `∇φ` of the current stage.
    pub grad: Vec<[[f64; 3]; 1]>,
    /// `R^φ_i`.
    pub residual: Vec<f64>,
    /// `φ¹`, then `φ^{n+1}` while the step is built.
    pub stage: Vec<f64>,
}

impl LevelSetWorkspace {
    pub fn new(n_nodes: usize) -> LevelSetWorkspace {
        LevelSetWorkspace {
            phi: vec![[0.0]; n_nodes],
            grad: vec![[[0.0; 3]]; n_nodes],
            residual: vec![0.0; n_nodes],
            stage: vec![0.0; n_nodes],
        }
    }

    /// Memory in bytes.
    pub fn memory_bytes(&self) -> usize {
        use std::mem::size_of_val;
        size_of_val(&self.phi[..])
            + size_of_val(&self.grad[..])
            + size_of_val(&self.residual[..])
            + size_of_val(&self.stage[..])
    }
}

/// What a step did to the interface.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct InterfaceStep {
    /// The step taken.
    pub dt: f64,
    /// Nodes whose material changed.
    pub changed: usize,
    /// Whether `φ` was reinitialised after the step.
    pub reinitialised: bool,
    /// Node states clipped to the cavitation cut-off in the step's two stages.
    pub clips: u64,
}

impl LevelSet {
    /// The level set between `materials[0]` (`φ < 0`) and `materials[1]` (`φ >= 0`) on the
    /// operator's mesh, reinitialised every `reinit_every` steps.
    pub fn new(
        semi: &Semidiscretization,
        materials: [MaterialId; 2],
        reinit_every: u64,
    ) -> LevelSet {
        let mut open = vec![false; semi.mesh.n_nodes()];
        for &(b, bc) in &semi.patches {
            if !matches!(bc, BoundaryCondition::SlipWall | BoundaryCondition::Symmetry) {
                for &i in &semi.mesh.boundaries[b].nodes {
                    open[i as usize] = true;
                }
            }
        }
        LevelSet {
            materials,
            reinit_every,
            gradient: gradient::phi_gradient(semi),
            adjacency: NodeEdges::build(&semi.mesh),
            open,
            p_cut: semi.eos.iter().map(|e| PressureCutoff::default_for(e).p_cut).collect(),
        }
    }

    /// The side of `φ`: 0 where `φ < 0`, 1 where `φ >= 0` (a node exactly on the interface
    /// belongs to the `φ >= 0` fluid, as a point on a region's surface is inside it).
    #[inline(always)]
    pub fn side(phi: f64) -> usize {
        usize::from(phi >= 0.0)
    }

    /// The material of a node with level set `phi`.
    #[inline(always)]
    pub fn material_of(&self, phi: f64) -> MaterialId {
        self.materials[Self::side(phi)]
    }

    /// Checks that `state` carries a level set consistent with its materials: one `φ` per node,
    /// finite, and each node's material the one of its side.
    pub fn check(&self, state: &State) -> Result<(), String> {
        if state.phi.len() != state.len() {
            return Err(format!(
                "{} level-set values for {} nodes (a state without a level set?)",
                state.phi.len(),
                state.len()
            ));
        }
        for (i, (&phi, &m)) in state.phi.iter().zip(&state.material).enumerate() {
            if !phi.is_finite() {
                return Err(format!("node {i}: level set φ = {phi} is not finite"));
            }
            if self.material_of(phi) != m {
                return Err(format!(
                    "node {i}: material {m} but level set φ = {phi:e} gives material {}",
                    self.material_of(phi)
                ));
            }
        }
        Ok(())
    }

    /// One step of the flow and the interface (module docs): RK2 of the flow and `φ` no longer
    /// than `dt_max`, the new materials and ghost states, the operator's layout, and the
    /// reinitialisation when `step_number` (the number of this step, from 1) is a multiple of
    /// `reinit_every`. The two-phase problems of the step are solved along the interface normals
    /// of `∇φⁿ`, which the step gives `semi` ([`crate::two_phase`]). On error `state` is unchanged,
    /// and so is `semi` but for those normals (of the unchanged `φ`).
    #[allow(clippy::too_many_arguments)]
    pub fn step(
        &self,
        semi: &mut Semidiscretization,
        state: &mut State,
        ws: &mut Workspace,
        lws: &mut LevelSetWorkspace,
        stepping: TimeStepping,
        dt_max: f64,
        step_number: u64,
    ) -> Result<InterfaceStep, FluidError> {
        let mut next = state.clone();
        let mut clips = 0;
        // The interface normals of the step's two-phase problems: ∇φⁿ (a function of the state,
        // which an error leaves unchanged).
        for (s, p) in lws.phi.iter_mut().zip(&state.phi) {
            s[0] = *p;
        }
        self.gradient.compute(&semi.mesh, &lws.phi, &mut lws.grad);
        let toward = self.materials[1];
        let normals = semi.interface.get_or_insert_with(|| InterfaceNormals {
            grad_phi: vec![[0.0; 3]; state.len()],
            toward,
        });
        normals.toward = toward;
        for (g, l) in normals.grad_phi.iter_mut().zip(&lws.grad) {
            *g = l[0];
        }
        let dt = rk2_step_level_set(semi, self, &mut next, ws, lws, stepping, dt_max, &mut clips)?;
        let (changed, reinitialised) =
            self.after_flow(semi, &mut next, lws, &self.gradient, None, step_number)?;
        *state = next;
        Ok(InterfaceStep { dt, changed, reinitialised, clips })
    }

    /// Steps 2 and 3 of the module docs once `state` holds the flow and `φ` at `t^{n+1}`: the
    /// new materials and ghost states, the operator's layout, and the reinitialisation when
    /// `step_number` is a multiple of `reinit_every`; `gradient` is the operator of `∇φ` and
    /// `through` the edges `φ` is taken through (`None`: all; with an embedded surface, the
    /// uncut edges between active nodes). Returns the number of nodes whose material changed and
    /// whether `φ` was reinitialised.
    pub fn after_flow(
        &self,
        semi: &mut Semidiscretization,
        state: &mut State,
        lws: &mut LevelSetWorkspace,
        gradient: &LsqGradient,
        through: Option<&[bool]>,
        step_number: u64,
    ) -> Result<(usize, bool), FluidError> {
        let moved = state.phi.iter().zip(&state.material).any(|(&p, &m)| self.material_of(p) != m);
        if moved {
            // The interface normals of the ghost states: ∇φⁿ⁺¹.
            for (s, p) in lws.phi.iter_mut().zip(&state.phi) {
                s[0] = *p;
            }
            gradient.compute(&semi.mesh, &lws.phi, &mut lws.grad);
        }
        let changed = ghost::update_materials(semi, self, &lws.grad, state, through)?;
        if changed > 0 {
            semi.set_materials(state.material.clone())
                .map_err(|e| FluidError::LevelSet(e.to_string()))?;
        }
        let reinitialised = self.reinit_every > 0 && step_number % self.reinit_every == 0;
        if reinitialised {
            for (s, p) in lws.phi.iter_mut().zip(&state.phi) {
                s[0] = *p;
            }
            gradient.compute(&semi.mesh, &lws.phi, &mut lws.grad);
            reinit::reinitialise(&semi.mesh, &self.adjacency, &lws.grad, &mut state.phi, through);
        }
        Ok((changed, reinitialised))
    }
}
