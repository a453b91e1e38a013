//! The fluid's reading of a gmsh `.msh` 4.1 mesh (format: [`interface_protocol::io::gmsh`]):
//! linear tets, hexes, prisms and pyramids are the cells; the triangles and quads of surfaces in
//! physical groups are the boundary faces, each physical group one boundary named by
//! `$PhysicalNames`. A surface in several physical groups belongs to the first. Points and lines
//! are skipped; any other element type is refused. Errors name the file and the line (and the
//! byte offset in binary data).

use super::geometry::{centroid, cross, dot, norm, sub};
use super::{Cell, CellKind, MeshError, RawMesh, TaggedFace};
use interface_protocol::io::gmsh::{self, ElementType, GmshError, Msh, Position};
use std::path::Path;

/// Reads a gmsh 4.1 mesh.
pub fn read(path: &Path) -> Result<RawMesh, MeshError> {
    from_msh(gmsh::read(path, accept).map_err(input)?).map_err(input)
}

fn input(e: GmshError) -> MeshError {
    MeshError::Input(e.to_string())
}

/// The element types the fluid reads; the error for the others.
fn accept(t: ElementType) -> Result<(), String> {
    element_kind(t).map(|_| ())
}

/// What a gmsh element type is to the fluid.
enum ElementKind {
    Cell(CellKind),
    Face,
    /// A point or a line.
    Skipped,
}

fn element_kind(t: ElementType) -> Result<ElementKind, String> {
    Ok(match t.code {
        4 => ElementKind::Cell(CellKind::Tet),
        5 => ElementKind::Cell(CellKind::Hex),
        6 => ElementKind::Cell(CellKind::Prism),
        7 => ElementKind::Cell(CellKind::Pyramid),
        2 | 3 => ElementKind::Face,
        15 | 1 => ElementKind::Skipped,
        _ => return Err(format!(
            "element type {} ({t}) is not supported: linear tetrahedra (4), hexahedra (5), prisms (6) and pyramids (7), with triangles (2) and quadrangles (3) on the boundary",
            t.code
        )),
    })
}

/// The cells, the named boundary faces and the boundary names of `msh`.
fn from_msh(msh: Msh) -> Result<RawMesh, GmshError> {
    let mut cells = Vec::new();
    let mut faces = Vec::new();
    let mut patch_names: Vec<String> = Vec::new();
    for block in &msh.blocks {
        let kind = element_kind(block.kind).map_err(|m| msh.error(block.at, m))?;
        match kind {
            ElementKind::Cell(k) => {
                for (ids, (&tag, &at)) in
                    block.elements().zip(block.tags.iter().zip(&block.positions))
                {
                    if let Some(node) = super::dual::repeated_node(ids) {
                        return Err(msh.error(at, format!(
                            "element {tag} ({}) lists node {} twice: its corners must be distinct nodes",
                            k.name(),
                            msh.node_tags[node as usize]
                        )));
                    }
                    let volume = signed_volume(k, ids, &msh.coords);
                    let size = ids
                        .iter()
                        .map(|&i| norm(sub(msh.coords[i as usize], msh.coords[ids[0] as usize])))
                        .fold(0.0, f64::max);
                    if volume.partial_cmp(&(1e-12 * size * size * size)).is_none_or(|o| o.is_le()) {
                        return Err(msh.error(at, format!(
                            "element {tag} ({}) is inverted or flat (signed volume {volume:e}): its nodes must follow gmsh's ordering with a positive orientation",
                            k.name()
                        )));
                    }
                    cells.push(Cell::new(k, ids));
                }
            }
            ElementKind::Face => {
                let Some(name) = surface_name(&msh, block.entity, block.at)? else { continue };
                let patch = match patch_names.iter().position(|p| *p == name) {
                    Some(p) => p,
                    None => {
                        patch_names.push(name);
                        patch_names.len() - 1
                    }
                };
                faces.extend(
                    block
                        .elements()
                        .map(|ids| TaggedFace { patch: patch as u32, nodes: ids.to_vec() }),
                );
            }
            ElementKind::Skipped => {}
        }
    }
    if cells.is_empty() {
        return Err(
            msh.error(msh.end, "the file has no volume elements (tets, hexes, prisms or pyramids)")
        );
    }
    Ok(RawMesh { coords: msh.coords, cells, faces, patch_names, origin: msh.origin })
}

/// The boundary name of the faces of surface `entity` (block at `block`), or `None` if it is in
/// no physical group (its faces are then dropped; if they bound the domain, `Mesh::build`
/// reports the dual cells left open there).
fn surface_name(msh: &Msh, entity: i32, block: Position) -> Result<Option<String>, GmshError> {
    let Some(entities) = &msh.entities else {
        return Err(msh.error(
            block,
            "surface elements, but no `$Entities` section to give their physical groups",
        ));
    };
    let Some(surface) = entities.get(&(2, entity)) else {
        return Err(msh.error(block, format!("surface {entity} is not in `$Entities`")));
    };
    let Some(&group) = surface.physical.first() else { return Ok(None) };
    if msh.physical_names.is_none() {
        return Err(msh.error(
            surface.at,
            format!("surface {entity} is in physical group {group}, but the file has no `$PhysicalNames` section: name each boundary with a named physical surface group"),
        ));
    }
    match msh.physical_name(2, group) {
        Some(name) => Ok(Some(name.to_string())),
        None => Err(msh.error(
            surface.at,
            format!("surface {entity} is in physical group {group}, which `$PhysicalNames` does not name"),
        )),
    }
}

/// Signed volume of a cell: cones from its centroid over the triangles joining each outward face
/// (gmsh ordering, [`CellKind::faces`]) to the face centroid. Negative for an inverted cell.
fn signed_volume(kind: CellKind, ids: &[u32], coords: &[[f64; 3]]) -> f64 {
    let x = |l: usize| coords[ids[l] as usize];
    let g = centroid((0..kind.n_nodes()).map(x));
    let mut v = 0.0;
    for face in kind.faces() {
        let fc = centroid(face.iter().map(|&l| x(l)));
        for q in 0..face.len() {
            let (a, b) = (sub(x(face[q]), g), sub(x(face[(q + 1) % face.len()]), g));
            v += dot(cross(a, b), sub(fc, g)) / 6.0;
        }
    }
    v
}
