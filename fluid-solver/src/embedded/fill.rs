//! States for the nodes that change side or become active in a step (thesis §4.4, DESIGN §5
//! "swept nodes"): a node that becomes an active fluid node takes the average primitive state of
//! its neighbours that were active on its new side before the step and still are, through edges
//! the surface does not cut now; never across the surface (and, with several fluids, never
//! across materials: `same_fluid` decides). A node with no such neighbour takes the average over
//! its same-side neighbours of their own source averages (sources two edges away); a node with
//! none within two edges is an error: the surface moved too far in one step.
//!
//! With `linear` (the second-order interface, [`super::riemann_fs::interface`]) each neighbour
//! `j` contributes its state carried to the new node along its own least-squares gradient over
//! its sources, `W_j + G_j (x_i - x_j)`, each component's increment limited to three times the
//! largest difference `|W_m - W_j|` over that stencil (a linear field's change along a cell
//! diagonal is within it, so linear fields stay exact; bounded at jumps). The
//! plain average is off by `O(h ∇W)` next to an accelerating wall (`∂p/∂x = -ρ a`): an `O(h)`
//! error at each uncovered node that the flow carries away, which makes the scheme first order;
//! the linear fill's is `O(h²)`.

use super::swept::Swept;
use crate::mesh::Mesh;

/// A newly active node that no neighbour could fill, named.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("node {node} at {position:?} became an active fluid node on side {side}, but no active node of that side lies within two edges of it: the surface moved more than one cell in a step (thesis §4.4), or the side is a pocket the grid does not resolve")]
pub struct FillError {
    pub node: u32,
    pub position: [f64; 3],
    pub side: u32,
}

/// The primitive states of the swept nodes that are active now: `(node, [ρ, u, v, w, p])`, in
/// the order of the changes. `prim` holds the states before the step, `same_fluid(i, j)` whether
/// two nodes hold one fluid.
pub fn fill_changed(
    swept: &Swept,
    prim: &[[f64; 5]],
    same_fluid: impl Fn(usize, usize) -> bool + Sync,
    linear: bool,
) -> Result<Vec<(u32, [f64; 5])>, FillError> {
    use rayon::prelude::*;
    let mesh = swept.mesh;
    // The same-side, same-fluid neighbours of `i` that `ring` gives a state for, averaged.
    let average = |i: usize, ring: &dyn Fn(usize) -> Option<[f64; 5]>| -> Option<[f64; 5]> {
        let mut sum = [0.0; 5];
        let mut count = 0usize;
        for j in swept.same_side(i).filter(|&j| same_fluid(i, j)) {
            if let Some(w) = ring(j) {
                for c in 0..5 {
                    sum[c] += w[c];
                }
                count += 1;
            }
        }
        (count > 0).then(|| sum.map(|s| s / count as f64))
    };
    // The source `j`'s state at node `i`: carried along its gradient over its own sources.
    let carried = |j: usize, i: usize| -> [f64; 5] {
        let stencil = swept.sources(j).filter(|&m| same_fluid(j, m));
        linear_at(mesh, prim, j, stencil, mesh.coords[i]).unwrap_or(prim[j])
    };
    // Each node on its own, in parallel; the first error in the order of the changes.
    let nodes: Vec<usize> = swept.nodes().collect();
    let filled: Vec<Result<(u32, [f64; 5]), FillError>> = nodes
        .par_iter()
        .map(|&i| {
            let first =
                |j: usize| swept.keeps(j).then(|| if linear { carried(j, i) } else { prim[j] });
            // Second ring for the rest: sources two edges away.
            let second =
                |j: usize| average(j, &|m: usize| (m != i && swept.keeps(m)).then(|| prim[m]));
            average(i, &first).or_else(|| average(i, &second)).map(|w| (i as u32, w)).ok_or(
                FillError { node: i as u32, position: mesh.coords[i], side: swept.sides.side[i] },
            )
        })
        .collect();
    filled.into_iter().collect()
}

