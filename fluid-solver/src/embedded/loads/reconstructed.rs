//! Alg. 5.3 (thesis Eq. 5.12-5.19) on the interface reconstructed by Alg. 5.2: in every cut cell
//! the polygon through the intersection points of its cut edges (one point per cut edge, so the
//! polygons of two cells sharing a face share its segment and the interface is watertight).
//!
//! Polygons are ordered by walking the cell's faces: a face with two cut edges gives the segment
//! between their points; a face with four (an ambiguous quad face, its diagonal corners on the
//! same side) pairs the two cut edges at its lowest-numbered node and the other two (one fixed
//! rule on global numbers, so both cells of the face agree); the segments are chained into
//! cycles. A cell whose faces do not close into cycles (odd counts: the rim of an open surface, a
//! cell holding a surface corner) orders its points by angle about their centroid. Each polygon
//! faces from the `-` to the `+` ends of its cut edges and is cut into triangles (one, or a fan
//! about its centroid), each with its own normal.
//!
//! On each triangle the load density is `q n̂`, `q = p*_- - p*_+` interpolated linearly from the
//! points (`+` the end of the cut edge on the side `n_E` points to), integrated with the
//! 3-point degree-2 rule; each Gauss point's force goes to the structure triangle nearest to it
//! (closest-point projection onto the triangles hit by the cell's cut edges) with that triangle's
//! shape functions at the projection (Eq. 5.18). The resultant is `Σ ∫ q n̂` exactly (Eq. 5.19).

use super::{distribute, or_zero, LoadView};
use crate::mesh::geometry::{add, cross, dot, norm, scale, sub};
use crate::mesh::Cell;

/// One vertex of a reconstructed polygon: the intersection point, its load density `q` and the
/// cut it comes from.
#[derive(Clone, Copy)]
struct Vertex {
    x: [f64; 3],
    q: f64,
    /// Unit vector along the cut edge from its `-` end to its `+` end.
    across: [f64; 3],
}

pub(super) fn loads(view: &LoadView, out: &mut [[f64; 3]]) {
    gauss_loads(view, |_, f, tri, bary| distribute(view.surface, tri, bary, f, out));
}

/// Calls `sink(x, f, triangle, bary)` for every Gauss point `x` of the reconstructed interface
/// with its force `f` on the structure and the structure triangle and barycentric coordinates of
/// its projection. Only the cells around the cut edges are visited, in ascending order.
pub(super) fn gauss_loads(view: &LoadView, sink: impl FnMut([f64; 3], [f64; 3], u32, [f64; 3])) {
    gauss_loads_in(view, &cut_cells(view), sink);
}

/// The cells holding both ends of some cut edge, ascending: every cell with a cut edge, so every
/// cell that can hold a polygon.
pub(super) fn cut_cells(view: &LoadView) -> Vec<u32> {
    let mut cells = Vec::with_capacity(8 * view.cuts.len());
    for c in view.cuts {
        let [i, j] = view.mesh.edges[c.edge as usize];
        let around = view.adjacency.cells_of(i as usize);
        cells.extend(around.iter().filter(|&&k| view.mesh.cells[k as usize].nodes().contains(&j)));
    }
    cells.sort_unstable();
    cells.dedup();
    cells
}

/// [`gauss_loads`] over the given `cells` (ascending), which must include every cut cell.
pub(super) fn gauss_loads_in(
    view: &LoadView,
    cells: &[u32],
    mut sink: impl FnMut([f64; 3], [f64; 3], u32, [f64; 3]),
) {
    let mut polygon = Vec::with_capacity(12);
    for &k in cells {
        let cell = &view.mesh.cells[k as usize];
        let cut_of = cell_cuts(view, cell);
        if cut_of.iter().flatten().count() < 3 {
            continue;
        }
        for (cycle, walked) in cycles(cell, &cut_of) {
            polygon.clear();
            polygon.extend(cycle.iter().map(|&k| vertex(view, k)));
            orient(&mut polygon, walked);
            integrate(view, &cycle, &polygon, &mut sink);
        }
    }
}

/// For each local edge of `cell`, the index of its cut edge, if it is cut and its ends lie on
/// different sides (an edge whose ends share a side crosses the surface twice; one point cannot
/// stand for it, and every cell around it leaves it out alike, which keeps the interface closed).
fn cell_cuts(view: &LoadView, cell: &Cell) -> [Option<usize>; 12] {
    let mut cut_of = [None; 12];
    for (l, &[a, b]) in cell.kind.edges().iter().enumerate() {
        let (p, q) = (cell.nodes[a], cell.nodes[b]);
        if view.side[p as usize] == view.side[q as usize] {
            continue;
        }
        let key = [p.min(q), p.max(q)];
        if let Ok(e) = view.mesh.edges.binary_search(&key) {
            cut_of[l] = view.cuts.binary_search_by_key(&(e as u32), |c| c.edge).ok();
        }
    }
    cut_of
}

