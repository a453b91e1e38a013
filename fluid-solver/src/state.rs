//! The fluid state and the scratch arrays of a residual evaluation.
//!
//! Arrays are separate per quantity (structure of arrays: conserved, primitive, gradients, edge
//! fluxes, residuals each in their own `Vec`), with each node's 5-vector contiguous so the edge
//! loop gathers one cache line per end node. Node `i` of every array is node `i` of the mesh.
//!
//! Two-phase flow (DESIGN §5, thesis Ch. 3) adds a material id and a level set per node as two
//! more arrays of this struct; MPI adds ghost nodes after the owned ones.

/// Conserved variables `[ρ, ρu, ρv, ρw, E]` at every node.
#[derive(Debug, Clone, PartialEq)]
pub struct State {
    pub cons: Vec<[f64; 5]>,
}

impl State {
    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.cons.len()
    }

    pub fn is_empty(&self) -> bool {
        self.cons.is_empty()
    }
}

/// Scratch memory of the residual and the time integrator, allocated once per mesh.
#[derive(Debug, Clone)]
pub struct Workspace {
    /// Primitive `[ρ, u, v, w, p]` per node.
    pub prim: Vec<[f64; 5]>,
    /// `∇` of each primitive variable per node.
    pub grad: Vec<[[f64; 3]; 5]>,
    /// Numerical flux through each edge, from `i` to `j`.
    pub edge_flux: Vec<[f64; 5]>,
    /// Residual `R_i = Σ_j F_ij + boundary fluxes` per node.
    pub residual: Vec<[f64; 5]>,
    /// Intermediate Runge-Kutta state.
    pub stage: Vec<[f64; 5]>,
    /// Time-step limit per node, `|C_i| / Σ (|u·ν| + c|ν|)`.
    pub dt_node: Vec<f64>,
}

impl Workspace {
    pub fn new(n_nodes: usize, n_edges: usize) -> Workspace {
        Workspace {
            prim: vec![[0.0; 5]; n_nodes],
            grad: vec![[[0.0; 3]; 5]; n_nodes],
            edge_flux: vec![[0.0; 5]; n_edges],
            residual: vec![[0.0; 5]; n_nodes],
            stage: vec![[0.0; 5]; n_nodes],
            dt_node: vec![0.0; n_nodes],
        }
    }

    /// Memory in bytes.
    pub fn memory_bytes(&self) -> usize {
        (self.prim.len() + self.residual.len() + self.stage.len()) * 40
            + self.grad.len() * 120
            + self.edge_flux.len() * 40
            + self.dt_node.len() * 8
    }
}
