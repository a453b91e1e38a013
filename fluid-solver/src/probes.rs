//! Probes and lines: the fluid state sampled at points (`probes.csv`) and along straight lines
//! (`lines/<name>.csv`). A sample takes the state of the node nearest to the point (exact at
//! nodes; interpolation inside cells is not done).

use crate::mesh::geometry::{add, dot, norm, scale, sub};
use crate::mesh::Mesh;
use interface_protocol::io::probes::LinePoint;

/// The node nearest to `x`.
pub fn nearest_node(mesh: &Mesh, x: [f64; 3]) -> usize {
    let mut best = (f64::INFINITY, 0);
    for (i, c) in mesh.coords.iter().enumerate() {
        let d = sub(*c, x);
        let d2 = dot(d, d);
        if d2 < best.0 {
            best = (d2, i);
        }
    }
    best.1
}

/// A line of `n` equally spaced points from `from` to `to`, each with its nearest node.
#[derive(Debug, Clone)]
pub struct Line {
    pub name: String,
    pub points: Vec<[f64; 3]>,
    pub nodes: Vec<usize>,
    /// Times still to write, ascending.
    pub pending: Vec<f64>,
}

impl Line {
    pub fn new(
        mesh: &Mesh,
        name: &str,
        from: [f64; 3],
        to: [f64; 3],
        n: usize,
        times: &[f64],
    ) -> Line {
        let points: Vec<[f64; 3]> =
            (0..n).map(|k| add(from, scale(sub(to, from), k as f64 / (n - 1) as f64))).collect();
        let nodes = points.iter().map(|&x| nearest_node(mesh, x)).collect();
        let mut pending = times.to_vec();
        pending.sort_by(f64::total_cmp);
        Line { name: name.to_string(), points, nodes, pending }
    }

    /// The samples of the current state.
    pub fn sample(&self, prim: &[[f64; 5]]) -> Vec<LinePoint> {
        let from = self.points[0];
        self.points
            .iter()
            .zip(&self.nodes)
            .map(|(&x, &i)| {
                let w = prim[i];
                LinePoint {
                    x,
                    s: norm(sub(x, from)),
                    rho: w[0],
                    v: [w[1], w[2], w[3]],
                    p: w[4],
                    material: 0,
                }
            })
            .collect()
    }
}
