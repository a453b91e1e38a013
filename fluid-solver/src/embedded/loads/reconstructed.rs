//! Alg. 5.3 (thesis Eq. 5.12-5.19) on the interface reconstructed by Alg. 5.2: in every cut cell
//! the polygon through the intersection points of its cut edges (one point per cut edge, so the
//! polygons of two cells sharing a face share its segment and the interface is watertight).
//!
//! Which cut edges join it ([`joining_cuts`]): those whose ends lie on different sides of the
//! flood fill (an edge whose ends share a side there crosses the surface twice; one point cannot
//! stand for it, and every cell around it leaves it out alike, which keeps the interface closed);
//! and on a one-fluid shell (an open connected part of the surface whose cut edges reach a single
//! fluid side: both its faces face one connected fluid, as a plate with free edges does) every cut
//! edge, its ends' sides being those of the orientation contract (PROTOCOL.md: the `+` end is the
//! one `n_E` points to, [`wall_normal_from_i`]). An edge crossing such a shell twice keeps its
//! crossing nearest to its node `i`.
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
//! points. Eq. 5.18: the force of vertex `I_k` is `F_k = ∫ q N̂_k n̂` (exact: the rows of the P1
//! mass matrix), and it goes to the structure with the shape functions of the structure triangle
//! hit by `I_k`'s cut edge at `I_k` (`N_i^q(ξ_k)`, the cut's barycentric coordinates). The fan's
//! centre moves as the mean of the polygon's points, so its force goes to them in equal shares.
//! Hence the resultant is `Σ ∫ q n̂` (Eq. 5.19), and the nodal moment `Σ x_i × f_i` is
//! `Σ_k I_k × F_k`, which for a uniform pressure is `p ∫ x × n̂` over the reconstructed
//! interface: zero on a closed one, to round-off.

use super::{distribute, or_zero, LoadView};
use crate::embedded::riemann_fs::wall_normal_from_i;
use crate::embedded::status::NO_SIDE;
use crate::mesh::geometry::{add, cross, dot, norm, scale, sub};
use crate::mesh::Cell;
use rayon::prelude::*;

/// One vertex of a reconstructed polygon: the intersection point, its load density `q` and the
/// cut it comes from.
#[derive(Clone, Copy)]
struct Vertex {
    x: [f64; 3],
    q: f64,
    /// Unit vector along the cut edge from its `-` end to its `+` end.
    across: [f64; 3],
    /// Index of its cut edge.
    cut: usize,
}

pub(super) fn loads(view: &LoadView, out: &mut [[f64; 3]]) {
    vertex_loads(view, |_, f, tri, bary| distribute(view.surface, tri, bary, f, out));
}

/// Calls `sink(x, f, triangle, bary)` for every vertex of the reconstructed interface, in cut
/// order: the intersection point `x`, its force `f` on the structure (summed over the polygons
/// it belongs to, in cell order), and the structure triangle hit there with the barycentric
/// coordinates of `x` in it. Only the cells around the cut edges are visited.
pub(super) fn vertex_loads(view: &LoadView, sink: impl FnMut([f64; 3], [f64; 3], u32, [f64; 3])) {
    vertex_loads_in(view, &cut_cells(view), sink);
}

/// The cut cells with their cut edges: a pair `(cell, cut)` for every cell holding both ends of
/// cut edge `cut`, ascending. Every cell with a cut edge appears, so every cell that can hold a
/// polygon. The cells of an edge are the common entries of its ends' node-to-cell rows (both
/// ascending: a merge, which reads no cell), found in parallel in cut order, then ordered by
/// cell with a stable radix sort (so by cut within a cell), the same for any number of threads.
pub(super) fn cut_cells(view: &LoadView) -> Vec<(u32, u32)> {
    let adjacency = view.adjacency;
    let pairs: Vec<(u32, u32)> = view
        .cuts
        .par_iter()
        .enumerate()
        .with_min_len(1024)
        .fold(Vec::new, |mut pairs, (k, c)| {
            let [i, j] = view.mesh.edges[c.edge as usize];
            let (a, b) = (adjacency.cells_of(i as usize), adjacency.cells_of(j as usize));
            let (mut x, mut y) = (0, 0);
            while x < a.len() && y < b.len() {
                match a[x].cmp(&b[y]) {
                    std::cmp::Ordering::Less => x += 1,
                    std::cmp::Ordering::Greater => y += 1,
                    std::cmp::Ordering::Equal => {
                        pairs.push((a[x], k as u32));
                        x += 1;
                        y += 1;
                    }
                }
            }
            pairs
        })
        .flatten_iter()
        .collect();
    let sorted = sort_by_cell(pairs, view.mesh.cells.len());
    debug_assert!(sorted.windows(2).all(|w| w[0] < w[1]), "cut cells out of order");
    sorted
}

