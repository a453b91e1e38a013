//! The mesh of a case's `[structure]`: a generator (its size checked against the machine's
//! memory before anything is allocated, coincident seam nodes merged) or a gmsh file, through
//! the one validity pass of [`crate::mesh::validate`]; then the box sets and the sets `all`,
//! and the locality renumbering of [`crate::mesh::renumber`] (the user's numbers kept apart).
//! Nodes at one position that no element shares draw a warning on stderr unless the mesh
//! declares them intended (`coincident_nodes = "allow"`).

use interface_protocol::case::{
    Case, CoincidentNodes, ElementType, StructureMesh, StructureSection,
};
use interface_protocol::resources::{bytes_for, ensure_memory, ResourceError};

use crate::build::{field_error, need};
use crate::mesh::merge::{merge_coincident, Collapsed};
use crate::mesh::renumber::renumber;
use crate::mesh::validate::{self, coincident_nodes, coincident_warning, Invalid};
use crate::mesh::{generate, gmsh, CellKind, Mesh};

/// Memory a model takes per node: the mesh's coordinates and sets, the model's reference,
/// current and committed positions and rotations, and 6 dofs of mass, constraint, prescribed
/// value, velocity, acceleration, forces and the integrators' work arrays, with the output
/// buffers. With [`BYTES_PER_CELL`] it bounds what a 300 x 300 BT4 plate was measured to take
/// (about 0.9 KiB per node and per cell, peak resident size of `check`).
pub const BYTES_PER_NODE: u64 = 1536;

/// Memory a model takes per cell besides its tangent: the mesh cell and its set entries, the
/// element with its reference geometry, section and committed and trial state, and the cell
/// fields of the output.
pub const BYTES_PER_CELL: u64 = 1536;

/// Memory of the tangent of a cell of `n` nodes, for models that have one (every element but
/// BT4): its `(6n)²` triplets of 24 bytes, twice for the growth of the triplet list. A 300 x
/// 300 MITC4 plate was measured at 28 KiB per cell, this gives 27 KiB for a quadrilateral.
pub fn tangent_bytes(n: usize) -> u64 {
    2 * 24 * (6 * n as u64).pow(2)
}

/// Refuses a model of `nodes` and `cells` (each taking `cell_bytes` beside
/// [`BYTES_PER_CELL`]) that the machine cannot hold; `what` names it.
pub fn ensure_model_memory(
    what: &str,
    nodes: f64,
    cells: f64,
    cell_bytes: u64,
) -> Result<(), ResourceError> {
    let per_cell = BYTES_PER_CELL + cell_bytes;
    let bytes = bytes_for(nodes, BYTES_PER_NODE).saturating_add(bytes_for(cells, per_cell));
    ensure_memory(what, bytes)
}

/// Whether some part of `s` has a tangent (any element but BT4).
fn has_tangent(s: &StructureSection) -> bool {
    if s.parts.is_empty() {
        s.element.is_some_and(|e| e != ElementType::Bt4)
    } else {
        s.parts.iter().any(|p| p.element != ElementType::Bt4)
    }
}

/// The generator's name, its grid size `(nu, nv)` (lines: `(n, 0)`) and cell count.
fn grid_of(m: &StructureMesh) -> Option<(&'static str, usize, usize, bool)> {
    Some(match *m {
        StructureMesh::Rectangle { nx, ny, triangles, .. } => ("rectangle", nx, ny, triangles),
        StructureMesh::Cylinder { n_theta, n_axial, triangles, .. } => {
            ("cylinder", n_theta, n_axial, triangles)
        }
        StructureMesh::Sphere { n_theta, n_phi, triangles, .. } => {
            ("sphere", n_theta, n_phi, triangles)
        }
        StructureMesh::Annulus { n_theta, n_r, triangles, .. } => {
            ("annulus", n_theta, n_r, triangles)
        }
        StructureMesh::Line { n, .. } => ("line", n, 0, false),
        StructureMesh::Gmsh { .. } => return None,
    })
}

