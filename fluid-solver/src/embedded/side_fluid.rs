//! The fluid of a node that changes side (DESIGN §5, "swept nodes"): a node the surface sweeps to
//! its other side, or uncovers, takes the fluid of its new side before its state is filled
//! ([`super::fill`]). Water on one side of a shell and air on the other: an air node the shell
//! passes becomes a water node.
//!
//! Rule: the material most of its sources hold, a source being a neighbour through an edge the
//! surface does not cut now, on the same side, active before and after the step and not changed
//! in it (the nodes [`super::fill::fill_changed`] averages); ties go to the lower material id. A
//! node with no source keeps its material (the fill then looks two edges away, or fails naming
//! the node).

use super::swept::Swept;
use crate::state::MaterialId;

/// The material layout after the changes of a step, or `None` when no node changes fluid.
pub fn side_materials(swept: &Swept, material: &[MaterialId]) -> Option<Vec<MaterialId>> {
    let mut out: Option<Vec<MaterialId>> = None;
    for i in swept.nodes() {
        let mut count = [0u32; 256];
        for j in swept.sources(i) {
            count[material[j] as usize] += 1;
        }
        // The most common material of the sources, the lower id on a tie.
        let (best, n) = count
            .iter()
            .enumerate()
            .fold((0, 0), |(b, n), (m, &k)| if k > n { (m, k) } else { (b, n) });
        if n > 0 && best as MaterialId != material[i] {
            out.get_or_insert_with(|| material.to_vec())[i] = best as MaterialId;
        }
    }
    out
}

/// The level set of the swept nodes that are active now (with a level set and a surface
/// together): the mean `φ` of their sources that hold their new material `material[i]` (from
/// [`side_materials`]), so the sign of `φ` gives that material; a node with no such source keeps
/// its `φ` (and, having no source at all, its material). `(node, φ)`, ascending by change.
pub fn side_phi(swept: &Swept, material: &[MaterialId], phi: &[f64]) -> Vec<(usize, f64)> {
    swept
        .nodes()
        .filter_map(|i| {
            let (sum, n) = swept
                .sources(i)
                .filter(|&j| material[j] == material[i])
                .fold((0.0, 0usize), |(s, n), j| (s + phi[j], n + 1));
            (n > 0).then(|| (i, sum / n as f64))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::embedded::generate::plate;
    use crate::embedded::tracker::{Seed, Tracker};
    use crate::embedded::Surface;
    use crate::mesh::boxmesh::{BoxCells, BoxSpec};
    use crate::mesh::Mesh;
    use interface_protocol::case::Tracking;

    /// A shell with fluid 1 left of it and fluid 0 right moves 0.6 cells to the right: the nodes
    /// it passes change side and take fluid 1; every other node keeps its fluid.
    #[test]
    fn nodes_a_shell_passes_take_the_fluid_of_their_new_side() {
        let spec = BoxSpec::uniform([0.0; 3], [1.0, 0.2, 0.2], [10, 2, 2], BoxCells::Tet);
        let mesh = Mesh::build(spec.raw().unwrap()).unwrap();
        let wall = |x: f64| plate([x, -0.1, -0.1], [0.0, 0.4, 0.0], [0.0, 0.0, 0.4], [2, 2]);
        let s0 = wall(0.55);
        let surface = Surface::new(&s0.elements, s0.x.clone(), 0).unwrap();
        let seeds =
            [Seed { point: [0.0; 3], fluid: true }, Seed { point: [1.0, 0.0, 0.0], fluid: true }];
        let mut tracker = Tracker::new(&mesh, surface, Tracking::Collision, &seeds).unwrap();
        let material: Vec<MaterialId> =
            mesh.coords.iter().map(|x| if x[0] < 0.55 { 1 } else { 0 }).collect();
        let was_active = tracker.active.clone();
        let s1 = wall(0.61);
        let v = vec![[1.0, 0.0, 0.0]; s1.x.len()];
        let changes = tracker.advance(&mesh, 0.06, &s1.x, &v).unwrap();
        let swept = Swept::new(&mesh, &tracker, &changes, &was_active);
        let new = side_materials(&swept, &material).expect("the swept nodes change fluid");
        let passed: Vec<usize> = (0..mesh.n_nodes()).filter(|&i| new[i] != material[i]).collect();
        assert!(!passed.is_empty());
        for i in 0..mesh.n_nodes() {
            let x = mesh.coords[i][0];
            let expected = if x < 0.61 { 1 } else { 0 };
            assert_eq!(new[i], expected, "node {i} at x = {x}");
        }
        assert!(passed.iter().all(|&i| (mesh.coords[i][0] - 0.6).abs() < 1e-12), "{passed:?}");
        // Nothing moves: no change of fluid.
        let was_active = tracker.active.clone();
        let changes = tracker.advance(&mesh, 0.07, &s1.x, &vec![[0.0; 3]; s1.x.len()]).unwrap();
        let swept = Swept::new(&mesh, &tracker, &changes, &was_active);
        let same = side_materials(&swept, &new);
        assert_eq!(same, None);
    }
}