/// `pairs` stably sorted by their first entry (each `< n_cells`): least significant digit
/// first, [`RADIX_BITS`] at a time.
fn sort_by_cell(mut pairs: Vec<(u32, u32)>, n_cells: usize) -> Vec<(u32, u32)> {
    let bits = usize::BITS - n_cells.saturating_sub(1).leading_zeros();
    let mut other = vec![(0, 0); pairs.len()];
    let mut shift = 0;
    while shift < bits {
        let digit = |c: u32| ((c >> shift) as usize) & ((1 << RADIX_BITS) - 1);
        let mut start = vec![0usize; (1 << RADIX_BITS) + 1];
        for &(c, _) in &pairs {
            start[digit(c) + 1] += 1;
        }
        for d in 0..1 << RADIX_BITS {
            start[d + 1] += start[d];
        }
        for &p in &pairs {
            let d = digit(p.0);
            other[start[d]] = p;
            start[d] += 1;
        }
        std::mem::swap(&mut pairs, &mut other);
        shift += RADIX_BITS;
    }
    pairs
}

/// Bits of a cell number sorted per pass of [`sort_by_cell`].
const RADIX_BITS: u32 = 11;

/// [`vertex_loads`] over the `(cell, cut)` pairs `pairs` (ascending), which must include every
/// cut edge of every cut cell.
pub(super) fn vertex_loads_in(
    view: &LoadView,
    pairs: &[(u32, u32)],
    mut sink: impl FnMut([f64; 3], [f64; 3], u32, [f64; 3]),
) {
    let joining = joining_cuts(view);
    // Each cut's vertex once (about five cells share it), with its edge's ends.
    let vertices: Vec<(Vertex, [u32; 2])> =
        (0..view.cuts.len()).into_par_iter().with_min_len(1024).map(|k| vertex(view, k)).collect();
    let cells: Vec<&[(u32, u32)]> = pairs.chunk_by(|a, b| a.0 == b.0).collect();
    // The cells' vertex forces in parallel, summed per cut in cell order (as one pass would).
    let per_chunk: Vec<Vec<(u32, [f64; 3])>> = cells
        .par_chunks(CELLS_PER_TASK)
        .map(|chunk| {
            let mut found = Vec::new();
            let mut polygon = Vec::with_capacity(12);
            for cuts in chunk {
                let cell = &view.mesh.cells[cuts[0].0 as usize];
                let cut_of = cell_cuts(&vertices, &joining, cell, cuts);
                if cut_of.iter().flatten().count() < 3 {
                    continue;
                }
                cycles(cell, &cut_of, |cycle, walked| {
                    polygon.clear();
                    polygon.extend(cycle.iter().map(|&k| vertices[k].0));
                    orient(&mut polygon, walked);
                    integrate(&polygon, &mut |k, f| found.push((k as u32, f)));
                });
            }
            found
        })
        .collect();
    let mut force: Vec<Option<[f64; 3]>> = vec![None; view.cuts.len()];
    for (k, f) in per_chunk.into_iter().flatten() {
        let sum = force[k as usize].get_or_insert([0.0; 3]);
        *sum = add(*sum, f);
    }
    for (k, f) in force.into_iter().enumerate() {
        if let Some(f) = f {
            let cut = &view.cuts[k];
            sink(vertices[k].0.x, f, cut.triangle, cut.bary);
        }
    }
}

/// Cut cells per parallel task of [`vertex_loads_in`].
const CELLS_PER_TASK: usize = 256;

/// Per cut edge, whether it joins the reconstruction (see the module docs): its ends on different
/// sides, or its triangle on a one-fluid shell.
fn joining_cuts(view: &LoadView) -> Vec<bool> {
    let part = &view.surface.open_part;
    // Per part: the first fluid side its cut edges reach, and whether they reach another.
    let mut reached: Vec<(u32, bool)> = vec![(NO_SIDE, false); part.len()];
    for c in view.cuts {
        let Some(root) = part[c.triangle as usize] else { continue };
        for n in view.mesh.edges[c.edge as usize] {
            let side = view.side[n as usize];
            let r = &mut reached[root as usize];
            if side == NO_SIDE || side == r.0 {
                continue;
            }
            if r.0 == NO_SIDE {
                r.0 = side;
            } else {
                r.1 = true;
            }
        }
    }
    view.cuts
        .par_iter()
        .with_min_len(1024)
        .map(|c| {
            let [i, j] = view.mesh.edges[c.edge as usize];
            let one_fluid_shell = part[c.triangle as usize].is_some_and(|r| !reached[r as usize].1);
            one_fluid_shell || view.side[i as usize] != view.side[j as usize]
        })
        .collect()
}

/// For each local edge of `cell`, the index of its cut edge, if it is cut and joins the
/// reconstruction (`joining`, per cut edge), from the cell's `(cell, cut)` pairs and the ends
/// of each cut's edge (`vertices`).
fn cell_cuts(
    vertices: &[(Vertex, [u32; 2])],
    joining: &[bool],
    cell: &Cell,
    pairs: &[(u32, u32)],
) -> [Option<usize>; 12] {
    let mut cut_of = [None; 12];
    let local = cell.kind.edges();
    for &(_, k) in pairs {
        let k = k as usize;
        if !joining[k] {
            continue;
        }
        let [i, j] = vertices[k].1;
        let l = local.iter().position(|&[a, b]| {
            let (p, q) = (cell.nodes[a], cell.nodes[b]);
            (p.min(q), p.max(q)) == (i, j)
        });
        if let Some(l) = l {
            cut_of[l] = Some(k);
        }
    }
    cut_of
}

