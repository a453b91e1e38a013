//! Reinitialisation of the level set to a signed distance (DESIGN §5), with the nodes of the
//! sign-changing edges frozen: they keep their `φ`, so the zero of `φ` along every edge it
//! crosses stays where it was, and no node changes sign, so no material changes.
//!
//! The distance is a closest-point transform over the edge graph (Danielsson's vector distance
//! transform, run in Dijkstra order as in the fast marching method): the interface points are the
//! zeros of the linear interpolation of `φ` on the sign-changing edges, each with the interface
//! normal there (`∇φ` of the two ends interpolated the same way); each end of such an edge starts
//! with its nearer crossing point, and the front then hands every node the closest point of the
//! neighbour that gives it the smallest distance `|x - c|`, nodes taken in increasing distance.
//! The distance returned is that to the tangent plane at the node's closest point,
//! `|(x - c)·n̂_c|`: exact for a plane whatever crossing point a node gets, and within
//! `(R + d) l²/(2R²)` of the distance to a sphere of radius `R` (`l` the offset of the chosen
//! point from the node's foot, at most about the spacing of the crossing points), where the
//! distance to the point itself would be off by up to `l` next to the interface. Every node
//! reachable from the interface gets `φ = sign(φ_old) d`; a node with no interface in its
//! connected part of the mesh keeps its `φ`. One sequential pass with a binary heap,
//! `O(N log N)`, deterministic.
//!
//! With an embedded surface only the edges `through` it may cross (uncut, both ends active fluid
//! nodes) hold interface points and carry the front: a sign change across the structure (water
//! on one side of a shell, air on the other) is no interface of `φ`, the distance never passes
//! through the structure, and the nodes that are not active, which the front never reaches, keep
//! their `φ`.

use super::LevelSet;
use crate::embedded::adjacency::NodeEdges;
use crate::mesh::geometry::{add, dot, norm, scale, sub};
use crate::mesh::Mesh;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// A node on the front with its squared distance (ordered nearest first; ties by node).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Front {
    d2: f64,
    node: u32,
}

impl Eq for Front {}

impl Ord for Front {
    fn cmp(&self, other: &Self) -> Ordering {
        other.d2.total_cmp(&self.d2).then_with(|| other.node.cmp(&self.node))
    }
}

impl PartialOrd for Front {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// A point of the interface on an edge.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Seed {
    /// The edge's end nodes, where the transform starts from this point.
    pub ends: [usize; 2],
    pub point: [f64; 3],
    /// The unit interface normal there, if known (the distance is then to the tangent plane).
    pub normal: Option<[f64; 3]>,
}

/// Each node's distance to the interface through the points `seeds`, by the closest-point
/// transform of the module docs over the edges `e` with `through[e]` (`None`: all); `∞` where no
/// seed reaches.
pub fn distance_to_interface(
    mesh: &Mesh,
    adjacency: &NodeEdges,
    seeds: &[Seed],
    through: Option<&[bool]>,
) -> Vec<f64> {
    let n = mesh.n_nodes();
    let mut d2 = vec![f64::INFINITY; n];
    let mut closest = vec![u32::MAX; n];
    let mut done = vec![false; n];
    let mut heap = BinaryHeap::with_capacity(2 * seeds.len());
    for (k, seed) in seeds.iter().enumerate() {
        for i in seed.ends {
            let r = sub(mesh.coords[i], seed.point);
            let r2 = dot(r, r);
            if r2 < d2[i] {
                d2[i] = r2;
                closest[i] = k as u32;
                heap.push(Front { d2: r2, node: i as u32 });
            }
        }
    }
    while let Some(Front { d2: di, node }) = heap.pop() {
        let i = node as usize;
        if done[i] || di > d2[i] {
            continue;
        }
        done[i] = true;
        let c = seeds[closest[i] as usize].point;
        for (k, e) in adjacency.neighbours(mesh, i) {
            if done[k] || through.is_some_and(|t| !t[e as usize]) {
                continue;
            }
            let r = sub(mesh.coords[k], c);
            let r2 = dot(r, r);
            if r2 < d2[k] {
                d2[k] = r2;
                closest[k] = closest[i];
                heap.push(Front { d2: r2, node: k as u32 });
            }
        }
    }
    (0..n)
        .map(|i| match seeds.get(closest[i] as usize) {
            None => f64::INFINITY,
            Some(Seed { normal: Some(nh), point, .. }) => {
                dot(sub(mesh.coords[i], *point), *nh).abs()
            }
            Some(_) => d2[i].sqrt(),
        })
        .collect()
}

/// The zero of the linear interpolation of `φ` on every sign-changing edge `e` with `through[e]`
/// (`None`: all), with its ends and the normal `∇φ/|∇φ|` interpolated from the ends' gradients
/// `grad` (none where that vanishes).
pub fn crossings(
    mesh: &Mesh,
    phi: &[f64],
    grad: &[[[f64; 3]; 1]],
    through: Option<&[bool]>,
) -> Vec<Seed> {
    mesh.edges
        .iter()
        .enumerate()
        .filter(|(e, _)| through.is_none_or(|t| t[*e]))
        .filter_map(|(_, &[i, j])| {
            let (i, j) = (i as usize, j as usize);
            let (a, b) = (phi[i], phi[j]);
            (LevelSet::side(a) != LevelSet::side(b)).then(|| {
                let t = a / (a - b);
                let (xi, xj) = (mesh.coords[i], mesh.coords[j]);
                let g = add(scale(grad[i][0], 1.0 - t), scale(grad[j][0], t));
                let normal = (norm(g) > 0.0).then(|| scale(g, 1.0 / norm(g)));
                Seed { ends: [i, j], point: add(xi, scale(sub(xj, xi), t)), normal }
            })
        })
        .collect()
}

