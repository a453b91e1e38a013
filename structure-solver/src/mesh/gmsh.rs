//! The structure's reading of a gmsh `.msh` 4.1 mesh, ASCII or binary (format:
//! [`interface_protocol::io::gmsh`]): lines (beams), triangles and quads (shells) and tets
//! (solids) are the cells; points are skipped; any other element type is refused at its block.
//! Each physical group, of any dimension, becomes a node set (the nodes of its elements) and a
//! cell set (its cells) of the same name: the name `$PhysicalNames` gives it, or `physical_<tag>`
//! without one. Errors name the file and the line (the byte offset in binary data); a cell
//! the validity pass ([`super::validate`]) refuses is named by its element tag and line.

use std::collections::BTreeMap;
use std::path::Path;

use interface_protocol::io::gmsh::{self, ElementType, GmshError, Msh};

use super::validate::{self, Invalid};
use super::{Cell, CellKind, Mesh, MeshError};

/// Reads a gmsh 4.1 file.
pub fn read(path: &Path) -> Result<Mesh, MeshError> {
    gmsh::read(path, accept).and_then(from_msh).map_err(read_error)
}

/// Parses the bytes of a gmsh 4.1 file named `file` (for messages).
pub fn parse(bytes: &[u8], file: &str) -> Result<Mesh, MeshError> {
    gmsh::parse(bytes, file, accept).and_then(from_msh).map_err(read_error)
}

fn read_error(e: GmshError) -> MeshError {
    MeshError::Read { file: e.location(), message: e.message }
}

/// The cell kind of a gmsh element type (`None`: a point, read and skipped); the error for the
/// types the structure does not read.
fn cell_kind(t: ElementType) -> Result<Option<CellKind>, String> {
    Ok(Some(match t.code {
        1 => CellKind::Line2,
        2 => CellKind::Tri3,
        3 => CellKind::Quad4,
        4 => CellKind::Tet4,
        15 => return Ok(None),
        _ => {
            return Err(format!(
                "element type {} ({t}) is not supported: lines (1), triangles (2), quadrangles (3), tetrahedra (4) and points (15)",
                t.code
            ))
        }
    }))
}

fn accept(t: ElementType) -> Result<(), String> {
    cell_kind(t).map(|_| ())
}

/// Nodes, cells and the sets of the physical groups of `msh` (every block's type is one
/// [`accept`] let through), checked by [`validate::check`].
fn from_msh(msh: Msh) -> Result<Mesh, GmshError> {
    let mut cells = Vec::new();
    // (block, element in block) of each cell, to name it by tag and line.
    let mut origin = Vec::new();
    let mut cell_sets: BTreeMap<String, Vec<usize>> = BTreeMap::new();
    let mut node_sets: BTreeMap<String, Vec<usize>> = BTreeMap::new();
    for (b, block) in msh.blocks.iter().enumerate() {
        let kind = cell_kind(block.kind).ok().flatten();
        let names: Vec<String> = msh
            .physical_groups(block.dim, block.entity)
            .iter()
            .map(|&g| match msh.physical_name(block.dim, g) {
                Some(name) => name.to_string(),
                None => format!("physical_{g}"),
            })
            .collect();
        for name in &names {
            let nodes = block.connectivity.iter().map(|&i| i as usize);
            node_sets.entry(name.clone()).or_default().extend(nodes);
        }
        let Some(kind) = kind else { continue };
        let first = cells.len();
        origin.extend((0..block.len()).map(|e| (b, e)));
        cells.extend(
            block
                .elements()
                .map(|ids| Cell { kind, nodes: ids.iter().map(|&i| i as usize).collect() }),
        );
        for name in &names {
            cell_sets.entry(name.clone()).or_default().extend(first..cells.len());
        }
    }
    for v in node_sets.values_mut() {
        v.sort_unstable();
        v.dedup();
    }
    let Msh { coords: nodes, node_tags: node_ids, .. } = &msh;
    let (node_ids, nodes) = (node_ids.clone(), nodes.clone());
    let mesh = Mesh { nodes, cells, node_sets, cell_sets, node_ids, ..Mesh::default() };
    match validate::check(&mesh) {
        Ok(()) => Ok(mesh),
        Err(e @ Invalid::Cell { cell, .. }) => {
            let (b, k) = origin[cell];
            let block = &msh.blocks[b];
            Err(msh.error(block.positions[k], e.describe(&format!("element {}", block.tags[k]))))
        }
        Err(e @ Invalid::Node { node }) => {
            Err(msh.error(msh.end, e.describe(&format!("node {}", mesh.node_id(node)))))
        }
    }
}
