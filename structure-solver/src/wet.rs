//! The wet surface a structure sends to the fluid: the set `structure.wet_set` of shell faces
//! (a cell set of the mesh, or the shells whose nodes all lie in that node set), or the outward
//! boundary triangles of a cell set of tets; its nodes are numbered in order of first
//! appearance in those faces, taken in the user's cell order: the protocol's order is the
//! user's, whatever the storage order of the renumbered mesh.

use interface_protocol::messages::SurfaceElement;

use crate::mesh::{CellKind, Mesh};

/// The wet surface sent to the fluid.
#[derive(Debug, Clone, PartialEq)]
pub struct WetSurface {
    /// Structure node of each wet node, in wet-surface order.
    pub nodes: Vec<usize>,
    /// Faces indexing `nodes`.
    pub elements: Vec<SurfaceElement>,
}

/// The wet surface named `name`: the cell set of that name (shell faces, or tets whose boundary
/// faces wet, see [`tet_boundary`]), else the triangles and quadrilaterals whose nodes all belong
/// to the node set of that name.
pub fn wet_surface(mesh: &Mesh, name: &str) -> Result<WetSurface, String> {
    let is_face = |k: CellKind| matches!(k, CellKind::Tri3 | CellKind::Quad4);
    let by_user = |cells: &[usize]| {
        let mut v = cells.to_vec();
        v.sort_by_key(|&c| mesh.cell_user(c));
        v
    };
    let faces: Vec<Vec<usize>> = if let Ok(cells) = mesh.cell_set(name) {
        let owned = by_user(cells);
        let cells = &owned[..];
        let solid = cells.first().is_some_and(|&c| mesh.cells[c].kind == CellKind::Tet4);
        let expected = |k: CellKind| if solid { k == CellKind::Tet4 } else { is_face(k) };
        if let Some(&c) = cells.iter().find(|&&c| !expected(mesh.cells[c].kind)) {
            let what = if solid {
                "tetrahedra only (the set's first cell is one)"
            } else {
                "shell faces (triangles or quadrilaterals) or tetrahedra"
            };
            return Err(format!(
                "wet set \"{name}\": cell {} is a {:?}, expected {what}",
                mesh.cell_user(c),
                mesh.cells[c].kind
            ));
        }
        if solid {
            tet_boundary(mesh, cells).into_iter().map(|f| f.to_vec()).collect()
        } else {
            cells.iter().map(|&c| mesh.cells[c].nodes.clone()).collect()
        }
    } else {
        let nodes = mesh.node_set(name).map_err(|e| format!("wet set: {e}"))?;
        let mut inside = vec![false; mesh.nodes.len()];
        nodes.iter().for_each(|&n| inside[n] = true);
        mesh.cells_in_user_order()
            .into_iter()
            .map(|c| &mesh.cells[c])
            .filter(|c| is_face(c.kind) && c.nodes.iter().all(|&n| inside[n]))
            .map(|c| c.nodes.clone())
            .collect()
    };
    if faces.is_empty() {
        return Err(format!("wet set \"{name}\" holds no shell face or tetrahedron"));
    }
    let mut local = vec![u32::MAX; mesh.nodes.len()];
    let mut nodes = Vec::new();
    let mut elements = Vec::with_capacity(faces.len());
    for face in faces {
        let mut e = SurfaceElement { n_nodes: face.len() as u8, ..Default::default() };
        for (k, &n) in face.iter().enumerate() {
            if local[n] == u32::MAX {
                local[n] = nodes.len() as u32;
                nodes.push(n);
            }
            e.nodes[k] = local[n];
        }
        elements.push(e);
    }
    Ok(WetSurface { nodes, elements })
}

/// The boundary of the tets `cells`: the faces that belong to exactly one of them, as triangles
/// ordered counter-clockwise seen from outside (normal `(x1 - x0) × (x2 - x0)` away from the
/// tet's fourth node), in cell order.
pub fn tet_boundary(mesh: &Mesh, cells: &[usize]) -> Vec<[usize; 3]> {
    let mut faces = Vec::with_capacity(4 * cells.len());
    let mut count = std::collections::HashMap::new();
    for &c in cells {
        let t = &mesh.cells[c].nodes;
        for opp in 0..4 {
            let f: [usize; 3] = std::array::from_fn(|k| t[(opp + 1 + k) % 4]);
            let mut key = f;
            key.sort_unstable();
            *count.entry(key).or_insert(0usize) += 1;
            faces.push((key, f, t[opp]));
        }
    }
    let p = |n: usize| nalgebra::Vector3::from(mesh.nodes[n]);
    faces
        .into_iter()
        .filter(|(key, _, _)| count[key] == 1)
        .map(|(_, [a, b, c], opp)| {
            let normal = (p(b) - p(a)).cross(&(p(c) - p(a)));
            if normal.dot(&(p(opp) - p(a))) > 0.0 {
                [a, c, b]
            } else {
                [a, b, c]
            }
        })
        .collect()
}
