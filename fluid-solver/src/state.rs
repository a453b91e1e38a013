//! The fluid state and the scratch arrays of a residual evaluation.
//!
//! Arrays are separate per quantity (structure of arrays: conserved, primitive, gradients,
//! residuals each in their own `Vec`), with each node's 5-vector contiguous so the edge loop
//! gathers one cache line per end node. Node `i` of every array is node `i` of the mesh. Nothing
//! is stored per edge: the edge loop adds its fluxes straight into the nodal residuals
//! ([`crate::mesh::EdgeBlocks`]).
//!
//! Two-phase flow (DESIGN §5, thesis Ch. 3): each node holds a material id, its fluid's index in
//! the EOS table of [`crate::semidiscretization::Semidiscretization`], and with a moving interface
//! the level set `φ` ([`crate::levelset`]): its sign gives the material. MPI adds ghost nodes after
//! the owned ones.

/// A node's material: its fluid's index in the EOS table.
pub type MaterialId = u8;

/// Conserved variables `[ρ, ρu, ρv, ρw, E]`, the material id and the level set of every node.
#[derive(Debug, Clone, PartialEq)]
pub struct State {
    pub cons: Vec<[f64; 5]>,
    pub material: Vec<MaterialId>,
    /// The level set `φ` of the interface between two fluids, one per node; empty when the
    /// interface does not move (one fluid, or a fixed material layout).
    pub phi: Vec<f64>,
}

impl State {
    /// A state of one fluid (material 0 everywhere).
    pub fn new(cons: Vec<[f64; 5]>) -> State {
        let material = vec![0; cons.len()];
        State { cons, material, phi: Vec::new() }
    }

    /// A state of several fluids with a fixed layout (no level set).
    pub fn with_materials(cons: Vec<[f64; 5]>, material: Vec<MaterialId>) -> State {
        State { cons, material, phi: Vec::new() }
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.cons.len()
    }

    pub fn is_empty(&self) -> bool {
        self.cons.is_empty()
    }

    /// Memory in bytes.
    pub fn memory_bytes(&self) -> usize {
        std::mem::size_of_val(&self.cons[..])
            + std::mem::size_of_val(&self.material[..])
            + std::mem::size_of_val(&self.phi[..])
    }
}

/// Scratch memory of the residual and the time integrator, allocated once per mesh.
#[derive(Debug, Clone)]
pub struct Workspace {
    /// Primitive `[ρ, u, v, w, p]` per node.
    pub prim: Vec<[f64; 5]>,
    /// `∇` of each primitive variable per node.
    pub grad: Vec<[[f64; 3]; 5]>,
    /// Residual `R_i = Σ_j F_ij + boundary fluxes` per node.
    pub residual: Vec<[f64; 5]>,
    /// Intermediate Runge-Kutta state (and the new state while the last stage is built).
    pub stage: Vec<[f64; 5]>,
    /// Time-step limit per node for CFL 1, `2 |C_i| / Σ (|u·ν| + c|ν|)`.
    pub dt_node: Vec<f64>,
}

impl Workspace {
    /// The scratch arrays of a mesh of `n_nodes` nodes (no array is per edge).
    pub fn new(n_nodes: usize) -> Workspace {
        Workspace {
            prim: vec![[0.0; 5]; n_nodes],
            grad: vec![[[0.0; 3]; 5]; n_nodes],
            residual: vec![[0.0; 5]; n_nodes],
            stage: vec![[0.0; 5]; n_nodes],
            dt_node: vec![0.0; n_nodes],
        }
    }

    /// Memory in bytes.
    pub fn memory_bytes(&self) -> usize {
        use std::mem::size_of_val;
        size_of_val(&self.prim[..])
            + size_of_val(&self.grad[..])
            + size_of_val(&self.residual[..])
            + size_of_val(&self.stage[..])
            + size_of_val(&self.dt_node[..])
    }
}
