//! The validity pass every structure mesh goes through: an inverted tet and a bow-tie quad in a
//! gmsh file are refused naming the file, line and element tag, while the same meshes in order
//! read; nodes at one position that no element shares draw a warning naming their tags unless
//! the case allows them; a generator whose cells collapse is refused naming its cell, and one
//! too large for the machine before anything is allocated.

use std::path::Path;
use std::process::{Command, Output};

use structure_solver::mesh::validate::coincident_nodes;
use structure_solver::mesh::{gmsh, CellKind};

/// Two positive tets sharing the face 2 3 4 (node tags 1..5); `elements` are lines 25 and 26.
fn tets(elements: &str) -> String {
    format!(
        "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n0 0 0 1\n1 0 0 0 1 1 1 0 0\n\
         $EndEntities\n$Nodes\n1 5 1 5\n3 1 0 5\n1\n2\n3\n4\n5\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n\
         1 1 1\n$EndNodes\n$Elements\n1 2 1 2\n3 1 4 2\n{elements}$EndElements\n"
    )
}

/// Quads on surface 1 with node tags `tags` at `coords` (one node per line); the element
/// block's lines follow the nodes.
fn quads(tags: &[u64], coords: &[[f64; 3]], elements: &[&[u64]]) -> String {
    let n = tags.len();
    let mut s = format!(
        "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n0 0 1 0\n1 0 0 0 2 1 0 0 0\n\
         $EndEntities\n$Nodes\n1 {n} {} {}\n2 1 0 {n}\n",
        tags.iter().min().unwrap(),
        tags.iter().max().unwrap()
    );
    tags.iter().for_each(|t| s += &format!("{t}\n"));
    coords.iter().for_each(|p| s += &format!("{} {} {}\n", p[0], p[1], p[2]));
    let m = elements.len();
    s += &format!("$EndNodes\n$Elements\n1 {m} 1 {m}\n2 1 3 {m}\n");
    for (k, e) in elements.iter().enumerate() {
        s += &format!("{} {} {} {} {}\n", k + 1, e[0], e[1], e[2], e[3]);
    }
    s + "$EndElements\n"
}

const STRIP: [[f64; 3]; 6] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [2.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [1.0, 1.0, 0.0],
    [2.0, 1.0, 0.0],
];

#[test]
fn an_inverted_tet_is_refused_naming_file_line_and_element() {
    let good = gmsh::parse(tets("1 1 2 3 4\n2 2 3 4 5\n").as_bytes(), "tets.msh").unwrap();
    assert_eq!(good.cells.len(), 2);
    assert!(good.cells.iter().all(|c| c.kind == CellKind::Tet4));
    // element 2 with two nodes swapped
    let e = gmsh::parse(tets("1 1 2 3 4\n2 2 4 3 5\n").as_bytes(), "tets.msh").unwrap_err();
    let msg = e.to_string();
    println!("{msg}");
    assert!(msg.starts_with("tets.msh:26: element 2 (a tetrahedron)"), "{msg}");
    assert!(msg.contains("negative volume") && msg.contains("swap"), "{msg}");
    // a node listed twice
    let flat = tets("1 1 2 3 4\n2 1 2 3 1\n");
    let msg = gmsh::parse(flat.as_bytes(), "tets.msh").unwrap_err().to_string();
    assert!(msg.starts_with("tets.msh:26: element 2") && msg.contains("twice"), "{msg}");
}

#[test]
fn a_bow_tie_quad_is_refused_and_either_winding_reads() {
    let tags = [1, 2, 3, 4, 5, 6];
    // both windings, one quad warped out of plane
    let mut warped = STRIP;
    warped[5][2] = 0.4;
    let ok = quads(&tags, &warped, &[&[1, 2, 5, 4], &[2, 5, 6, 3]]);
    let mesh = gmsh::parse(ok.as_bytes(), "strip.msh").unwrap();
    assert_eq!(mesh.cells.len(), 2);
    let bow_tie = quads(&tags, &STRIP, &[&[1, 2, 5, 4], &[2, 3, 5, 6]]);
    let msg = gmsh::parse(bow_tie.as_bytes(), "strip.msh").unwrap_err().to_string();
    println!("{msg}");
    // elements at lines 27 and 28
    assert!(msg.starts_with("strip.msh:28: element 2 (a quadrilateral) is a bow-tie"), "{msg}");
    let mut line = STRIP;
    line[4] = [1.0, 0.0, 0.0];
    line[3] = [0.0, 0.0, 0.0];
    let zero = quads(&[1, 2, 3, 4, 5, 6], &line, &[&[1, 2, 5, 4]]);
    let msg = gmsh::parse(zero.as_bytes(), "strip.msh").unwrap_err().to_string();
    assert!(msg.contains("element 1") && msg.contains("has zero area"), "{msg}");
}

