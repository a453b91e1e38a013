//! The errors of a fluid step (residual, boundary, two-phase and wall fluxes, material changes),
//! each naming the node or edge, its position and what went wrong.

use crate::eos::StateError;
use crate::riemann::RiemannError;
use crate::state::MaterialId;

/// A failure of a residual evaluation, naming the node.
#[derive(Debug, Clone, thiserror::Error)]
pub enum FluidError {
    #[error("invalid fluid state at node {node} (x = {position:?}): {error}; primitive [ρ, u, v, w, p] = {prim:?}")]
    InvalidState { node: usize, position: [f64; 3], prim: [f64; 5], error: StateError },
    #[error("boundary `{boundary}` at node {node} (x = {position:?}): {error}")]
    Boundary { boundary: String, node: usize, position: [f64; 3], error: RiemannError },
    #[error(
        "two-phase Riemann problem on edge {edge} between nodes {nodes:?} (materials {materials:?}, \
         x = {position:?}): {error}"
    )]
    TwoPhase {
        edge: usize,
        nodes: [usize; 2],
        materials: [MaterialId; 2],
        position: [f64; 3],
        error: RiemannError,
    },
    #[error(transparent)]
    Wall(#[from] crate::embedded::riemann_fs::WallFluxError),
    #[error("ghost state of node {node} changing from material {} to {} (x = {position:?}): {error}", materials[0], materials[1])]
    Ghost { node: usize, materials: [MaterialId; 2], position: [f64; 3], error: RiemannError },
    #[error("level set: {0}")]
    LevelSet(String),
    #[error("edge {edge} from active node {node} (x = {position:?}) to a node that is not active, not cut by the surface (taken as a slip wall): {error}")]
    FrozenEdge { edge: usize, node: usize, position: [f64; 3], error: RiemannError },
}