/// The local edge of `cell` joining local nodes `a` and `b`.
fn local_edge(cell: &Cell, a: usize, b: usize) -> usize {
    let edges = cell.kind.edges();
    edges.iter().position(|&[p, q]| (p, q) == (a, b) || (p, q) == (b, a)).expect("a face edge")
}

/// The polygons of a cut cell as cycles of cut-edge indices, and whether they come from the face
/// walk (`false`: the unordered points of a cell whose faces do not close; see the module docs).
fn cycles(cell: &Cell, cut_of: &[Option<usize>; 12]) -> Vec<(Vec<usize>, bool)> {
    // Neighbours of each local edge along the polygon, through the faces.
    let mut next: [[usize; 2]; 12] = [[usize::MAX; 2]; 12];
    let mut degree = [0usize; 12];
    let mut closed = true;
    for face in cell.kind.faces() {
        let n = face.len();
        let mut on_face = [0usize; 4];
        let mut m = 0;
        for k in 0..n {
            let l = local_edge(cell, face[k], face[(k + 1) % n]);
            if cut_of[l].is_some() {
                on_face[m] = l;
                m += 1;
            }
        }
        if m % 2 == 1 {
            closed = false;
        }
        if m == 4 {
            // Ambiguous face: edge k joins face nodes k and k + 1; cut off the lowest-numbered
            // node, i.e. pair its edges k0 - 1 and k0.
            let k0 = (0..4).min_by_key(|&k| cell.nodes[face[k]]).expect("four nodes");
            on_face = [0, 1, 2, 3].map(|r| on_face[(k0 + 3 + r) % 4]);
        }
        for pair in on_face[..m - m % 2].chunks(2) {
            for (a, b) in [(pair[0], pair[1]), (pair[1], pair[0])] {
                if degree[a] < 2 {
                    next[a][degree[a]] = b;
                }
                degree[a] += 1;
            }
        }
    }
    let cut_edges: Vec<usize> = (0..12).filter(|&l| cut_of[l].is_some()).collect();
    closed &= cut_edges.iter().all(|&l| degree[l] == 2);
    if !closed {
        return vec![(cut_edges.iter().map(|&l| cut_of[l].expect("cut")).collect(), false)];
    }
    let mut seen = [false; 12];
    let mut out = Vec::new();
    for &start in &cut_edges {
        if seen[start] {
            continue;
        }
        let mut cycle = vec![];
        let (mut prev, mut cur) = (usize::MAX, start);
        while !seen[cur] {
            seen[cur] = true;
            cycle.push(cut_of[cur].expect("cut"));
            let step = if next[cur][0] != prev { next[cur][0] } else { next[cur][1] };
            (prev, cur) = (cur, step);
        }
        if cycle.len() >= 3 {
            out.push((cycle, true));
        }
    }
    out
}

/// The polygon vertex of cut `k`: its intersection point and `q = p*_- - p*_+`.
fn vertex(view: &LoadView, k: usize) -> Vertex {
    let cut = &view.cuts[k];
    let [i, j] = view.mesh.edges[cut.edge as usize];
    let (xi, xj) = (view.mesh.coords[i as usize], view.mesh.coords[j as usize]);
    let d = sub(xj, xi);
    let [pi, pj] = view.p_star[k].map(or_zero);
    // The `+` end is the one n_E points to.
    let (q, s) = if dot(cut.normal, d) > 0.0 { (pi - pj, 1.0) } else { (pj - pi, -1.0) };
    Vertex { x: add(xi, scale(d, cut.alpha)), q, across: scale(d, s / norm(d)) }
}

/// Orders the vertices of a polygon that did not come from the face walk by angle about their
/// centroid, then turns the polygon to face from the `-` ends of its cut edges to their `+` ends
/// (the sum of the unit edge vectors: unlike the mean `n_E`, never misleading where the polygon
/// spans a sharp edge of the surface).
fn orient(poly: &mut [Vertex], walked: bool) {
    let n_mean = poly.iter().fold([0.0; 3], |s, v| add(s, v.across));
    if !walked {
        let c = centroid(poly);
        // Angle about the centroid in the plane normal to the mean surface normal.
        let e1 = any_perpendicular(n_mean);
        let e2 = cross(n_mean, e1);
        poly.sort_by(|a, b| {
            let (da, db) = (sub(a.x, c), sub(b.x, c));
            let ta = dot(da, e2).atan2(dot(da, e1));
            let tb = dot(db, e2).atan2(dot(db, e1));
            ta.total_cmp(&tb)
        });
    }
    if dot(newell(poly), n_mean) < 0.0 {
        poly.reverse();
    }
}

