//! The gradient of the level set (DESIGN §5): least squares through every edge of the mesh, so
//! straight across the material interface (`φ` is continuous there, unlike the density), with
//! the mirror planes of the flow's operator at symmetry planes and plane slip walls (`φ` is a
//! scalar, even under the reflection). The flow's own gradients stay same-fluid: their operator
//! masks the two-material edges ([`crate::semidiscretization::Semidiscretization::set_materials`]).
//! With an embedded surface the edges it cuts, and those with an end that is not active, are
//! masked out too ([`crate::embedded::level_set::PhiWall`]).

use crate::reconstruct::gradient::LsqGradient;
use crate::semidiscretization::Semidiscretization;

/// The operator of `∇φ` on the mesh of `semi`: no edge masked, the mirror planes of `semi`.
pub fn phi_gradient(semi: &Semidiscretization) -> LsqGradient {
    LsqGradient::with_planes(&semi.mesh, None, semi.gradient.planes().clone())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bc::BoundaryCondition;
    use crate::eos::Eos;
    use crate::mesh::boxmesh::{BoxCells, BoxSpec, FACE_NAMES};
    use crate::mesh::{perturb, Mesh};
    use crate::semidiscretization::Numerics;

    /// A linear `φ` has its exact gradient at every node, also at the nodes of two-material edges
    /// (whose flow gradients are masked) and on the symmetry planes (tangential `∇φ`).
    #[test]
    fn phi_gradient_is_exact_for_linear_phi_across_the_interface() {
        let mut raw = BoxSpec::uniform([0.0; 3], [1.0; 3], [6, 5, 4], BoxCells::Tet).raw().unwrap();
        perturb(&mut raw, 0.2, 7);
        let mesh = Mesh::build(raw).unwrap();
        let g = [0.3, -1.2, 0.7];
        let phi: Vec<[f64; 1]> =
            mesh.coords.iter().map(|x| [g[0] * x[0] + g[1] * x[1] + g[2] * x[2] - 0.4]).collect();
        let material: Vec<u8> = phi.iter().map(|p| u8::from(p[0] >= 0.0)).collect();
        assert!(material.contains(&0) && material.contains(&1));
        // Slip walls everywhere: every boundary node has a mirror plane, so only the normal
        // component of the exact gradient is dropped there.
        let walls: Vec<(String, BoundaryCondition)> =
            FACE_NAMES.iter().map(|n| (n.to_string(), BoundaryCondition::SlipWall)).collect();
        let eos = vec![Eos::PerfectGas { gamma: 1.4 }, Eos::PerfectGas { gamma: 1.67 }];
        let semi =
            Semidiscretization::with_materials(mesh, eos, material, Numerics::default(), &walls)
                .unwrap();
        let op = phi_gradient(&semi);
        let mut grad = vec![[[0.0; 3]]; semi.mesh.n_nodes()];
        op.compute(&semi.mesh, &phi, &mut grad);
        let boundary: Vec<bool> = {
            let mut b = vec![false; semi.mesh.n_nodes()];
            for p in &semi.mesh.boundaries {
                for &i in &p.nodes {
                    b[i as usize] = true;
                }
            }
            b
        };
        let mut interior = 0;
        for (i, gi) in grad.iter().enumerate() {
            if boundary[i] {
                continue;
            }
            interior += 1;
            for k in 0..3 {
                assert!((gi[0][k] - g[k]).abs() < 1e-12, "node {i}: {:?} vs {g:?}", gi[0]);
            }
        }
        assert!(interior > 20);
    }
}
