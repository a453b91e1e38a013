//! Median-dual control volumes (thesis §3.3.1): each cell is cut by the facets joining its edge
//! midpoints, face centroids and centroid; node `a` of a cell owns the cones from the cell
//! centroid over the face pieces `(a, m_ab, f)`.

use super::cell::edge_faces;
use super::geometry::{add, centroid, cross, dot, norm, scale, sub};
use super::renumber::reverse_cuthill_mckee;
use super::{Boundary, Cell, EdgeBlocks, Mesh, MeshError, RawMesh};

/// Node adjacency through cell edges as CSR (sorted neighbour lists, no self).
fn adjacency(n: usize, cells: &[Cell]) -> (Vec<usize>, Vec<u32>) {
    let (co, cn) = node_cells(n, cells);
    let mut offsets = vec![0usize; n + 1];
    let mut neighbours = Vec::new();
    let mut row: Vec<u32> = Vec::new();
    for i in 0..n {
        row.clear();
        for &c in &cn[co[i]..co[i + 1]] {
            let cell = &cells[c as usize];
            for &[a, b] in cell.kind.edges() {
                let (p, q) = (cell.nodes[a], cell.nodes[b]);
                if p as usize == i {
                    row.push(q);
                } else if q as usize == i {
                    row.push(p);
                }
            }
        }
        row.sort_unstable();
        row.dedup();
        neighbours.extend_from_slice(&row);
        offsets[i + 1] = neighbours.len();
    }
    (offsets, neighbours)
}

/// Node-to-cell CSR.
fn node_cells(n: usize, cells: &[Cell]) -> (Vec<usize>, Vec<u32>) {
    let mut offsets = vec![0usize; n + 1];
    for c in cells {
        for &v in c.nodes() {
            offsets[v as usize + 1] += 1;
        }
    }
    for i in 0..n {
        offsets[i + 1] += offsets[i];
    }
    let mut fill = offsets.clone();
    let mut list = vec![0u32; offsets[n]];
    for (k, c) in cells.iter().enumerate() {
        for &v in c.nodes() {
            list[fill[v as usize]] = k as u32;
            fill[v as usize] += 1;
        }
    }
    (offsets, list)
}

/// A node a cell lists twice (its corners must be distinct), if any.
pub(super) fn repeated_node(nodes: &[u32]) -> Option<u32> {
    nodes.iter().enumerate().find(|&(a, v)| nodes[..a].contains(v)).map(|(_, &v)| v)
}

