//! Material changes (thesis §3.3.2, DESIGN §5): after a step each node takes the material of the
//! side of its `φ`; a node whose material changed from `a` to `b` takes the ghost state of the
//! exact two-phase Riemann problem it had with its neighbours of fluid `b`.
//!
//! The problem is solved along the interface normal at the node, `n̂ = ±∇φ_i/|∇φ_i|` pointing from
//! fluid `a` into fluid `b` (the level set's normal: on a 1D tube of tets exactly the axis, where
//! the normals of single edges are not), between `W_i` (EOS_a) and `W̄_b`, the mean primitive
//! state of the neighbours that held `b` at `t^n` (EOS_b; at a node on symmetry planes each
//! neighbour counted with its mirror images, [`crate::symmetry::SymmetryPlanes::images`], so that
//! the mean is that of the whole mirrored stencil), with the cavitation cut-off of the pair
//! ([`crate::two_phase::cutoff`]). Its star state on `b`'s side of the contact, `(ρ*_b, u*, p*)`,
//! gives the ghost state `W = (ρ*_b, v_i + (u* - v_i·n̂) n̂, p*)` (the node keeps its tangential
//! velocity, as in the ghost-fluid flux), and the node's conserved variables are recomputed with
//! EOS_b. All states are read before any is written, so the result does not depend on the node
//! order. A uniform flow (equal `u` and `p` on both sides) gives the other fluid's state exactly.

use super::LevelSet;
use crate::mesh::geometry::{add, dot, norm, scale, sub};
use crate::riemann::{self, State1d};
use crate::semidiscretization::{FluidError, Semidiscretization};
use crate::state::State;

