//! What a fluid run holds in memory, estimated from the node and cell counts before the mesh is
//! built, so that a mesh that cannot fit is refused with the estimate and what the machine has
//! (`interface_protocol::resources`) instead of aborting in the allocator.
//!
//! The estimate adds up the arrays a run keeps, from their element types: per node the mesh's
//! coordinates, original ids, dual volumes and dual areas, the gradient operator's inverse
//! matrix, the conserved state and material id and the five workspace arrays; per edge its two node numbers and
//! its area normal, at [`EDGES_PER_NODE`] edges per node; per cell its [`Cell`]. `fluid-solver
//! bench` measured 806 B/node on a tet box, cells included; the test below holds this estimate
//! to the arrays of a built mesh.

use crate::mesh::Cell;
use interface_protocol::resources::{self, ResourceError};
use std::mem::size_of;

/// Edges per node of a tet mesh (a box of Kuhn tets has 7; a hex mesh has 3): an upper bound.
pub const EDGES_PER_NODE: u64 = 7;

/// Bytes a run holds per node, edges included.
pub const BYTES_PER_NODE: u64 = {
    let f = size_of::<f64>() as u64;
    let mesh = 3 * f + size_of::<u32>() as u64 + 2 * f;
    let gradient = 6 * f;
    let state = 5 * f + size_of::<crate::state::MaterialId>() as u64;
    // prim, grad (5 x 3), residual, stage, dt_node.
    let workspace = 5 * f + 15 * f + 5 * f + 5 * f + f;
    let edge = size_of::<[u32; 2]>() as u64 + 3 * f;
    mesh + gradient + state + workspace + EDGES_PER_NODE * edge
};

/// Bytes a run holds per cell.
pub const BYTES_PER_CELL: u64 = size_of::<Cell>() as u64;

/// The estimated bytes of a run on `nodes` nodes and `cells` cells (saturating).
pub fn estimate(nodes: f64, cells: f64) -> u64 {
    resources::bytes_for(nodes, BYTES_PER_NODE)
        .saturating_add(resources::bytes_for(cells, BYTES_PER_CELL))
}

/// Refuses a mesh of `nodes` nodes and `cells` cells that this machine cannot hold; `what`
/// names it (e.g. "the fluid mesh of `fluid.mesh.box.cells = [..]`").
pub fn ensure_fits(what: &str, nodes: f64, cells: f64) -> Result<(), ResourceError> {
    let what = format!(
        "{what} ({nodes:.3e} nodes, {cells:.3e} cells, at about {BYTES_PER_NODE} B per node and \
         {BYTES_PER_CELL} B per cell)"
    );
    resources::ensure_memory(&what, estimate(nodes, cells))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eos::Eos;
    use crate::mesh::boxmesh::{BoxCells, BoxSpec, FACE_NAMES};
    use crate::mesh::Mesh;
    use crate::semidiscretization::{Numerics, Semidiscretization};
    use crate::state::Workspace;

    #[test]
    fn the_estimate_matches_the_arrays_of_a_built_tet_mesh() {
        let spec = BoxSpec::uniform([0.0; 3], [1.0; 3], [12, 12, 12], BoxCells::Tet);
        let mesh = Mesh::build(spec.raw().unwrap()).unwrap();
        let (nodes, cells) = (mesh.n_nodes(), mesh.cells.len());
        let walls: Vec<_> = FACE_NAMES
            .iter()
            .map(|n| (n.to_string(), crate::bc::BoundaryCondition::SlipWall))
            .collect();
        let semi = Semidiscretization::new(
            mesh,
            Eos::PerfectGas { gamma: 1.4 },
            Numerics::default(),
            &walls,
        )
        .unwrap();
        let ws = Workspace::new(nodes);
        let held = semi.mesh.memory_bytes()
            + semi.gradient.memory_bytes()
            + semi.symmetry.memory_bytes()
            + ws.memory_bytes()
            + crate::state::State::new(vec![[0.0; 5]; nodes]).memory_bytes();
        let estimate = estimate(nodes as f64, cells as f64);
        let ratio = estimate as f64 / held as f64;
        println!("{nodes} nodes, {cells} cells: estimate {estimate} B, held {held} B ({ratio:.3})");
        assert!((1.0..1.3).contains(&ratio), "estimate / held = {ratio}");
    }

    #[test]
    fn an_absurd_mesh_is_refused_with_the_estimate() {
        let e = ensure_fits("the fluid mesh of `fluid.mesh.box.cells`", 1e14, 6e14).unwrap_err();
        let msg = e.to_string();
        assert!(msg.contains("fluid.mesh.box.cells") && msg.contains("1.000e14 nodes"), "{msg}");
        assert!(msg.contains("PiB") && msg.contains("available"), "{msg}");
        assert!(ensure_fits("a small mesh", 1e3, 6e3).is_ok());
    }
}