fn centroid(poly: &[Vertex]) -> [f64; 3] {
    let s = poly.iter().fold([0.0; 3], |s, v| add(s, v.x));
    scale(s, 1.0 / poly.len() as f64)
}

/// Newell's area vector (twice the area times the unit normal) of a closed polygon.
fn newell(poly: &[Vertex]) -> [f64; 3] {
    let m = poly.len();
    (0..m).fold([0.0; 3], |s, k| add(s, cross(poly[k].x, poly[(k + 1) % m].x)))
}

fn any_perpendicular(n: [f64; 3]) -> [f64; 3] {
    let a = if n[0].abs() < 0.6 { [1.0, 0.0, 0.0] } else { [0.0, 1.0, 0.0] };
    let p = cross(n, a);
    scale(p, 1.0 / norm(p))
}

/// Degree-2 rule on a triangle: barycentric points, weight 1/3 each.
const GAUSS: [[f64; 3]; 3] = [
    [2.0 / 3.0, 1.0 / 6.0, 1.0 / 6.0],
    [1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0],
    [1.0 / 6.0, 1.0 / 6.0, 2.0 / 3.0],
];

/// Integrates `q n̂` over the triangles of an oriented polygon into `sink`.
fn integrate(
    view: &LoadView,
    cycle: &[usize],
    poly: &[Vertex],
    sink: &mut impl FnMut([f64; 3], [f64; 3], u32, [f64; 3]),
) {
    let mut candidates: Vec<u32> = cycle.iter().map(|&k| view.cuts[k].triangle).collect();
    candidates.sort_unstable();
    candidates.dedup();
    let corners: Vec<[[f64; 3]; 3]> =
        candidates.iter().map(|&t| view.surface.triangle_at(t as usize, view.t).0).collect();
    let mut triangle = |a: ([f64; 3], f64), b: ([f64; 3], f64), c: ([f64; 3], f64)| {
        let area = scale(cross(sub(b.0, a.0), sub(c.0, a.0)), 0.5);
        for g in GAUSS {
            let x = add(add(scale(a.0, g[0]), scale(b.0, g[1])), scale(c.0, g[2]));
            let q = g[0] * a.1 + g[1] * b.1 + g[2] * c.1;
            let (k, bary) = nearest(&corners, x);
            sink(x, scale(area, q / 3.0), candidates[k], bary);
        }
    };
    let p = |v: &Vertex| (v.x, v.q);
    if poly.len() == 3 {
        triangle(p(&poly[0]), p(&poly[1]), p(&poly[2]));
    } else {
        let c = (centroid(poly), poly.iter().map(|v| v.q).sum::<f64>() / poly.len() as f64);
        for k in 0..poly.len() {
            triangle(c, p(&poly[k]), p(&poly[(k + 1) % poly.len()]));
        }
    }
}

/// The candidate triangle nearest to `x` and the barycentric coordinates of the closest point.
fn nearest(corners: &[[[f64; 3]; 3]], x: [f64; 3]) -> (usize, [f64; 3]) {
    let mut best = (0, [1.0, 0.0, 0.0], f64::INFINITY);
    for (k, t) in corners.iter().enumerate() {
        let bary = closest_point(x, t);
        let y = add(add(scale(t[0], bary[0]), scale(t[1], bary[1])), scale(t[2], bary[2]));
        let d = norm(sub(x, y));
        if d < best.2 {
            best = (k, bary, d);
        }
    }
    (best.0, best.1)
}

/// Barycentric coordinates of the point of triangle `t` closest to `p` (Ericson, *Real-Time
/// Collision Detection* §5.1.5).
fn closest_point(p: [f64; 3], t: &[[f64; 3]; 3]) -> [f64; 3] {
    let (a, b, c) = (t[0], t[1], t[2]);
    let (ab, ac, ap) = (sub(b, a), sub(c, a), sub(p, a));
    let (d1, d2) = (dot(ab, ap), dot(ac, ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return [1.0, 0.0, 0.0];
    }
    let bp = sub(p, b);
    let (d3, d4) = (dot(ab, bp), dot(ac, bp));
    if d3 >= 0.0 && d4 <= d3 {
        return [0.0, 1.0, 0.0];
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return [1.0 - v, v, 0.0];
    }
    let cp = sub(p, c);
    let (d5, d6) = (dot(ab, cp), dot(ac, cp));
    if d6 >= 0.0 && d5 <= d6 {
        return [0.0, 0.0, 1.0];
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return [1.0 - w, 0.0, w];
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return [0.0, 1.0 - w, w];
    }
    let denom = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denom, vc * denom);
    [1.0 - v - w, v, w]
}