/// The generated or read mesh, with the box sets, the node set `all` and the cell set `all`,
/// stored in locality order ([`renumber`]); its numberings give the user's numbers.
pub fn build_mesh(s: &StructureSection, case: &Case) -> anyhow::Result<Mesh> {
    let spec = need(&s.mesh, "mesh", case)?;
    let mut mesh = match spec {
        StructureMesh::Gmsh { file: path, coincident_nodes: policy } => {
            let p = case.dir().join(path);
            let m = gmsh::read(&p)
                .map_err(|e| field_error(case, "structure.mesh.file", format!("{e:#}")))?;
            let what = format!(
                "the model of {} ({} nodes, {} cells)",
                p.display(),
                m.nodes.len(),
                m.cells.len()
            );
            let tangent = if has_tangent(s) {
                m.cells.iter().map(|c| tangent_bytes(c.nodes.len())).max().unwrap_or(0)
            } else {
                0
            };
            ensure_model_memory(&what, m.nodes.len() as f64, m.cells.len() as f64, tangent)
                .map_err(|e| field_error(case, "structure.mesh.file", e))?;
            let pairs = coincident_nodes(&m);
            if !pairs.is_empty() && *policy == CoincidentNodes::Warn {
                let warning = case.field_error(
                    "structure.mesh.file",
                    format!(
                        "{}: {}; if that is intended (a notch), say so with \
                         `coincident_nodes = \"allow\"` in `structure.mesh`",
                        p.display(),
                        coincident_warning(&m, &pairs)
                    ),
                );
                eprintln!("structure-solver: warning: {warning}");
            }
            m
        }
        generated => generated_mesh(generated, has_tangent(s))
            .map_err(|message| field_error(case, "structure.mesh", message))?,
    };
    for (name, b) in &s.sets {
        let nodes = mesh.nodes_where(|p| (0..3).all(|k| p[k] >= b.min[k] && p[k] <= b.max[k]));
        if nodes.is_empty() {
            return Err(field_error(
                case,
                &format!("structure.sets.{name}"),
                "no node inside the box",
            ));
        }
        mesh.node_sets.insert(name.clone(), nodes);
    }
    mesh.node_sets.insert("all".into(), (0..mesh.nodes.len()).collect());
    mesh.cell_sets.insert("all".into(), (0..mesh.cells.len()).collect());
    Ok(renumber(mesh))
}

/// The mesh of a generator, refused before allocating when the machine cannot hold its model,
/// and when a cell collapses or is invalid (named by its grid cell).
fn generated_mesh(spec: &StructureMesh, tangent: bool) -> Result<Mesh, String> {
    let (name, nu, nv, triangles) = grid_of(spec).expect("a generator");
    let (nodes, cells) = if name == "line" {
        (nu as f64 + 1.0, nu as f64)
    } else {
        let cells = nu as f64 * nv as f64;
        ((nu as f64 + 1.0) * (nv as f64 + 1.0), if triangles { 2.0 * cells } else { cells })
    };
    let what = format!("the {name} ({nodes:.3e} nodes, {cells:.3e} cells)");
    let per_cell = match (tangent, name, triangles) {
        (false, ..) => 0,
        (true, "line", _) => tangent_bytes(2),
        (true, _, true) => tangent_bytes(3),
        (true, _, false) => tangent_bytes(4),
    };
    ensure_model_memory(&what, nodes, cells, per_cell).map_err(|e| e.to_string())?;
    let rad = |a: [f64; 2]| [a[0].to_radians(), a[1].to_radians()];
    let mesh = match *spec {
        StructureMesh::Rectangle { lx, ly, nx, ny, .. } => generate::rectangle(lx, ly, nx, ny),
        StructureMesh::Cylinder { radius, length, n_theta, n_axial, theta_deg, .. } => {
            generate::cylinder(radius, length, rad(theta_deg), n_theta, n_axial)
        }
        StructureMesh::Sphere { radius, n_theta, n_phi, theta_deg, phi_deg, .. } => {
            generate::sphere(radius, rad(theta_deg), rad(phi_deg), n_theta, n_phi)
        }
        StructureMesh::Annulus { r_inner, r_outer, n_theta, n_r, theta_deg, .. } => {
            generate::annulus(r_inner, r_outer, rad(theta_deg), n_theta, n_r)
        }
        StructureMesh::Line { from, to, n } => generate::line(from, to, n),
        StructureMesh::Gmsh { .. } => unreachable!("not a generator"),
    };
    // Grid cell (i, j) is cell j nu + i; a line's cell k is k.
    let cell_name = |c: usize| {
        if name == "line" {
            format!("cell {c} of the line")
        } else {
            format!("cell (i = {}, j = {}) of the {name}", c % nu, c / nu)
        }
    };
    let mut mesh = merge_coincident(mesh).map_err(|Collapsed { cell, kind, nodes }| {
        format!("{} (a {kind:?}) collapses to {nodes} nodes", cell_name(cell)).to_lowercase()
    })?;
    // The grid cell of each cell once quadrilaterals are split.
    let parents: Vec<usize> = if triangles {
        let split = |(c, k): (usize, CellKind)| {
            let n = if k == CellKind::Quad4 { 2 } else { 1 };
            std::iter::repeat_n(c, n)
        };
        let parents = mesh.cells.iter().map(|c| c.kind).enumerate().flat_map(split).collect();
        mesh = mesh.to_triangles();
        parents
    } else {
        (0..mesh.cells.len()).collect()
    };
    match validate::check(&mesh) {
        Ok(()) => Ok(mesh),
        Err(e @ Invalid::Cell { cell, .. }) => Err(e.describe(&cell_name(parents[cell]))),
        Err(e @ Invalid::Node { node }) => {
            Err(e.describe(&format!("node {} of the {name}", mesh.node_id(node))))
        }
    }
}
