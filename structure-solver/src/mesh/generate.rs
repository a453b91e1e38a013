//! Structured mesh generators for plates, cylinders, spheres, annuli, beams and tet blocks
//! ([`block`]). Each surface generator maps a
//! `nu x nv` grid of the unit square onto the surface; node `(i, j)` is `j (nu + 1) + i`.
//! Node sets `u0`, `u1`, `v0`, `v1` are the four grid edges, cell set `all` every cell; cells
//! are quads `(i, j), (i+1, j), (i+1, j+1), (i, j+1)` (use `Mesh::to_triangles` for triangles).

use std::f64::consts::PI;

use super::{Cell, CellKind, Mesh};

/// A structured quad grid through `f(u, v)`, `u, v ∈ [0, 1]`.
pub fn grid(nu: usize, nv: usize, f: impl Fn(f64, f64) -> [f64; 3]) -> Mesh {
    let mut m = Mesh::default();
    for j in 0..=nv {
        for i in 0..=nu {
            m.nodes.push(f(i as f64 / nu as f64, j as f64 / nv as f64));
        }
    }
    let id = |i: usize, j: usize| j * (nu + 1) + i;
    for j in 0..nv {
        for i in 0..nu {
            m.cells.push(Cell {
                kind: CellKind::Quad4,
                nodes: vec![id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)],
            });
        }
    }
    m.node_sets.insert("u0".into(), (0..=nv).map(|j| id(0, j)).collect());
    m.node_sets.insert("u1".into(), (0..=nv).map(|j| id(nu, j)).collect());
    m.node_sets.insert("v0".into(), (0..=nu).map(|i| id(i, 0)).collect());
    m.node_sets.insert("v1".into(), (0..=nu).map(|i| id(i, nv)).collect());
    m.cell_sets.insert("all".into(), (0..m.cells.len()).collect());
    m
}

/// Rectangle `[0, lx] x [0, ly]` in the plane `z = 0`, `nx x ny` cells.
pub fn rectangle(lx: f64, ly: f64, nx: usize, ny: usize) -> Mesh {
    grid(nx, ny, |u, v| [u * lx, v * ly, 0.0])
}

/// Cylinder of radius `r` about the `z` axis, `θ ∈ [θ0, θ1]` (`u`, `n_theta` cells),
/// `z ∈ [0, length]` (`v`, `n_axial` cells).
pub fn cylinder(r: f64, length: f64, theta: [f64; 2], n_theta: usize, n_axial: usize) -> Mesh {
    grid(n_theta, n_axial, |u, v| {
        let t = theta[0] + u * (theta[1] - theta[0]);
        [r * t.cos(), r * t.sin(), v * length]
    })
}

/// Sphere patch of radius `r`: azimuth `θ ∈ [θ0, θ1]` about `z` (`u`), polar angle from `+z`
/// `φ ∈ [φ0, φ1]` (`v`).
pub fn sphere(r: f64, theta: [f64; 2], phi: [f64; 2], n_theta: usize, n_phi: usize) -> Mesh {
    grid(n_theta, n_phi, |u, v| {
        let t = theta[0] + u * (theta[1] - theta[0]);
        let p = phi[0] + v * (phi[1] - phi[0]);
        [r * p.sin() * t.cos(), r * p.sin() * t.sin(), r * p.cos()]
    })
}

/// Annulus `r ∈ [ri, ro]` (`v`), `θ ∈ [θ0, θ1]` (`u`) in the plane `z = 0`.
pub fn annulus(ri: f64, ro: f64, theta: [f64; 2], n_theta: usize, n_r: usize) -> Mesh {
    grid(n_theta, n_r, |u, v| {
        let t = theta[0] + u * (theta[1] - theta[0]);
        let rr = ri + v * (ro - ri);
        [rr * t.cos(), rr * t.sin(), 0.0]
    })
}

/// Quarter turn and full turn in radians, for the generators' angle arguments.
pub const QUARTER: f64 = 0.5 * PI;

/// Straight beam from `p0` to `p1` in `n` 2-node cells; node sets `start`, `end`.
pub fn line(p0: [f64; 3], p1: [f64; 3], n: usize) -> Mesh {
    let mut m = Mesh::default();
    for i in 0..=n {
        let s = i as f64 / n as f64;
        m.nodes.push([0, 1, 2].map(|c| p0[c] + s * (p1[c] - p0[c])));
    }
    m.cells = (0..n).map(|i| Cell { kind: CellKind::Line2, nodes: vec![i, i + 1] }).collect();
    m.node_sets.insert("start".into(), vec![0]);
    m.node_sets.insert("end".into(), vec![n]);
    m.cell_sets.insert("all".into(), (0..n).collect());
    m
}

/// The block `[0, lx] x [0, ly] x [0, lz]` of `nx x ny x nz` cubes, each split into the six
/// tets of Kuhn's subdivision about its main diagonal (a conforming mesh, every tet
/// positively oriented). Node `(i, j, k)` is `(k (ny + 1) + j) (nx + 1) + i`; node sets `x0`,
/// `x1`, `y0`, `y1`, `z0`, `z1` are the six faces, cell set `all` every tet.
pub fn block(l: [f64; 3], n: [usize; 3]) -> Mesh {
    let [nx, ny, nz] = n;
    let mut m = Mesh::default();
    let id = |i: usize, j: usize, k: usize| (k * (ny + 1) + j) * (nx + 1) + i;
    for k in 0..=nz {
        for j in 0..=ny {
            for i in 0..=nx {
                let f = |a: usize, b: usize, len: f64| len * a as f64 / b as f64;
                m.nodes.push([f(i, nx, l[0]), f(j, ny, l[1]), f(k, nz, l[2])]);
            }
        }
    }
    // the six monotone paths from corner 0 to corner 7 of a unit cube, one tet each
    const PATHS: [[usize; 3]; 6] =
        [[0, 1, 2], [0, 2, 1], [1, 0, 2], [1, 2, 0], [2, 0, 1], [2, 1, 0]];
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                for path in PATHS {
                    let mut c = [i, j, k];
                    let mut nodes = vec![id(c[0], c[1], c[2])];
                    for axis in path {
                        c[axis] += 1;
                        nodes.push(id(c[0], c[1], c[2]));
                    }
                    let p = |q: usize| nalgebra::Vector3::from(m.nodes[nodes[q]]);
                    if (p(1) - p(0)).cross(&(p(2) - p(0))).dot(&(p(3) - p(0))) < 0.0 {
                        nodes.swap(1, 2);
                    }
                    m.cells.push(Cell { kind: CellKind::Tet4, nodes });
                }
            }
        }
    }
    let face = |axis: usize, at: usize| -> Vec<usize> {
        let mut out = Vec::new();
        for k in 0..=nz {
            for j in 0..=ny {
                for i in 0..=nx {
                    if [i, j, k][axis] == at {
                        out.push(id(i, j, k));
                    }
                }
            }
        }
        out
    };
    for (axis, name) in ["x", "y", "z"].iter().enumerate() {
        m.node_sets.insert(format!("{name}0"), face(axis, 0));
        m.node_sets.insert(format!("{name}1"), face(axis, n[axis]));
    }
    m.cell_sets.insert("all".into(), (0..m.cells.len()).collect());
    m
}
