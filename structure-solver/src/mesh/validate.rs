//! The one validity pass every structure mesh goes through, read or generated: finite node
//! coordinates, and no cell that would give a wrong answer that looks right: a tetrahedron of
//! negative or zero volume (gmsh order: `(x1 - x0) · ((x2 - x0) × (x3 - x0)) > 0`), a bow-tie
//! (self-crossing) or zero-area quadrilateral, a zero-area triangle, a zero-length line, or a
//! cell listing a node twice. Shell winding is free (either orientation of a face is fine, and
//! so is a warped quadrilateral whose corners do not cross).
//!
//! Also here: the pairs of nodes at one position that no cell shares ([`coincident_nodes`]),
//! found by a spatial hash ([`close_pairs`], shared with the merge of generated seams).

use std::collections::HashMap;

use super::{Cell, CellKind, Mesh};

/// "Zero" for a cell: a length below this fraction of the mesh's bounding-box diagonal, an area
/// below it times the cell's longest edge squared, a volume below it times its cube.
pub const ZERO: f64 = 1e-10;

/// What is wrong with a cell.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Defect {
    /// The cell lists this node index twice.
    RepeatedNode(usize),
    /// Its nodes all sit at one point (within [`ZERO`] of the mesh size).
    ZeroSize,
    ZeroArea,
    /// A quadrilateral whose edges cross (node order `0 1 3 2` of a convex one).
    BowTie,
    ZeroVolume,
    /// A tetrahedron of negative signed volume (two of its nodes swapped).
    NegativeVolume(f64),
}

/// The first invalid cell of a mesh, or a node with a non-finite coordinate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Invalid {
    Cell { cell: usize, kind: CellKind, defect: Defect },
    Node { node: usize },
}

impl Invalid {
    /// What is wrong, the cell or node named by `what` (e.g. "element 12 (line 40)").
    pub fn describe(&self, what: &str) -> String {
        let Invalid::Cell { kind, defect, .. } = *self else {
            return format!("{what} has a non-finite coordinate");
        };
        let shape = match kind {
            CellKind::Line2 => "line",
            CellKind::Tri3 => "triangle",
            CellKind::Quad4 => "quadrilateral",
            CellKind::Tet4 => "tetrahedron",
        };
        match defect {
            Defect::RepeatedNode(_) => format!("{what} (a {shape}) lists one node twice"),
            Defect::ZeroSize => format!("{what} (a {shape}) has all its nodes at one point"),
            Defect::ZeroArea => format!("{what} (a {shape}) has zero area"),
            Defect::BowTie => format!(
                "{what} (a quadrilateral) is a bow-tie: its edges cross; order its nodes \
                 around its boundary"
            ),
            Defect::ZeroVolume => format!("{what} (a tetrahedron) has zero volume"),
            Defect::NegativeVolume(v) => format!(
                "{what} (a tetrahedron) has a negative volume ({v:.3e}): it is inverted; swap \
                 two of its nodes (gmsh order: (x1 - x0) · ((x2 - x0) × (x3 - x0)) > 0)"
            ),
        }
    }

    /// The cell at fault, if a cell is.
    pub fn cell(&self) -> Option<usize> {
        match self {
            Invalid::Cell { cell, .. } => Some(*cell),
            Invalid::Node { .. } => None,
        }
    }
}

/// The diagonal of the bounding box of `nodes` (0 for none).
pub fn diagonal(nodes: &[[f64; 3]]) -> f64 {
    let (lo, hi) =
        nodes.iter().fold(([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]), |(lo, hi), p| {
            (std::array::from_fn(|k| lo[k].min(p[k])), std::array::from_fn(|k| hi[k].max(p[k])))
        });
    let d = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
    if d.is_finite() {
        d
    } else {
        0.0
    }
}

/// The first invalid node or cell of `mesh`, in index order.
pub fn check(mesh: &Mesh) -> Result<(), Invalid> {
    if let Some(node) = mesh.nodes.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
        return Err(Invalid::Node { node });
    }
    let size = diagonal(&mesh.nodes);
    for (c, cell) in mesh.cells.iter().enumerate() {
        if let Some(defect) = cell_defect(&mesh.nodes, cell, size) {
            return Err(Invalid::Cell { cell: c, kind: cell.kind, defect });
        }
    }
    Ok(())
}

type V = [f64; 3];