/// Resets `φ` to a signed distance with the ends of its sign-changing edges frozen (module
/// docs), `grad` holding `∇φ`, over the edges `through` (`None`: all); returns the number of
/// frozen nodes.
pub fn reinitialise(
    mesh: &Mesh,
    adjacency: &NodeEdges,
    grad: &[[[f64; 3]; 1]],
    phi: &mut [f64],
    through: Option<&[bool]>,
) -> usize {
    let seeds = crossings(mesh, phi, grad, through);
    let mut frozen = vec![false; phi.len()];
    for seed in &seeds {
        for &i in &seed.ends {
            frozen[i] = true;
        }
    }
    let d = distance_to_interface(mesh, adjacency, &seeds, through);
    for (i, p) in phi.iter_mut().enumerate() {
        // A node at zero distance would lose its sign (`-0 >= 0`): keep it.
        if !frozen[i] && d[i].is_finite() && d[i] > 0.0 {
            *p = if *p >= 0.0 { d[i] } else { -d[i] };
        }
    }
    frozen.iter().filter(|&&f| f).count()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::boxmesh::{BoxCells, BoxSpec};
    use crate::mesh::perturb;
    use crate::reconstruct::gradient::LsqGradient;

    fn gradient(mesh: &Mesh, phi: &[f64]) -> Vec<[[f64; 3]; 1]> {
        let values: Vec<[f64; 1]> = phi.iter().map(|&p| [p]).collect();
        let mut grad = vec![[[0.0; 3]]; phi.len()];
        LsqGradient::new(mesh).compute(mesh, &values, &mut grad);
        grad
    }

    fn mesh(cells: [usize; 3], seed: Option<u64>) -> Mesh {
        let mut raw = BoxSpec::uniform([0.0; 3], [1.0; 3], cells, BoxCells::Tet).raw().unwrap();
        if let Some(s) = seed {
            perturb(&mut raw, 0.2, s);
        }
        Mesh::build(raw).unwrap()
    }

    /// A distorted level set of a sphere (`φ = (r - R)(1 + 3|x|²)`, the right zero set, not a
    /// distance) becomes the sphere's signed distance: no sign changes, the frozen nodes keep their
    /// values exactly, and the others are within 0.15 h of `r - R` within 2h of the sphere and
    /// within 10% of it beyond.
    #[test]
    fn reinitialisation_keeps_the_interface_and_restores_the_distance() {
        let mesh = mesh([16, 16, 16], Some(3));
        let adjacency = NodeEdges::build(&mesh);
        let c = [0.45, 0.5, 0.55];
        let radius = 0.3;
        let r = |x: [f64; 3]| dot(sub(x, c), sub(x, c)).sqrt();
        let mut phi: Vec<f64> =
            mesh.coords.iter().map(|&x| (r(x) - radius) * (1.0 + 3.0 * dot(x, x))).collect();
        let before = phi.clone();
        let grad = gradient(&mesh, &phi);
        let frozen = reinitialise(&mesh, &adjacency, &grad, &mut phi, None);
        assert!(frozen > 100, "{frozen} frozen nodes");
        let h = 1.0 / 16.0;
        let (mut near, mut far): (f64, f64) = (0.0, 0.0);
        let seeds = crossings(&mesh, &before, &grad, None);
        let is_frozen = |i: usize| seeds.iter().any(|s| s.ends.contains(&i));
        for i in 0..mesh.n_nodes() {
            assert_eq!(LevelSet::side(phi[i]), LevelSet::side(before[i]), "node {i} changed side");
            if is_frozen(i) {
                assert_eq!(phi[i].to_bits(), before[i].to_bits(), "frozen node {i} moved");
            } else {
                let d = r(mesh.coords[i]) - radius;
                let e = (phi[i] - d).abs();
                if d.abs() < 2.0 * h {
                    near = near.max(e);
                } else {
                    far = far.max(e / d.abs());
                }
            }
        }
        println!(
            "sphere reinitialisation: {frozen} frozen; |φ - d| <= {:.3} h within 2h of the \
             interface, <= {:.3} |d| beyond",
            near / h,
            far
        );
        assert!(near < 0.15 * h && far < 0.1, "|φ - d| up to {} h near, {far} |d| far", near / h);
        // Again: the same frozen nodes, untouched.
        let mut again = phi.clone();
        let grad = gradient(&mesh, &phi);
        reinitialise(&mesh, &adjacency, &grad, &mut again, None);
        for i in 0..mesh.n_nodes() {
            assert_eq!(LevelSet::side(again[i]), LevelSet::side(before[i]));
            if is_frozen(i) {
                assert_eq!(again[i].to_bits(), before[i].to_bits());
            }
        }
    }

    /// A plane through a tube of tets (`φ` three times the distance): the distance is exact at
    /// every node that is not frozen.
    #[test]
    fn a_plane_in_a_tube_gets_its_exact_distance() {
        let raw = BoxSpec::tube(0.0, 1.0, 50, 0.02, BoxCells::Tet).raw().unwrap();
        let mesh = Mesh::build(raw).unwrap();
        let adjacency = NodeEdges::build(&mesh);
        let x0 = 0.4071;
        let mut phi: Vec<f64> = mesh.coords.iter().map(|x| 3.0 * (x[0] - x0)).collect();
        let grad = gradient(&mesh, &phi);
        reinitialise(&mesh, &adjacency, &grad, &mut phi, None);
        for (i, x) in mesh.coords.iter().enumerate() {
            if (x[0] - x0).abs() > 0.02 {
                assert!((phi[i] - (x[0] - x0)).abs() < 1e-14, "node {i} at {x:?}: φ = {}", phi[i]);
            }
        }
    }
}