/// Two unit squares meshed apart: tags 20 and 50, 30 and 80 sit at one position.
fn apart() -> String {
    let tags = [10, 20, 30, 40, 50, 60, 70, 80];
    let coords = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 0.0, 0.0],
        [2.0, 0.0, 0.0],
        [2.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
    ];
    quads(&tags, &coords, &[&[10, 20, 30, 40], &[50, 60, 70, 80]])
}

fn exe() -> Command {
    Command::new(env!("CARGO_BIN_EXE_structure-solver"))
}

/// `structure-solver check` on a case of `mesh` (with `msh` as `m.msh` beside it).
fn check(dir: &Path, mesh: &str, msh: Option<&str>) -> Output {
    if let Some(m) = msh {
        std::fs::write(dir.join("m.msh"), m).unwrap();
    }
    let case = format!(
        "[structure]\nmesh = {mesh}\nmaterial = {{ e = 1e9, nu = 0.3, rho = 1000.0 }}\n\
         thickness = 0.01\nt_end = 1e-3\n"
    );
    let path = dir.join("case.toml");
    std::fs::write(&path, case).unwrap();
    exe().arg("check").arg(&path).output().unwrap()
}

#[test]
fn coincident_nodes_no_element_shares_warn_unless_allowed() {
    let mesh = gmsh::parse(apart().as_bytes(), "apart.msh").unwrap();
    let pairs = coincident_nodes(&mesh);
    let by_tag: Vec<(u64, u64)> =
        pairs.iter().map(|&(a, b)| (mesh.node_id(a), mesh.node_id(b))).collect();
    assert_eq!(by_tag, [(20, 50), (30, 80)]);
    let dir = tempfile::tempdir().unwrap();
    let o = check(dir.path(), "{ generator = \"gmsh\", file = \"m.msh\" }", Some(&apart()));
    let err = String::from_utf8_lossy(&o.stderr);
    println!("{err}");
    assert!(o.status.success(), "{err}");
    assert!(err.contains("warning") && err.contains("2 pair(s)"), "{err}");
    assert!(err.contains("20 and 50") && err.contains("30 and 80"), "{err}");
    assert!(err.contains("coincident_nodes = \"allow\""), "{err}");
    let allowed = "{ generator = \"gmsh\", file = \"m.msh\", coincident_nodes = \"allow\" }";
    let o = check(dir.path(), allowed, None);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(o.stderr.is_empty(), "{}", String::from_utf8_lossy(&o.stderr));
    // a connected mesh has none
    let joined = gmsh::parse(
        quads(&[1, 2, 3, 4, 5, 6], &STRIP, &[&[1, 2, 5, 4], &[2, 3, 6, 5]]).as_bytes(),
        "joined.msh",
    )
    .unwrap();
    assert!(coincident_nodes(&joined).is_empty());
}

#[test]
fn check_refuses_an_inverted_tet_of_the_case_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let o = check(
        dir.path(),
        "{ generator = \"gmsh\", file = \"m.msh\" }",
        Some(&tets("1 1 2 3 4\n2 2 4 3 5\n")),
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(err.contains("case.toml:2:30: field `structure.mesh.file`"), "{err}");
    assert!(err.contains("m.msh:26: element 2 (a tetrahedron) has a negative volume"), "{err}");
}

#[test]
fn generators_refuse_collapsed_cells_and_sizes_the_machine_cannot_hold() {
    let dir = tempfile::tempdir().unwrap();
    // a sphere of one cell from pole to pole: its quadrilaterals collapse to lines
    let o = check(
        dir.path(),
        "{ generator = \"sphere\", radius = 1.0, n_theta = 4, n_phi = 1, phi_deg = [0, 180] }",
        None,
    );
    let err = String::from_utf8_lossy(&o.stderr);
    println!("{err}");
    assert!(!o.status.success());
    assert!(err.contains("field `structure.mesh`: cell (i = 0, j = 0) of the sphere"), "{err}");
    assert!(err.contains("collapses to 2 nodes"), "{err}");
    // 10^14 cells: refused with the estimate before any allocation
    let o = check(
        dir.path(),
        "{ generator = \"rectangle\", lx = 1.0, ly = 1.0, nx = 10000000, ny = 10000000 }",
        None,
    );
    let err = String::from_utf8_lossy(&o.stderr);
    println!("{err}");
    assert!(!o.status.success());
    assert!(err.contains("field `structure.mesh`: the rectangle (1.000e14 nodes"), "{err}");
    assert!(err.contains("needs about") && err.contains("available"), "{err}");
}
