//! The gmsh 4.1 reader: a mesh written in the `.msh` 4.1 ASCII format (sparse node tags, physical
//! groups naming the boundary surfaces, mixed cell blocks) reads back into the same dual mesh.

use fluid_solver::mesh::boxmesh::{BoxCells, BoxSpec};
use fluid_solver::mesh::{gmsh, CellKind, Mesh, RawMesh};
use std::fmt::Write;

/// Writes `raw` as gmsh 4.1 ASCII: node tags `10 + 3k` (sparse), one surface entity and physical
/// group per boundary, one volume entity; cells in one block per kind.
fn to_msh(raw: &RawMesh) -> String {
    let tag = |k: u32| 10 + 3 * k as u64;
    let mut s = String::from("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n");
    writeln!(s, "{}", raw.patch_names.len() + 1).unwrap();
    for (k, n) in raw.patch_names.iter().enumerate() {
        writeln!(s, "2 {} \"{n}\"", k + 1).unwrap();
    }
    writeln!(s, "3 100 \"fluid\"\n$EndPhysicalNames\n$Entities\n0 0 {} 1", raw.patch_names.len())
        .unwrap();
    for k in 0..raw.patch_names.len() {
        writeln!(s, "{} 0 0 0 1 1 1 1 {} 0", k + 1, k + 1).unwrap();
    }
    writeln!(s, "1 0 0 0 1 1 1 1 100 0\n$EndEntities\n$Nodes").unwrap();
    let n = raw.coords.len() as u32;
    writeln!(s, "1 {n} {} {}\n3 1 0 {n}", tag(0), tag(n - 1)).unwrap();
    for k in 0..n {
        writeln!(s, "{}", tag(k)).unwrap();
    }
    for c in &raw.coords {
        writeln!(s, "{} {} {}", c[0], c[1], c[2]).unwrap();
    }
    s.push_str("$EndNodes\n$Elements\n");
    let mut blocks: Vec<(i32, i32, u32, Vec<Vec<u32>>)> = Vec::new();
    for (k, _) in raw.patch_names.iter().enumerate() {
        let faces: Vec<Vec<u32>> =
            raw.faces.iter().filter(|f| f.patch as usize == k).map(|f| f.nodes.clone()).collect();
        for len in [3, 4] {
            let these: Vec<Vec<u32>> = faces.iter().filter(|f| f.len() == len).cloned().collect();
            if !these.is_empty() {
                blocks.push((2, k as i32 + 1, if len == 3 { 2 } else { 3 }, these));
            }
        }
    }
    for (kind, code) in [(CellKind::Tet, 4), (CellKind::Hex, 5)] {
        let cells: Vec<Vec<u32>> =
            raw.cells.iter().filter(|c| c.kind == kind).map(|c| c.nodes().to_vec()).collect();
        if !cells.is_empty() {
            blocks.push((3, 1, code, cells));
        }
    }
    let total: usize = blocks.iter().map(|b| b.3.len()).sum();
    writeln!(s, "{} {total} 1 {total}", blocks.len()).unwrap();
    let mut id = 1;
    for (dim, entity, code, elems) in &blocks {
        writeln!(s, "{dim} {entity} {code} {}", elems.len()).unwrap();
        for e in elems {
            write!(s, "{id}").unwrap();
            for &v in e {
                write!(s, " {}", tag(v)).unwrap();
            }
            s.push('\n');
            id += 1;
        }
    }
    s.push_str("$EndElements\n");
    s
}

#[test]
fn gmsh_files_read_back_into_the_same_dual_mesh() {
    let dir = tempfile::tempdir().unwrap();
    for shape in [BoxCells::Tet, BoxCells::Hex] {
        let raw = BoxSpec::uniform([0.0; 3], [1.0, 2.0, 0.5], [3, 4, 2], shape).raw().unwrap();
        let path = dir.path().join("box.msh");
        std::fs::write(&path, to_msh(&raw)).unwrap();
        let read = gmsh::read(&path).unwrap();
        assert_eq!(read.patch_names, raw.patch_names);
        let a = Mesh::build(raw).unwrap();
        let b = Mesh::build(read).unwrap();
        assert_eq!(a.n_edges(), b.n_edges());
        assert!((b.total_volume() - 1.0).abs() < 1e-12);
        for name in a.boundary_names() {
            let (ba, bb) = (a.boundary(&name).unwrap(), b.boundary(&name).unwrap());
            let sum = |bd: &fluid_solver::mesh::Boundary| {
                bd.normals.iter().fold([0.0; 3], |s, n| [s[0] + n[0], s[1] + n[1], s[2] + n[2]])
            };
            let (sa, sb) = (sum(ba), sum(bb));
            assert!((0..3).all(|k| (sa[k] - sb[k]).abs() < 1e-12), "{name}: {sa:?} vs {sb:?}");
        }
    }
}

#[test]
fn gmsh_errors_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.msh");
    std::fs::write(&path, "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n").unwrap();
    let e = gmsh::read(&path).unwrap_err().to_string();
    assert!(e.contains("bad.msh") && e.contains("4.1"), "{e}");
    // A boundary surface without a physical group leaves dual cells open: named in the error.
    let mut raw = BoxSpec::uniform([0.0; 3], [1.0; 3], [2, 2, 2], BoxCells::Tet).raw().unwrap();
    raw.faces.retain(|f| f.patch != 3);
    raw.patch_names.truncate(6);
    std::fs::write(&path, to_msh(&raw)).unwrap();
    let e = Mesh::build(gmsh::read(&path).unwrap()).unwrap_err().to_string();
    assert!(e.contains("not closed") && e.contains("physical group"), "{e}");
    let e = gmsh::read(&dir.path().join("missing.msh")).unwrap_err().to_string();
    assert!(e.contains("missing.msh") && e.contains("cannot read"), "{e}");
}
