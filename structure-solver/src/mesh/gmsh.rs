//! gmsh `.msh` 4.1 reader (ASCII or binary, through `mshio`): lines, triangles, quads and
//! tets; each physical group becomes a cell set and a node set of the same name (named by
//! `$PhysicalNames`, or `physical_<tag>` without one).

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use mshio::mshfile::ElementType;

use super::{Cell, CellKind, Mesh, MeshError};

/// Reads a gmsh 4.1 file.
pub fn read(path: &Path) -> Result<Mesh, MeshError> {
    let file = path.display().to_string();
    let bytes = std::fs::read(path)
        .map_err(|e| MeshError::Read { file: file.clone(), message: e.to_string() })?;
    parse(&bytes, &file)
}

/// `$PhysicalNames`: (dimension, tag) -> name.
fn physical_names(bytes: &[u8]) -> HashMap<(i32, i32), String> {
    let mut names = HashMap::new();
    let text = String::from_utf8_lossy(bytes);
    if let Some(start) = text.find("$PhysicalNames") {
        for line in text[start..].lines().skip(2) {
            if line.starts_with("$End") {
                break;
            }
            let mut it = line.splitn(3, char::is_whitespace);
            if let (Some(d), Some(t), Some(n)) = (it.next(), it.next(), it.next()) {
                if let (Ok(d), Ok(t)) = (d.parse(), t.parse()) {
                    names.insert((d, t), n.trim().trim_matches('"').to_string());
                }
            }
        }
    }
    names
}

/// Parses the bytes of a gmsh 4.1 file named `file` (for messages).
pub fn parse(bytes: &[u8], file: &str) -> Result<Mesh, MeshError> {
    let err = |message: String| MeshError::Read { file: file.to_string(), message };
    let msh =
        mshio::parse_msh_bytes(bytes).map_err(|e| err(format!("not a gmsh 4.1 mesh: {e}")))?;
    let names = physical_names(bytes);
    let data = msh.data;
    let nodes = data.nodes.ok_or_else(|| err("no $Nodes section".into()))?;
    let mut mesh = Mesh::default();
    let mut index: HashMap<u64, usize> = HashMap::new();
    for block in &nodes.node_blocks {
        let tags: Vec<u64> = match &block.node_tags {
            Some(map) => {
                let mut v = vec![0u64; block.nodes.len()];
                for (&tag, &i) in map {
                    v[i] = tag;
                }
                v
            }
            // dense tags across the file: mshio drops them, they run on from the minimum
            None => (0..block.nodes.len() as u64)
                .map(|i| nodes.min_node_tag + mesh.nodes.len() as u64 + i)
                .collect(),
        };
        for (n, tag) in block.nodes.iter().zip(tags) {
            index.insert(tag, mesh.nodes.len());
            mesh.nodes.push([n.x, n.y, n.z]);
        }
    }
    // entity (dim, tag) -> physical tags
    let mut physical: HashMap<(i32, i32), Vec<i32>> = HashMap::new();
    if let Some(ent) = &data.entities {
        for p in &ent.points {
            physical.insert((0, p.tag), p.physical_tags.clone());
        }
        for c in &ent.curves {
            physical.insert((1, c.tag), c.physical_tags.clone());
        }
        for s in &ent.surfaces {
            physical.insert((2, s.tag), s.physical_tags.clone());
        }
        for v in &ent.volumes {
            physical.insert((3, v.tag), v.physical_tags.clone());
        }
    }
    let mut cell_sets: BTreeMap<String, Vec<usize>> = BTreeMap::new();
    let mut node_sets: BTreeMap<String, Vec<usize>> = BTreeMap::new();
    let elements = data.elements.ok_or_else(|| err("no $Elements section".into()))?;
    for block in &elements.element_blocks {
        let kind = match block.element_type {
            ElementType::Lin2 => Some(CellKind::Line2),
            ElementType::Tri3 => Some(CellKind::Tri3),
            ElementType::Qua4 => Some(CellKind::Quad4),
            ElementType::Tet4 => Some(CellKind::Tet4),
            ElementType::Pnt => None,
            other => {
                return Err(err(format!(
                    "element type {other:?} is not supported (lines, triangles, quads, tets)"
                )))
            }
        };
        let groups =
            physical.get(&(block.entity_dim, block.entity_tag)).cloned().unwrap_or_default();
        let set_name = |g: i32| {
            names.get(&(block.entity_dim, g)).cloned().unwrap_or_else(|| format!("physical_{g}"))
        };
        for e in &block.elements {
            let mut nn = Vec::with_capacity(e.nodes.len());
            for t in &e.nodes {
                nn.push(*index.get(t).ok_or_else(|| {
                    err(format!("element {} names unknown node {t}", e.element_tag))
                })?);
            }
            for &g in &groups {
                node_sets.entry(set_name(g)).or_default().extend(nn.iter().copied());
            }
            if let Some(kind) = kind {
                for &g in &groups {
                    cell_sets.entry(set_name(g)).or_default().push(mesh.cells.len());
                }
                mesh.cells.push(Cell { kind, nodes: nn });
            }
        }
    }
    for v in node_sets.values_mut() {
        v.sort_unstable();
        v.dedup();
    }
    mesh.node_sets = node_sets;
    mesh.cell_sets = cell_sets;
    Ok(mesh)
}