/// Calls `visit` with each polygon of a cut cell as a cycle of cut-edge indices, and whether it
/// comes from the face walk (`false`: the unordered points of a cell whose faces do not close; see
/// the module docs). No allocation: a cell has at most 12 edges.
fn cycles(cell: &Cell, cut_of: &[Option<usize>; 12], mut visit: impl FnMut(&[usize], bool)) {
    // Neighbours of each local edge along the polygon, through the faces.
    let mut next: [[usize; 2]; 12] = [[usize::MAX; 2]; 12];
    let mut degree = [0usize; 12];
    let mut closed = true;
    for (f, face) in cell.kind.faces().iter().enumerate() {
        let mut on_face = [0usize; 4];
        let mut m = 0;
        for &l in cell.kind.face_sides(f) {
            let l = l as usize;
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
    let (mut cut_edges, mut n_cut) = ([0usize; 12], 0);
    for l in (0..12).filter(|&l| cut_of[l].is_some()) {
        cut_edges[n_cut] = l;
        n_cut += 1;
    }
    let cut_edges = &cut_edges[..n_cut];
    closed &= cut_edges.iter().all(|&l| degree[l] == 2);
    let mut cycle = [0usize; 12];
    if !closed {
        for (c, &l) in cycle.iter_mut().zip(cut_edges) {
            *c = cut_of[l].expect("cut");
        }
        return visit(&cycle[..n_cut], false);
    }
    let mut seen = [false; 12];
    for &start in cut_edges {
        if seen[start] {
            continue;
        }
        let mut len = 0;
        let (mut prev, mut cur) = (usize::MAX, start);
        while !seen[cur] {
            seen[cur] = true;
            cycle[len] = cut_of[cur].expect("cut");
            len += 1;
            let step = if next[cur][0] != prev { next[cur][0] } else { next[cur][1] };
            (prev, cur) = (cur, step);
        }
        if len >= 3 {
            visit(&cycle[..len], true);
        }
    }
}

/// The polygon vertex of cut `k`: its intersection point and `q = p*_- - p*_+`, the `+` end the
/// one `n_E` points to (the orientation contract); with the ends of its edge.
fn vertex(view: &LoadView, k: usize) -> (Vertex, [u32; 2]) {
    let cut = &view.cuts[k];
    let e = cut.edge as usize;
    let [i, j] = view.mesh.edges[e];
    let (xi, xj) = (view.mesh.coords[i as usize], view.mesh.coords[j as usize]);
    let d = sub(xj, xi);
    let [pi, pj] = view.p_star[k].map(or_zero);
    let towards_j = dot(wall_normal_from_i(cut.normal, d, view.mesh.edge_normals[e]), cut.normal);
    let (q, s) = if towards_j > 0.0 { (pi - pj, 1.0) } else { (pj - pi, -1.0) };
    let vertex =
        Vertex { x: add(xi, scale(d, cut.alpha)), q, across: scale(d, s / norm(d)), cut: k };
    (vertex, [i, j])
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

/// Integrates `q n̂` over the triangles of an oriented polygon into per-vertex forces (Eq. 5.18)
/// and hands each to `sink` with its vertex's cut.
fn integrate(poly: &[Vertex], sink: &mut impl FnMut(usize, [f64; 3])) {
    let m = poly.len();
    let mut force = [[0.0; 3]; 12];
    if m == 3 {
        let f = triangle_forces([0, 1, 2].map(|k| (poly[k].x, poly[k].q)));
        force[..3].copy_from_slice(&f);
    } else {
        let c = (centroid(poly), poly.iter().map(|v| v.q).sum::<f64>() / m as f64);
        let mut centre = [0.0; 3];
        for k in 0..m {
            let (a, b) = (&poly[k], &poly[(k + 1) % m]);
            let [fc, fa, fb] = triangle_forces([c, (a.x, a.q), (b.x, b.q)]);
            centre = add(centre, fc);
            force[k] = add(force[k], fa);
            force[(k + 1) % m] = add(force[(k + 1) % m], fb);
        }
        let share = scale(centre, 1.0 / m as f64);
        force[..m].iter_mut().for_each(|f| *f = add(*f, share));
    }
    for (v, f) in poly.iter().zip(&force) {
        sink(v.cut, *f);
    }
}

/// `F_k = ∫ q N̂_k n̂` on the triangle of `(x, q)` corners, `q` linear: the area vector times
/// `(2 q_k + q_l + q_m) / 12` (the rows of the P1 mass matrix; a uniform `q` gives each corner a
/// third).
fn triangle_forces(corner: [([f64; 3], f64); 3]) -> [[f64; 3]; 3] {
    let [(a, qa), (b, qb), (c, qc)] = corner;
    let area = scale(cross(sub(b, a), sub(c, a)), 0.5);
    let sum = qa + qb + qc;
    [qa, qb, qc].map(|q| scale(area, (sum + q) / 12.0))
}