/// Sets `state.material` to the side of `state.phi` and gives every node whose material changed
/// its ghost state (module docs), with `semi` still holding the layout of `t^n` and `grad_phi`
/// the gradient of `state.phi`; the neighbours are those through the edges `e` with `through[e]`
/// (`None`: all; with an embedded surface, never across it). Returns the number of changed
/// nodes. On error `state` is unchanged.
pub fn update_materials(
    semi: &Semidiscretization,
    ls: &LevelSet,
    grad_phi: &[[[f64; 3]; 1]],
    state: &mut State,
    through: Option<&[bool]>,
) -> Result<usize, FluidError> {
    let mesh = &semi.mesh;
    let old = &state.material;
    let changed: Vec<usize> =
        (0..state.len()).filter(|&i| ls.material_of(state.phi[i]) != old[i]).collect();
    let mut ghosts = Vec::with_capacity(changed.len());
    for &i in &changed {
        let (a, b) = (old[i], ls.material_of(state.phi[i]));
        let (eos_a, eos_b) = (&semi.eos[a as usize], &semi.eos[b as usize]);
        let wi = eos_a.cons_to_prim(&state.cons[i]);
        // The neighbours of fluid b: their mean state, and the mean direction towards them; on
        // symmetry planes each neighbour counts with its mirror images.
        let mut wb = [0.0; 5];
        let mut towards = [0.0; 3];
        let mut count = 0.0;
        for (j, e) in ls.adjacency.neighbours(mesh, i) {
            if old[j] == b && through.is_none_or(|t| t[e as usize]) {
                let wj = eos_b.cons_to_prim(&state.cons[j]);
                let d = sub(mesh.coords[j], mesh.coords[i]);
                let images = semi.symmetry.images(i, d);
                for k in 0..5 {
                    wb[k] += images * wj[k];
                }
                towards = add(towards, scale(d, images));
                count += images;
            }
        }
        if count == 0.0 {
            return Err(FluidError::LevelSet(format!(
                "node {i} (x = {:?}) changed from material {a} to {b}, but none of its \
                 neighbours held material {b}: the interface moved more than one edge in a step \
                 (lower the CFL number)",
                mesh.coords[i]
            )));
        }
        let wb = wb.map(|s| s / count);
        // ∇φ points to φ >= 0, the side of materials[1].
        let g = grad_phi[i][0];
        let to_b = if b == ls.materials[1] { 1.0 } else { -1.0 };
        let nh = if norm(g) > 0.0 {
            scale(g, to_b / norm(g))
        } else {
            scale(towards, 1.0 / norm(towards))
        };
        let vi = [wi[1], wi[2], wi[3]];
        let ui = dot(vi, nh);
        let star = riemann::solve_with_cutoff(
            eos_a,
            State1d { rho: wi[0], u: ui, p: wi[4] },
            eos_b,
            State1d { rho: wb[0], u: dot([wb[1], wb[2], wb[3]], nh), p: wb[4] },
            crate::two_phase::cutoff(eos_a, eos_b),
        )
        .map_err(|error| FluidError::Ghost {
            node: i,
            materials: [a, b],
            position: mesh.coords[i],
            error,
        })?
        .state;
        let dv = star.u - ui;
        let p = if eos_b.is_barotropic() { eos_b.tait_pressure(star.rho_r) } else { star.p };
        let w = [star.rho_r, vi[0] + dv * nh[0], vi[1] + dv * nh[1], vi[2] + dv * nh[2], p];
        ghosts.push((i, b, eos_b.prim_to_cons(&w)));
    }
    for &(i, b, q) in &ghosts {
        state.cons[i] = q;
        state.material[i] = b;
    }
    Ok(changed.len())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bc::BoundaryCondition;
    use crate::eos::Eos;
    use crate::mesh::boxmesh::{BoxCells, BoxSpec, FACE_NAMES};
    use crate::mesh::Mesh;
    use crate::semidiscretization::Numerics;

    const WATER: Eos = Eos::StiffenedGas { gamma: 4.4, p_c: 6e8 };
    const AIR: Eos = Eos::PerfectGas { gamma: 1.4 };

    fn tube(n: usize) -> Semidiscretization {
        let mesh =
            Mesh::build(BoxSpec::tube(0.0, 1.0, n, 1.0 / n as f64, BoxCells::Tet).raw().unwrap())
                .unwrap();
        let material = mesh.coords.iter().map(|x| u8::from(x[0] > 0.5)).collect();
        let walls: Vec<(String, BoundaryCondition)> =
            FACE_NAMES.iter().map(|n| (n.to_string(), BoundaryCondition::SlipWall)).collect();
        Semidiscretization::with_materials(
            mesh,
            vec![WATER, AIR],
            material,
            Numerics::default(),
            &walls,
        )
        .unwrap()
    }

    /// `∇φ` of `φ = x - 0.49`.
    fn along_x(semi: &Semidiscretization) -> Vec<[[f64; 3]; 1]> {
        vec![[[1.0, 0.0, 0.0]]; semi.mesh.n_nodes()]
    }

    /// Water (x <= 0.5) and air; `φ` moved so that the water nodes at x = 0.5 turn to air.
    fn moved(semi: &Semidiscretization, water: [f64; 5], air: [f64; 5]) -> (LevelSet, State) {
        let ls = LevelSet::new(semi, [0, 1], 0);
        let m = semi.material().to_vec();
        let cons = m
            .iter()
            .map(|&k| if k == 0 { WATER.prim_to_cons(&water) } else { AIR.prim_to_cons(&air) })
            .collect();
        let phi = semi.mesh.coords.iter().map(|x| x[0] - 0.49).collect();
        (ls, State { cons, material: m, phi })
    }

    /// In a uniform flow (equal u and p) a node turning to air takes the air state exactly.
    #[test]
    fn a_node_in_a_uniform_flow_takes_the_other_fluid_state() {
        let semi = tube(10);
        let (water, air) = ([1000.0, 30.0, 0.0, 0.0, 2e5], [1.2, 30.0, 0.0, 0.0, 2e5]);
        let (ls, mut state) = moved(&semi, water, air);
        let changed = update_materials(&semi, &ls, &along_x(&semi), &mut state, None).unwrap();
        let at_half = semi.mesh.coords.iter().filter(|x| (x[0] - 0.5).abs() < 1e-12).count();
        assert_eq!(changed, at_half);
        for (i, x) in semi.mesh.coords.iter().enumerate() {
            assert_eq!(state.material[i], u8::from(x[0] > 0.49));
            if (x[0] - 0.5).abs() < 1e-12 {
                let w = AIR.cons_to_prim(&state.cons[i]);
                for k in 0..5 {
                    assert!((w[k] - air[k]).abs() <= 1e-12 * air[k].abs(), "{w:?} vs {air:?}");
                }
            }
        }
    }

    /// High-pressure water against air: the changed node takes the air-side star state of the
    /// exact problem along the tube (velocity u*, pressure p*, the air's star density).
    #[test]
    fn a_changed_node_takes_the_star_state_of_its_new_side() {
        let semi = tube(10);
        let (water, air) = ([1000.0, 0.0, 0.0, 0.0, 1e9], [50.0, 0.0, 0.0, 0.0, 1e5]);
        let (ls, mut state) = moved(&semi, water, air);
        let star = riemann::solve(
            &WATER,
            State1d { rho: 1000.0, u: 0.0, p: 1e9 },
            &AIR,
            State1d { rho: 50.0, u: 0.0, p: 1e5 },
        )
        .unwrap();
        update_materials(&semi, &ls, &along_x(&semi), &mut state, None).unwrap();
        let node = (0..semi.mesh.n_nodes())
            .find(|&i| (semi.mesh.coords[i][0] - 0.5).abs() < 1e-12)
            .unwrap();
        let w = AIR.cons_to_prim(&state.cons[node]);
        let exact = [star.rho_r, star.u, 0.0, 0.0, star.p];
        for k in 0..5 {
            let scale = if (1..4).contains(&k) { star.u } else { exact[k] };
            assert!((w[k] - exact[k]).abs() < 1e-12 * scale, "{w:?} vs {exact:?}");
        }
    }
}