fn sub(a: V, b: V) -> V {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: V, b: V) -> V {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

fn dot(a: V, b: V) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn norm(a: V) -> f64 {
    dot(a, a).sqrt()
}

/// What is wrong with `cell` of a mesh of bounding-box diagonal `size`, if anything.
fn cell_defect(nodes: &[V], cell: &Cell, size: f64) -> Option<Defect> {
    let ids = &cell.nodes;
    for (k, &n) in ids.iter().enumerate() {
        if ids[..k].contains(&n) {
            return Some(Defect::RepeatedNode(n));
        }
    }
    let x: Vec<V> = ids.iter().map(|&n| nodes[n]).collect();
    let longest = (0..x.len())
        .flat_map(|a| (a + 1..x.len()).map(move |b| (a, b)))
        .map(|(a, b)| norm(sub(x[b], x[a])))
        .fold(0.0, f64::max);
    if longest <= ZERO * size {
        return Some(Defect::ZeroSize);
    }
    let area_tol = ZERO * longest * longest;
    match cell.kind {
        CellKind::Line2 => None,
        CellKind::Tri3 => {
            let a = 0.5 * norm(cross(sub(x[1], x[0]), sub(x[2], x[0])));
            (a <= area_tol).then_some(Defect::ZeroArea)
        }
        CellKind::Quad4 => {
            // Corner normals (next edge × previous edge): a bow-tie flips both opposite pairs.
            let corner = |i: usize| cross(sub(x[(i + 1) % 4], x[i]), sub(x[(i + 3) % 4], x[i]));
            let n: [V; 4] = std::array::from_fn(corner);
            if dot(n[0], n[2]) < 0.0 && dot(n[1], n[3]) < 0.0 {
                return Some(Defect::BowTie);
            }
            let a = 0.5 * norm(cross(sub(x[2], x[0]), sub(x[3], x[1])));
            (a <= area_tol).then_some(Defect::ZeroArea)
        }
        CellKind::Tet4 => {
            let v = dot(sub(x[1], x[0]), cross(sub(x[2], x[0]), sub(x[3], x[0]))) / 6.0;
            let tol = ZERO * longest.powi(3);
            if v < -tol {
                Some(Defect::NegativeVolume(v))
            } else if v <= tol {
                Some(Defect::ZeroVolume)
            } else {
                None
            }
        }
    }
}

/// The pairs `(a, b)`, `a < b`, of nodes closer than `tol`, sorted; a hash of cells of size
/// `tol` looks at the 27 cells around each node, so the cost grows with the node count.
pub fn close_pairs(nodes: &[V], tol: f64) -> Vec<(usize, usize)> {
    if !(tol > 0.0 && tol.is_finite()) {
        return Vec::new();
    }
    let key = |p: &V| p.map(|c| (c / tol).floor() as i64);
    let mut grid: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
    let mut pairs = Vec::new();
    for (b, p) in nodes.iter().enumerate() {
        let k = key(p);
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let q = [k[0] + dx, k[1] + dy, k[2] + dz];
                    for &a in grid.get(&q).into_iter().flatten() {
                        if norm(sub(nodes[a], *p)) <= tol {
                            pairs.push((a, b));
                        }
                    }
                }
            }
        }
        grid.entry(k).or_default().push(b);
    }
    pairs.sort_unstable();
    pairs
}

/// The pairs of distinct nodes at one position (within [`ZERO`] of the bounding-box diagonal)
/// that no cell holds both of: where a mesh falls apart unintentionally (two surfaces meshed
/// apart), or on purpose (a notch). Sorted by node index.
pub fn coincident_nodes(mesh: &Mesh) -> Vec<(usize, usize)> {
    let pairs = close_pairs(&mesh.nodes, ZERO * diagonal(&mesh.nodes));
    if pairs.is_empty() {
        return pairs;
    }
    let mut in_pair = vec![false; mesh.nodes.len()];
    pairs.iter().for_each(|&(a, b)| (in_pair[a], in_pair[b]) = (true, true));
    let mut shared = std::collections::HashSet::new();
    for cell in &mesh.cells {
        for (k, &a) in cell.nodes.iter().enumerate() {
            for &b in &cell.nodes[k + 1..] {
                if in_pair[a] && in_pair[b] {
                    shared.insert((a.min(b), a.max(b)));
                }
            }
        }
    }
    pairs.into_iter().filter(|p| !shared.contains(p)).collect()
}

