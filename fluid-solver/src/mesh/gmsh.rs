//! Reader of gmsh `.msh` 4.1 files (ASCII or binary, through `mshio`): tets, hexes, prisms and
//! pyramids; triangles and quads on surfaces belonging to physical groups name the boundaries
//! (`$PhysicalNames`, read here since `mshio` skips that section).

use super::{Cell, CellKind, MeshError, RawMesh, TaggedFace};
use mshio::mshfile::ElementType;
use std::collections::HashMap;
use std::path::Path;

/// `(dim, tag) -> name` from the `$PhysicalNames` section.
fn physical_names(bytes: &[u8]) -> HashMap<(i32, i32), String> {
    let mut names = HashMap::new();
    let text = String::from_utf8_lossy(bytes);
    let Some(start) = text.find("$PhysicalNames") else { return names };
    let Some(end) = text[start..].find("$EndPhysicalNames") else { return names };
    for line in text[start..start + end].lines().skip(2) {
        let mut parts = line.splitn(3, ' ');
        let (Some(dim), Some(tag), Some(name)) = (parts.next(), parts.next(), parts.next()) else {
            continue;
        };
        if let (Ok(dim), Ok(tag)) = (dim.trim().parse(), tag.trim().parse()) {
            names.insert((dim, tag), name.trim().trim_matches('"').to_string());
        }
    }
    names
}

/// Reads a gmsh 4.1 mesh.
pub fn read(path: &Path) -> Result<RawMesh, MeshError> {
    let origin = path.display().to_string();
    let err = |msg: String| MeshError::Input(format!("{origin}: {msg}"));
    let bytes = std::fs::read(path).map_err(|e| err(format!("cannot read the mesh file: {e}")))?;
    let msh = mshio::parse_msh_bytes(&bytes)
        .map_err(|e| err(format!("not a valid gmsh 4.1 .msh file: {e}")))?;
    let names = physical_names(&bytes);
    let nodes =
        msh.data.nodes.as_ref().ok_or_else(|| err("the file has no $Nodes section".into()))?;
    let elements = msh
        .data
        .elements
        .as_ref()
        .ok_or_else(|| err("the file has no $Elements section".into()))?;

    // Node tag -> index in the concatenated blocks.
    let mut coords = Vec::new();
    let mut index_of: HashMap<u64, u32> = HashMap::new();
    let dense = nodes.node_blocks.iter().all(|b| b.node_tags.is_none());
    for b in &nodes.node_blocks {
        let first = coords.len();
        if let Some(tags) = &b.node_tags {
            for (&tag, &k) in tags {
                index_of.insert(tag, (first + k) as u32);
            }
        }
        coords.extend(b.nodes.iter().map(|n| [n.x, n.y, n.z]));
    }
    let min_tag = nodes.min_node_tag;
    let node = |tag: u64| -> Result<u32, MeshError> {
        let idx = if dense {
            tag.checked_sub(min_tag).map(|v| v as u32)
        } else {
            index_of.get(&tag).copied()
        };
        idx.filter(|&i| (i as usize) < coords.len()).ok_or_else(|| {
            err(format!("an element refers to node tag {tag}, which is not in $Nodes"))
        })
    };

    // Surface entity tag -> physical group name.
    let mut surface_group: HashMap<i32, String> = HashMap::new();
    if let Some(entities) = &msh.data.entities {
        for s in &entities.surfaces {
            if let Some(&pt) = s.physical_tags.first() {
                let name = names.get(&(2, pt)).cloned().unwrap_or_else(|| format!("physical_{pt}"));
                surface_group.insert(s.tag, name);
            }
        }
    }
    let mut patch_names: Vec<String> = Vec::new();
    let mut cells = Vec::new();
    let mut faces = Vec::new();
    for block in &elements.element_blocks {
        let kind = match block.element_type {
            ElementType::Tet4 => Some(CellKind::Tet),
            ElementType::Hex8 => Some(CellKind::Hex),
            ElementType::Pri6 => Some(CellKind::Prism),
            ElementType::Pyr5 => Some(CellKind::Pyramid),
            ElementType::Tri3 | ElementType::Qua4 => None,
            ElementType::Pnt | ElementType::Lin2 => continue,
            other => {
                return Err(err(format!(
                    "element type {other:?} is not supported (linear tets, hexes, prisms, pyramids, triangles and quads only)"
                )))
            }
        };
        match kind {
            Some(kind) => {
                for e in &block.elements {
                    let ids: Vec<u32> =
                        e.nodes.iter().map(|&t| node(t)).collect::<Result<_, _>>()?;
                    cells.push(Cell::new(kind, &ids));
                }
            }
            None => {
                // Faces of surfaces without a physical group are ignored; if they bound the
                // domain, Mesh::build reports the open dual cells there.
                let Some(name) = surface_group.get(&block.entity_tag) else { continue };
                let patch = match patch_names.iter().position(|n| n == name) {
                    Some(p) => p,
                    None => {
                        patch_names.push(name.clone());
                        patch_names.len() - 1
                    }
                } as u32;
                for e in &block.elements {
                    let ids: Vec<u32> =
                        e.nodes.iter().map(|&t| node(t)).collect::<Result<_, _>>()?;
                    faces.push(TaggedFace { patch, nodes: ids });
                }
            }
        }
    }
    if cells.is_empty() {
        return Err(
            err("the file has no volume elements (tets, hexes, prisms or pyramids)".into()),
        );
    }
    Ok(RawMesh { coords, cells, faces, patch_names, origin })
}