/// `W_j + G_j (x - x_j)` with `G_j` the least-squares gradient of `prim` at `j` over the nodes
/// of `stencil`, each increment limited to three times the stencil's
/// largest difference; `None` if the stencil does not span space or the result has `ρ <= 0` or `p <= 0`.
fn linear_at(
    mesh: &Mesh,
    prim: &[[f64; 5]],
    j: usize,
    stencil: impl Iterator<Item = usize>,
    x: [f64; 3],
) -> Option<[f64; 5]> {
    let xj = mesh.coords[j];
    let (mut m, mut b, mut range) = ([[0.0; 3]; 3], [[0.0; 3]; 5], [0.0f64; 5]);
    let mut scale = 0.0f64;
    for n in stencil {
        let d: [f64; 3] = std::array::from_fn(|a| mesh.coords[n][a] - xj[a]);
        for a in 0..3 {
            for c in 0..3 {
                m[a][c] += d[a] * d[c];
            }
        }
        for k in 0..5 {
            let dw = prim[n][k] - prim[j][k];
            range[k] = range[k].max(dw.abs());
            for a in 0..3 {
                b[k][a] += d[a] * dw;
            }
        }
        scale = scale.max(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    }
    let inv = inverse3(m, scale)?;
    let dx: [f64; 3] = std::array::from_fn(|a| x[a] - xj[a]);
    let w: [f64; 5] = std::array::from_fn(|k| {
        let g: [f64; 3] = std::array::from_fn(|a| (0..3).map(|c| inv[a][c] * b[k][c]).sum());
        let inc = g[0] * dx[0] + g[1] * dx[1] + g[2] * dx[2];
        prim[j][k] + inc.clamp(-3.0 * range[k], 3.0 * range[k])
    });
    (w[0] > 0.0 && w[4] > 0.0).then_some(w)
}

/// The inverse of the symmetric 3x3 matrix `m` whose entries scale like `scale`, or `None` if it
/// is singular relative to that scale.
fn inverse3(m: [[f64; 3]; 3], scale: f64) -> Option<[[f64; 3]; 3]> {
    let c = |a: usize, b: usize| {
        let (a1, a2, b1, b2) = ((a + 1) % 3, (a + 2) % 3, (b + 1) % 3, (b + 2) % 3);
        m[b1][a1] * m[b2][a2] - m[b1][a2] * m[b2][a1]
    };
    let det = m[0][0] * c(0, 0) + m[0][1] * c(1, 0) + m[0][2] * c(2, 0);
    if det.is_nan() || det.abs() <= 1e-9 * scale * scale * scale {
        return None;
    }
    Some(std::array::from_fn(|a| std::array::from_fn(|b| c(a, b) / det)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::embedded::generate::plate;
    use crate::embedded::status::NodeStatus;
    use crate::embedded::tracker::{Seed, Tracker};
    use crate::embedded::Surface;
    use crate::mesh::boxmesh::{BoxCells, BoxSpec};
    use interface_protocol::case::Tracking;

    /// A wall closing a tube moves 0.6 cells towards the body side: the nodes it uncovers become
    /// active and take the state of their fluid neighbours (uniform here, so exactly it), and a
    /// wall that jumps three cells leaves nodes no neighbour can fill, named in the error.
    #[test]
    fn uncovered_nodes_take_their_neighbours_state() {
        let spec = BoxSpec::uniform([0.0; 3], [1.0, 0.2, 0.2], [10, 2, 2], BoxCells::Tet);
        let mesh = Mesh::build(spec.raw().unwrap()).unwrap();
        let wall = |x: f64| plate([x, -0.1, -0.1], [0.0, 0.4, 0.0], [0.0, 0.0, 0.4], [2, 2]);
        let s0 = wall(0.55);
        let surface = Surface::new(&s0.elements, s0.x.clone(), 0).unwrap();
        let seeds =
            [Seed { point: [0.0; 3], fluid: true }, Seed { point: [1.0, 0.0, 0.0], fluid: false }];
        let mut tracker = Tracker::new(&mesh, surface, Tracking::Collision, &seeds).unwrap();
        let was_active = tracker.active.clone();
        let n_active = was_active.iter().filter(|a| **a).count();
        let w = [1.2, 3.0, 0.0, 0.0, 1e5];
        let prim: Vec<[f64; 5]> =
            (0..mesh.n_nodes()).map(|i| if was_active[i] { w } else { [f64::NAN; 5] }).collect();
        let s1 = wall(0.61);
        let v = vec![[1.0, 0.0, 0.0]; s1.x.len()];
        let changes = tracker.advance(&mesh, 0.06, &s1.x, &v).unwrap();
        let gained: Vec<u32> =
            changes.iter().filter(|c| c.new_status == NodeStatus::Active).map(|c| c.node).collect();
        assert_eq!(tracker.active.iter().filter(|a| **a).count(), n_active + gained.len());
        assert!(
            !gained.is_empty()
                && gained.iter().all(|&i| (mesh.coords[i as usize][0] - 0.6).abs() < 1e-12)
        );
        let filled = fill_changed(
            &Swept::new(&mesh, &tracker, &changes, &was_active),
            &prim,
            |_, _| true,
            false,
        )
        .unwrap();
        assert_eq!(filled.iter().map(|f| f.0).collect::<Vec<_>>(), gained);
        assert!(filled.iter().all(|f| f.1 == w), "{filled:?}");
        // A linear pressure: the linear fill gives it at the new nodes, the plain average is a
        // cell's gradient off.
        let p = |x: [f64; 3]| 1e5 + 2e3 * x[0] - 7e2 * x[1] + 3e2 * x[2];
        let prim: Vec<[f64; 5]> = (0..mesh.n_nodes())
            .map(|i| if was_active[i] { [1.2, 3.0, 0.0, 0.0, p(mesh.coords[i])] } else { prim[i] })
            .collect();
        for linear in [false, true] {
            let filled = fill_changed(
                &Swept::new(&mesh, &tracker, &changes, &was_active),
                &prim,
                |_, _| true,
                linear,
            )
            .unwrap();
            for (i, w) in filled {
                let err = (w[4] - p(mesh.coords[i as usize])).abs();
                match linear {
                    true => assert!(err < 1e-9, "node {i}: {err}"),
                    false => assert!(err > 1.0, "node {i}: {err}"),
                }
            }
        }

        let mut tracker = Tracker::new(
            &mesh,
            Surface::new(&s0.elements, s0.x.clone(), 0).unwrap(),
            Tracking::Collision,
            &seeds,
        )
        .unwrap();
        let s2 = wall(0.95);
        let changes = tracker.advance(&mesh, 0.4, &s2.x, &v).unwrap();
        let e = fill_changed(
            &Swept::new(&mesh, &tracker, &changes, &was_active),
            &prim,
            |_, _| true,
            true,
        )
        .unwrap_err();
        assert!(mesh.coords[e.node as usize][0] > 0.75, "{e}");
    }
}