/// A warning naming the first few of `pairs` by user node id, and their count.
pub fn coincident_warning(mesh: &Mesh, pairs: &[(usize, usize)]) -> String {
    const SHOWN: usize = 5;
    let shown: Vec<String> = pairs
        .iter()
        .take(SHOWN)
        .map(|&(a, b)| format!("{} and {}", mesh.node_id(a), mesh.node_id(b)))
        .collect();
    let more = if pairs.len() > SHOWN { ", ..." } else { "" };
    format!(
        "{} pair(s) of nodes share a position but no element: {}{more}; the mesh is not \
         connected there",
        pairs.len(),
        shown.join(", ")
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mesh(nodes: Vec<V>, kind: CellKind, cells: &[&[usize]]) -> Mesh {
        let cells = cells.iter().map(|c| Cell { kind, nodes: c.to_vec() }).collect();
        Mesh { nodes, cells, ..Mesh::default() }
    }

    fn defect(m: &Mesh) -> Option<Defect> {
        match check(m) {
            Ok(()) => None,
            Err(Invalid::Cell { defect, .. }) => Some(defect),
            Err(e) => panic!("{e:?}"),
        }
    }

    const TET: [V; 4] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

    #[test]
    fn tets_must_have_positive_volume() {
        let m = mesh(TET.to_vec(), CellKind::Tet4, &[&[0, 1, 2, 3]]);
        assert_eq!(defect(&m), None);
        let swapped = mesh(TET.to_vec(), CellKind::Tet4, &[&[0, 2, 1, 3]]);
        assert!(matches!(defect(&swapped), Some(Defect::NegativeVolume(v)) if v < 0.0));
        let mut flat = TET.to_vec();
        flat[3] = [0.3, 0.3, 0.0];
        assert_eq!(defect(&mesh(flat, CellKind::Tet4, &[&[0, 1, 2, 3]])), Some(Defect::ZeroVolume));
        let twice = mesh(TET.to_vec(), CellKind::Tet4, &[&[0, 1, 2, 1]]);
        assert_eq!(defect(&twice), Some(Defect::RepeatedNode(1)));
    }

    #[test]
    fn quads_may_wind_either_way_and_warp_but_not_cross() {
        let square = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
        for order in [[0, 1, 2, 3], [0, 3, 2, 1], [2, 3, 0, 1]] {
            assert_eq!(defect(&mesh(square.clone(), CellKind::Quad4, &[&order])), None);
        }
        for order in [[0, 1, 3, 2], [0, 2, 1, 3], [1, 0, 2, 3]] {
            let m = mesh(square.clone(), CellKind::Quad4, &[&order]);
            assert_eq!(defect(&m), Some(Defect::BowTie), "{order:?}");
        }
        let mut warped = square.clone();
        warped[2][2] = 2.0;
        assert_eq!(defect(&mesh(warped, CellKind::Quad4, &[&[0, 1, 2, 3]])), None);
        let line = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [3.0, 0.0, 0.0]];
        assert_eq!(defect(&mesh(line, CellKind::Quad4, &[&[0, 1, 2, 3]])), Some(Defect::ZeroArea));
    }

    #[test]
    fn triangles_lines_and_nodes() {
        let pts = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        assert_eq!(defect(&mesh(pts.clone(), CellKind::Tri3, &[&[0, 1, 3]])), None);
        assert_eq!(
            defect(&mesh(pts.clone(), CellKind::Tri3, &[&[0, 1, 2]])),
            Some(Defect::ZeroArea)
        );
        let mut same = pts.clone();
        same[1] = same[0];
        let m = mesh(same, CellKind::Line2, &[&[2, 3], &[0, 1]]);
        assert_eq!(check(&m).unwrap_err().cell(), Some(1));
        let mut nan = pts;
        nan[2][1] = f64::NAN;
        assert_eq!(check(&mesh(nan, CellKind::Tri3, &[])), Err(Invalid::Node { node: 2 }));
    }

    #[test]
    fn coincident_nodes_outside_a_shared_cell_are_found() {
        // two unit squares side by side, meshed apart: nodes 1, 2 and 4, 5 coincide
        let nodes = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
            [1.0, 1.0, 1e-14],
            [2.0, 0.0, 0.0],
            [2.0, 1.0, 0.0],
        ];
        let m = mesh(nodes, CellKind::Quad4, &[&[0, 1, 4, 3], &[2, 6, 7, 5]]);
        assert_eq!(coincident_nodes(&m), vec![(1, 2), (4, 5)]);
        let w = coincident_warning(&m, &coincident_nodes(&m));
        assert!(
            w.starts_with("2 pair(s)") && w.contains("1 and 2") && w.contains("4 and 5"),
            "{w}"
        );
        assert_eq!(close_pairs(&m.nodes, 0.5), vec![(1, 2), (4, 5)]);
    }
}