pub(super) fn build(mut raw: RawMesh) -> Result<Mesh, MeshError> {
    let n_raw = raw.coords.len();
    for (k, c) in raw.cells.iter().enumerate() {
        if let Some(&node) = c.nodes().iter().find(|&&v| v as usize >= n_raw) {
            return Err(MeshError::BadNode {
                origin: raw.origin.clone(),
                cell: k,
                node,
                n_nodes: n_raw,
            });
        }
        if let Some(node) = repeated_node(c.nodes()) {
            return Err(MeshError::RepeatedNode {
                origin: raw.origin.clone(),
                cell: k,
                kind: c.kind.name(),
                node,
            });
        }
    }
    for f in &raw.faces {
        if let Some(&node) = f.nodes.iter().find(|&&v| v as usize >= n_raw) {
            return Err(MeshError::Input(format!(
                "{}: a face of boundary `{}` refers to node {node}, but the mesh has {n_raw} nodes",
                raw.origin, raw.patch_names[f.patch as usize]
            )));
        }
    }
    // Drop nodes no cell uses (gmsh geometry points), then renumber by RCM.
    let mut used = vec![false; n_raw];
    for c in &raw.cells {
        for &v in c.nodes() {
            used[v as usize] = true;
        }
    }
    let mut compact = vec![u32::MAX; n_raw];
    let mut kept: Vec<u32> = Vec::new();
    for i in 0..n_raw {
        if used[i] {
            compact[i] = kept.len() as u32;
            kept.push(i as u32);
        }
    }
    let renumber_cells = |cells: &mut [Cell], map: &[u32]| {
        for c in cells.iter_mut() {
            let k = c.kind.n_nodes();
            for v in &mut c.nodes[..k] {
                *v = map[*v as usize];
            }
        }
    };
    renumber_cells(&mut raw.cells, &compact);
    let n = kept.len();
    let (ao, an) = adjacency(n, &raw.cells);
    let rcm = reverse_cuthill_mckee(&ao, &an);
    renumber_cells(&mut raw.cells, &rcm);
    let mut coords = vec![[0.0; 3]; n];
    let mut original_ids = vec![0u32; n];
    for (c, &old) in kept.iter().enumerate() {
        coords[rcm[c] as usize] = raw.coords[old as usize];
        original_ids[rcm[c] as usize] = old;
    }
    for f in &mut raw.faces {
        for v in &mut f.nodes {
            let c = compact[*v as usize];
            if c == u32::MAX {
                return Err(MeshError::OrphanFace {
                    origin: raw.origin.clone(),
                    patch: raw.patch_names[f.patch as usize].clone(),
                    nodes: f.nodes.clone(),
                });
            }
            *v = rcm[c as usize];
        }
    }
    let cells = raw.cells;

    // Edges (i < j), sorted: the upper part of the adjacency.
    let (ao, an) = adjacency(n, &cells);
    let mut edge_offsets = vec![0usize; n + 1];
    let mut edges: Vec<[u32; 2]> = Vec::with_capacity(an.len() / 2);
    for i in 0..n {
        for &j in &an[ao[i]..ao[i + 1]] {
            if j as usize > i {
                edges.push([i as u32, j]);
            }
        }
        edge_offsets[i + 1] = edges.len();
    }
    let edge_index = |a: u32, b: u32| -> usize {
        let (i, j) = if a < b { (a, b) } else { (b, a) };
        let row = &edges[edge_offsets[i as usize]..edge_offsets[i as usize + 1]];
        edge_offsets[i as usize]
            + row.binary_search_by_key(&j, |e| e[1]).expect("edge of a cell is in the edge list")
    };

    // Dual volumes and edge normals, cell by cell.
    let mut volumes = vec![0.0; n];
    let mut edge_normals = vec![[0.0; 3]; edges.len()];
    let mut face_centres: Vec<[f64; 3]> = Vec::with_capacity(6);
    for (k, cell) in cells.iter().enumerate() {
        let x = |l: usize| coords[cell.nodes[l] as usize];
        let g = centroid((0..cell.kind.n_nodes()).map(x));
        face_centres.clear();
        face_centres.extend(cell.kind.faces().iter().map(|f| centroid(f.iter().map(|&l| x(l)))));
        let mut cell_volume = 0.0;
        let mut parts = [0.0f64; 8];
        for (f, face) in cell.kind.faces().iter().enumerate() {
            let fc = face_centres[f];
            for q in 0..face.len() {
                let (a, b) = (face[q], face[(q + 1) % face.len()]);
                let (xa, xb) = (x(a), x(b));
                let m = scale(add(xa, xb), 0.5);
                // Cones from g over the outward triangles (a, m, f) and (m, b, f).
                let va = dot(cross(sub(m, xa), sub(fc, xa)), sub(xa, g)) / 6.0;
                let vb = dot(cross(sub(xb, m), sub(fc, m)), sub(m, g)) / 6.0;
                parts[a] += va;
                parts[b] += vb;
                cell_volume += va + vb;
            }
        }
        let size = (0..cell.kind.n_nodes()).map(|l| norm(sub(x(l), g))).fold(0.0, f64::max);
        // Also catches NaN coordinates.
        if cell_volume.partial_cmp(&(1e-12 * size * size * size)).is_none_or(|o| o.is_le()) {
            return Err(MeshError::BadCell {
                origin: raw.origin.clone(),
                cell: k,
                kind: cell.kind.name(),
                volume: cell_volume,
            });
        }
        for l in 0..cell.kind.n_nodes() {
            volumes[cell.nodes[l] as usize] += parts[l];
        }
        for &[a, b] in cell.kind.edges() {
            let (fab, fba) = edge_faces(cell.kind, a, b);
            let m = scale(add(x(a), x(b)), 0.5);
            // Quad facet (m, f_ba, g, f_ab): ν = ½ (g - m) × (f_ab - f_ba), from a to b.
            let nu = scale(cross(sub(g, m), sub(face_centres[fab], face_centres[fba])), 0.5);
            let (p, q) = (cell.nodes[a], cell.nodes[b]);
            let e = edge_index(p, q);
            let nu = if p < q { nu } else { scale(nu, -1.0) };
            edge_normals[e] = add(edge_normals[e], nu);
        }
    }

    // Boundaries: each tagged face is oriented by the cell face it matches.
    let (co, cn) = node_cells(n, &cells);
    let mut contributions: Vec<Vec<(u32, [f64; 3])>> = vec![Vec::new(); raw.patch_names.len()];
    for face in &raw.faces {
        let mut key = face.nodes.clone();
        key.sort_unstable();
        let v0 = face.nodes[0] as usize;
        let mut found = None;
        'cells: for &c in &cn[co[v0]..co[v0 + 1]] {
            let cell = &cells[c as usize];
            for lf in cell.kind.faces() {
                if lf.len() != key.len() {
                    continue;
                }
                let mut nodes: Vec<u32> = lf.iter().map(|&l| cell.nodes[l]).collect();
                let ordered = nodes.clone();
                nodes.sort_unstable();
                if nodes == key {
                    found = Some(ordered);
                    break 'cells;
                }
            }
        }
        let Some(ordered) = found else {
            return Err(MeshError::OrphanFace {
                origin: raw.origin.clone(),
                patch: raw.patch_names[face.patch as usize].clone(),
                nodes: face.nodes.iter().map(|&v| original_ids[v as usize]).collect(),
            });
        };
        let fc = centroid(ordered.iter().map(|&v| coords[v as usize]));
        let list = &mut contributions[face.patch as usize];
        for q in 0..ordered.len() {
            let (a, b) = (ordered[q], ordered[(q + 1) % ordered.len()]);
            let (xa, xb) = (coords[a as usize], coords[b as usize]);
            let m = scale(add(xa, xb), 0.5);
            list.push((a, scale(cross(sub(m, xa), sub(fc, xa)), 0.5)));
            list.push((b, scale(cross(sub(xb, m), sub(fc, m)), 0.5)));
        }
    }
    let boundaries: Vec<Boundary> = raw
        .patch_names
        .iter()
        .zip(contributions)
        .map(|(name, mut list)| {
            list.sort_by_key(|c| c.0);
            let mut nodes: Vec<u32> = Vec::new();
            let mut normals: Vec<[f64; 3]> = Vec::new();
            for (v, a) in list {
                if nodes.last() == Some(&v) {
                    let last = normals.last_mut().expect("same length as nodes");
                    *last = add(*last, a);
                } else {
                    nodes.push(v);
                    normals.push(a);
                }
            }
            Boundary { name: name.clone(), nodes, normals }
        })
        .collect();

    let mut dual_areas = vec![0.0; n];
    for (&[i, j], nu) in edges.iter().zip(&edge_normals) {
        let a = norm(*nu);
        dual_areas[i as usize] += a;
        dual_areas[j as usize] += a;
    }
    let scale_sum = dual_areas.clone();
    for b in &boundaries {
        for (&i, nb) in b.nodes.iter().zip(&b.normals) {
            dual_areas[i as usize] += norm(*nb);
        }
    }
    let mesh = Mesh {
        coords,
        original_ids,
        cells,
        volumes,
        blocks: EdgeBlocks::new(n, &edges),
        edges,
        edge_normals,
        dual_areas,
        boundaries,
    };
    // A dual cell that does not close means boundary faces are missing from every named boundary.
    for (i, defect) in mesh.closure_defects().into_iter().enumerate() {
        let d = norm(defect);
        if d > 1e-9 * scale_sum[i].max(f64::MIN_POSITIVE) {
            return Err(MeshError::OpenBoundary {
                origin: raw.origin,
                node: mesh.original_ids[i] as usize,
                position: mesh.coords[i],
                mismatch: d,
            });
        }
    }
    Ok(mesh)
}
