//! The gmsh 4.1 reader: nodes, lines, triangles and physical groups as named sets; a shell
//! model built from the file's surface cells; errors that name the file.

use structure_solver::assembly::{FeModel, Part};
use structure_solver::elements::ShellSection;
use structure_solver::mesh::{gmsh, CellKind, MeshError};
use structure_solver::model::Model;

/// Unit square: a clamped edge (curve 1, physical 1 "clamped") and two triangles (surface 1,
/// physical 2 "plate"); node tags 1..4 at (0,0), (0,1), (1,0), (1,1).
const SQUARE: &str = r#"$MeshFormat
4.1 0 8
$EndMeshFormat
$PhysicalNames
2
1 1 "clamped"
2 2 "plate"
$EndPhysicalNames
$Entities
0 1 1 0
1 0 0 0 0 1 0 1 1 0
1 0 0 0 1 1 0 1 2 0
$EndEntities
$Nodes
2 4 1 4
1 1 0 2
1
2
0 0 0
0 1 0
2 1 0 2
3
4
1 0 0
1 1 0
$EndNodes
$Elements
2 3 1 3
1 1 1 1
1 1 2
2 1 2 2
2 1 3 4
3 1 4 2
$EndElements
"#;

#[test]
fn reads_cells_and_physical_groups() {
    let mesh = gmsh::parse(SQUARE.as_bytes(), "square.msh").unwrap();
    assert_eq!(mesh.nodes.len(), 4);
    assert_eq!(mesh.nodes[2], [1.0, 0.0, 0.0]);
    let kinds: Vec<CellKind> = mesh.cells.iter().map(|c| c.kind).collect();
    assert_eq!(kinds, vec![CellKind::Line2, CellKind::Tri3, CellKind::Tri3]);
    assert_eq!(mesh.cells[1].nodes, vec![0, 2, 3]);
    assert_eq!(mesh.cell_set("clamped").unwrap(), &[0]);
    assert_eq!(mesh.cell_set("plate").unwrap(), &[1, 2]);
    assert_eq!(mesh.node_set("clamped").unwrap(), &[0, 1]);
    assert_eq!(mesh.node_set("plate").unwrap(), &[0, 1, 2, 3]);
    // a shell model of the surface cells; the line cell asks for what it is
    let sec = ShellSection { e: 1e6, nu: 0.3, rho: 1.0, h: 0.01 };
    let err = FeModel::new(&mesh, |_| Part::Shell(sec)).unwrap_err().to_string();
    assert!(err.contains("cell 0") && err.contains("Line2"), "{err}");
    let mut surface = mesh.clone();
    surface.cells.retain(|c| c.kind == CellKind::Tri3);
    let m = FeModel::new(&surface, |_| Part::Shell(sec)).unwrap();
    let total: f64 = m.lumped_mass().iter().step_by(6).sum();
    assert!((total - 1.0 * 0.01).abs() < 1e-14, "mass {total}");
}

#[test]
fn errors_name_the_file_and_the_set() {
    let err = gmsh::parse(b"$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 2\n", "broken.msh")
        .unwrap_err();
    assert!(matches!(err, MeshError::Read { .. }));
    assert!(err.to_string().starts_with("broken.msh:"), "{err}");
    let err = gmsh::read(std::path::Path::new("/nonexistent/mesh.msh")).unwrap_err().to_string();
    assert!(err.contains("/nonexistent/mesh.msh"), "{err}");
    let mesh = gmsh::parse(SQUARE.as_bytes(), "square.msh").unwrap();
    let err = mesh.node_set("wet").unwrap_err().to_string();
    assert!(err.contains("wet") && err.contains("clamped"), "{err}");
}
