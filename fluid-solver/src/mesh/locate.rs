//! Point location: which of a few points (probes, line samples) lie inside the mesh, that is in
//! one of its cells (a bounding-box test alone would accept points in the holes and notches of
//! a non-convex mesh).
//!
//! One pass over the cells, each tested only against the points within its bounding box (the
//! points sorted along their widest axis), so locating `P` points costs `O(cells log P)` plus
//! the few exact tests. A cell is the union of the tets of its median-dual decomposition: its
//! centroid, a face centroid and a face edge (a tet is itself), the same decomposition for a
//! face seen from both of its cells, so the cells tile the domain without gaps even when their
//! quad faces are not planar. Points on a face, an edge or a node count as inside.

use super::geometry::{centroid, cross, dot, norm, sub};
use super::{Cell, CellKind, Mesh};

/// Relative barycentric slack: a point this far outside a face (in units of the tet) is on it.
const TOLERANCE: f64 = 1e-9;

/// For each point, whether a cell of `mesh` holds it.
pub fn inside(mesh: &Mesh, points: &[[f64; 3]]) -> Vec<bool> {
    let mut found = vec![false; points.len()];
    if points.is_empty() {
        return found;
    }
    let axis = widest_axis(points);
    let mut order: Vec<usize> = (0..points.len()).collect();
    order.sort_by(|&a, &b| points[a][axis].total_cmp(&points[b][axis]));
    let keys: Vec<f64> = order.iter().map(|&k| points[k][axis]).collect();
    let mut left = points.len();
    for cell in &mesh.cells {
        let (lo, hi) = cell_box(cell, &mesh.coords);
        let start = keys.partition_point(|&x| x < lo[axis]);
        let end = keys.partition_point(|&x| x <= hi[axis]);
        for &k in &order[start..end] {
            let x = points[k];
            if !found[k] && (0..3).all(|d| x[d] >= lo[d] && x[d] <= hi[d]) && holds(cell, mesh, x) {
                found[k] = true;
                left -= 1;
            }
        }
        if left == 0 {
            break;
        }
    }
    found
}

/// The axis along which the points spread most.
fn widest_axis(points: &[[f64; 3]]) -> usize {
    let spread = |d: usize| {
        let (lo, hi) = points
            .iter()
            .filter(|p| p[d].is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| (lo.min(p[d]), hi.max(p[d])));
        hi - lo
    };
    (0..3).max_by(|&a, &b| spread(a).total_cmp(&spread(b))).unwrap_or(0)
}

/// The bounding box of a cell, padded by the tolerance.
fn cell_box(cell: &Cell, coords: &[[f64; 3]]) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for &v in cell.nodes() {
        let p = coords[v as usize];
        for d in 0..3 {
            lo[d] = lo[d].min(p[d]);
            hi[d] = hi[d].max(p[d]);
        }
    }
    let pad = TOLERANCE * norm(sub(hi, lo));
    (lo.map(|v| v - pad), hi.map(|v| v + pad))
}

/// Whether `cell` holds `x` (see the module docs).
fn holds(cell: &Cell, mesh: &Mesh, x: [f64; 3]) -> bool {
    let p = |l: usize| mesh.coords[cell.nodes[l] as usize];
    if cell.kind == CellKind::Tet {
        return in_tet([p(0), p(1), p(2), p(3)], x);
    }
    let g = centroid((0..cell.kind.n_nodes()).map(p));
    cell.kind.faces().iter().any(|face| {
        let fc = centroid(face.iter().map(|&l| p(l)));
        (0..face.len()).any(|q| in_tet([g, fc, p(face[q]), p(face[(q + 1) % face.len()])], x))
    })
}

/// Six times the signed volume of the tet `a, b, c, d`.
fn orient(a: [f64; 3], b: [f64; 3], c: [f64; 3], d: [f64; 3]) -> f64 {
    dot(cross(sub(b, a), sub(c, a)), sub(d, a))
}

/// Whether `x` is in the tet `t` (its barycentric coordinates all at least `-TOLERANCE`).
fn in_tet(t: [[f64; 3]; 4], x: [f64; 3]) -> bool {
    let v = orient(t[0], t[1], t[2], t[3]);
    if v == 0.0 || !v.is_finite() {
        return false;
    }
    (0..4).all(|k| {
        let mut s = t;
        s[k] = x;
        orient(s[0], s[1], s[2], s[3]) / v >= -TOLERANCE
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::boxmesh::{BoxCells, BoxSpec};

    #[test]
    fn finds_points_in_the_cells_and_on_the_boundary_only() {
        for shape in [BoxCells::Hex, BoxCells::Tet] {
            let spec = BoxSpec::uniform([0.0; 3], [1.0, 0.5, 0.25], [4, 3, 2], shape);
            let mesh = Mesh::build(spec.raw().unwrap()).unwrap();
            let points = [
                [0.5, 0.25, 0.125],
                [0.0, 0.0, 0.0],
                [1.0, 0.5, 0.25],
                [0.3, 0.0, 0.1],
                [1.0 + 1e-6, 0.2, 0.1],
                [0.5, -0.01, 0.1],
                [9.0, 0.0, 0.0],
                [f64::NAN, 0.0, 0.0],
            ];
            let found = inside(&mesh, &points);
            assert_eq!(found, [true, true, true, true, false, false, false, false], "{shape:?}");
        }
    }

    #[test]
    fn a_point_in_a_notch_is_outside_though_inside_the_bounding_box() {
        // An L of three hexes: the fourth quarter of the square is missing.
        let spec = BoxSpec::uniform([0.0; 3], [2.0, 2.0, 1.0], [2, 2, 1], BoxCells::Hex);
        let mut raw = spec.raw().unwrap();
        let x = |v: u32| raw.coords[v as usize];
        let notch = raw
            .cells
            .iter()
            .position(|c| c.nodes().iter().all(|&v| x(v)[0] >= 1.0 && x(v)[1] >= 1.0));
        let cell = raw.cells.remove(notch.unwrap());
        // The box faces of the removed hex go; its faces towards the other hexes become boundary.
        raw.faces.retain(|f| !f.nodes.iter().all(|v| cell.nodes().contains(v)));
        for lf in cell.kind.faces() {
            let nodes: Vec<u32> = lf.iter().rev().map(|&l| cell.nodes[l]).collect();
            if (0..2).any(|d| nodes.iter().all(|&v| x(v)[d] == 1.0)) {
                raw.faces.push(crate::mesh::TaggedFace { patch: 0, nodes });
            }
        }
        let mesh = Mesh::build(raw).unwrap();
        let (lo, hi) = mesh.bounding_box();
        assert_eq!((lo, hi), ([0.0; 3], [2.0, 2.0, 1.0]));
        let found = inside(&mesh, &[[1.5, 1.5, 0.5], [0.5, 1.5, 0.5], [1.5, 0.5, 0.5]]);
        assert_eq!(found, [false, true, true]);
    }
}
