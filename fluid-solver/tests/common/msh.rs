//! A mesh written as gmsh 4.1 ASCII, for tests that need a mesh file the box mesher cannot make.

use fluid_solver::mesh::{CellKind, RawMesh};
use std::fmt::Write;

/// Writes `raw` as gmsh 4.1 ASCII: node tags `10 + 3k` (sparse), one surface entity and physical
/// group per boundary, one volume entity; cells in one block per kind.
pub fn to_msh(raw: &RawMesh) -> String {
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
