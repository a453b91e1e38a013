//! The gmsh 4.1 reader: nodes, lines, triangles and physical groups as named sets; a shell
//! model built from the file's surface cells; errors that name the file. On meshes made by gmsh
//! itself (`tests/fixtures/make_meshes.py`, gmsh 4.15.2): a quarter cylinder of quads whose
//! shell model has the area of its facets, and a binary L-shaped beam mesh whose beam model has
//! its length.

use structure_solver::assembly::{FeModel, Part};
use structure_solver::elements::{BeamSection, ShellSection};
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

fn fixture(name: &str) -> std::path::PathBuf {
    std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures").join(name)
}

/// The sum of the translational lumped masses along x.
fn mass(m: &FeModel) -> f64 {
    m.lumped_mass().iter().step_by(6).sum()
}

/// A quarter cylinder (radius 1, length 2) of 8 x 4 quads made by gmsh
/// (`tests/fixtures/make_meshes.py`): its counts and sets, and a shell model whose mass is
/// `rho h` times the area of the flat facets, `2 * 8 * 2 sin(pi / 32)`, which is below the
/// cylinder's area `pi` by about `(pi / 32)^2 / 6` relative.
#[test]
fn gmsh_quarter_cylinder_builds_a_shell_of_its_area() {
    let mesh = gmsh::read(&fixture("quarter_cylinder.msh")).unwrap();
    assert_eq!(mesh.nodes.len(), 45);
    let count = |k: CellKind| mesh.cells.iter().filter(|c| c.kind == k).count();
    assert_eq!((count(CellKind::Quad4), count(CellKind::Line2), mesh.cells.len()), (32, 16, 48));
    let shell = mesh.cell_set("shell").unwrap();
    assert_eq!(shell.len(), 32);
    assert!(shell.iter().all(|&c| mesh.cells[c].kind == CellKind::Quad4));
    assert_eq!(mesh.node_set("shell").unwrap().len(), 45);
    for (name, z) in [("clamp", 0.0), ("free", 2.0)] {
        let cells = mesh.cell_set(name).unwrap();
        assert_eq!(cells.len(), 8, "{name}");
        assert!(cells.iter().all(|&c| mesh.cells[c].kind == CellKind::Line2), "{name}");
        let nodes = mesh.node_set(name).unwrap();
        assert_eq!(nodes, mesh.nodes_where(|p| (p[2] - z).abs() < 1e-12), "{name}");
        assert_eq!(nodes.len(), 9, "{name}");
        for &n in nodes {
            let p = mesh.nodes[n];
            assert!((p[0].hypot(p[1]) - 1.0).abs() < 1e-12 && p[0] >= 0.0 && p[1] >= 0.0, "{p:?}");
        }
    }
    let mut surface = mesh.clone();
    surface.cells.retain(|c| c.kind == CellKind::Quad4);
    let sec = ShellSection { e: 1e6, nu: 0.3, rho: 2.0, h: 0.01 };
    let area = mass(&FeModel::new(&surface, |_| Part::Shell(sec)).unwrap()) / (sec.rho * sec.h);
    let facets = 2.0 * 8.0 * 2.0 * (std::f64::consts::PI / 32.0).sin();
    let exact = std::f64::consts::PI;
    let gap = (std::f64::consts::PI / 32.0).powi(2) / 6.0;
    println!("shell area {area:.15}, facets {facets:.15}, cylinder {exact:.15}");
    assert!((area - facets).abs() < 1e-12 * facets, "area {area} vs facets {facets}");
    assert!(area < exact && (exact - area) / exact < 1.01 * gap, "area {area} vs {exact}");
}

/// An L-shaped beam of 2 x 5 lines in gmsh's binary format: counts, the point groups as node
/// sets, and a beam model of mass `rho A` times the length 2.
#[test]
fn gmsh_binary_l_beam_builds_a_beam_model() {
    let mesh = gmsh::read(&fixture("l_beam.msh")).unwrap();
    assert_eq!(mesh.nodes.len(), 11);
    assert_eq!(mesh.cells.len(), 10);
    assert!(mesh.cells.iter().all(|c| c.kind == CellKind::Line2));
    assert_eq!(mesh.cell_set("beam").unwrap(), (0..10).collect::<Vec<_>>());
    assert_eq!(mesh.node_set("beam").unwrap(), (0..11).collect::<Vec<_>>());
    assert_eq!(mesh.node_set("base").unwrap(), &[mesh.nearest_node([0.0; 3])]);
    assert_eq!(mesh.node_set("tip").unwrap(), &[mesh.nearest_node([1.0, 1.0, 0.0])]);
    assert_eq!(mesh.nodes[mesh.node_set("tip").unwrap()[0]], [1.0, 1.0, 0.0]);
    assert!(mesh.cell_set("tip").is_err());
    let sec = BeamSection::rectangle(2e11, 0.3, 7800.0, 0.02, 0.01);
    let m = FeModel::new(&mesh, |_| Part::Beam(sec, [0.0, 0.0, 1.0])).unwrap();
    let length = mass(&m) / (sec.rho * sec.area);
    println!("beam length from its mass {length:.15}");
    assert!((length - 2.0).abs() < 1e-12, "{length}");
}

/// A type the structure does not read is refused at its block header, by line.
#[test]
fn unsupported_element_types_are_refused_at_their_block() {
    let text = SQUARE.replace("2 1 2 2\n", "2 1 9 2\n");
    let err = gmsh::parse(text.as_bytes(), "order2.msh").unwrap_err().to_string();
    assert!(
        err.starts_with("order2.msh:31: element type 9 (second-order triangle (6 nodes))"),
        "{err}"
    );
}
