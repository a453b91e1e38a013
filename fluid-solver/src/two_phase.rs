//! Edges between two fluids (thesis §3.3.2, Eq. 3.9; DESIGN §5): the two-phase ghost-fluid flux.
//!
//! At an edge `i -> j` whose end nodes hold different materials, the exact two-phase Riemann
//! problem along a direction `n̂` between the nodal states `W_i` (EOS_i) and `W_j` (EOS_j)
//! gives the star states on each side of the contact, `W*_i = (ρ*_i, v_i + (u* - v_i·n̂) n̂, p*)`
//! and likewise `W*_j`; each node then takes the single-material flux of the scheme between its
//! own state and its side's star state through the edge's facet, with its own EOS
//! ([`crate::flux::two_phase_flux_along`]): `R_i += F(W_i, W*_i, EOS_i, ν_ij)` and
//! `R_j -= F(W*_j, W_j, EOS_j, ν_ij)` (the j-side flux is along `+ν`, so it is subtracted as in
//! the ordinary loop). No flux mixes the two EOS.
//!
//! The direction ([`direction`]): with a level set, the interface normal
//! `(∇φ_i + ∇φ_j)/|∇φ_i + ∇φ_j|` of the step's `φⁿ` ([`Semidiscretization::interface`]), pointing
//! from `i`'s fluid into `j`'s; else the edge's `ν_ij/|ν_ij|`. The contact is a 1D problem along
//! the interface's normal: along an edge oblique to the interface the problem along `ν̂` would
//! carry the whole pressure jump, not its normal projection, and drive the contact along every
//! such edge as fast as along the normal. On axis-aligned hexes around a sphere (the underwater
//! bubble) the facets' volume flux `Σ u* |ν|` then exceeds the interface's own `∫ u*_n dA` while
//! the pressure jumps (the bubble's acceleration); the gas nodes lost that mass through their
//! facets but the level set, moving at the normal speed, did not hand them the nodes it would
//! have filled (the gas lost 20% of its mass in the first 0.2 ms, see the case's README). Where
//! `ν̂` is the normal (a planar interface across a tube of hexes) both are the same problem.
//!
//! The Riemann problem takes the nodal states, as in the thesis (Eq. 3.9 is initialised by
//! `W_i` and `W_j`): the interface is first order. The two fluxes differ by the jump the contact
//! carries, so the scheme is not conservative at the interface: `Σ_i R_i` equals the boundary flux
//! plus `Σ (F_i - F_j)` over the two-material edges (zero for a contact at rest at equal
//! pressure, whose two fluxes are both the pressure flux `p ν`).
//!
//! Cavitation (DESIGN §5.1): the star pressure is cut off at the larger of the two fluids'
//! default cut-offs ([`cutoff`]), so a liquid next to a gas never returns tension.

use crate::eos::Eos;
use crate::flux::two_phase_flux_along;
use crate::mesh::blocks::Window;
use crate::riemann::PressureCutoff;
use crate::semidiscretization::{FluidError, Semidiscretization};

/// Adds the two-phase fluxes of edge `e` (its ends hold different materials) to the residuals of
/// its ends.
pub(crate) fn edge_flux(
    semi: &Semidiscretization,
    e: usize,
    prim: &[[f64; 5]],
    r: &mut Window<'_, [f64; 5]>,
) -> Result<(), FluidError> {
    let mesh = &semi.mesh;
    let [i, j] = mesh.edges[e];
    let (i, j) = (i as usize, j as usize);
    let (eos_i, eos_j) = (semi.eos_at(i), semi.eos_at(j));
    let n = &mesh.edge_normals[e];
    let f = two_phase_flux_along(
        semi.numerics.flux,
        eos_i,
        &prim[i],
        eos_j,
        &prim[j],
        n,
        direction(semi, i, j, n),
        cutoff(eos_i, eos_j),
    )
    .map_err(|error| {
        let m = semi.material();
        FluidError::TwoPhase {
            edge: e,
            nodes: [i, j],
            materials: [m[i], m[j]],
            position: mesh.coords[i],
            error,
        }
    })?;
    for k in 0..5 {
        r[i][k] += f.flux_i[k];
    }
    for k in 0..5 {
        r[j][k] -= f.flux_j[k];
    }
    Ok(())
}

/// The direction of the two-phase problem of the edge `i -> j` with normal `n`: the interface
/// normal `(∇φ_i + ∇φ_j)/|∇φ_i + ∇φ_j|` pointing from `i`'s fluid into `j`'s, where a level set
/// gives it (module docs), else `n/|n|`.
pub fn direction(semi: &Semidiscretization, i: usize, j: usize, n: &[f64; 3]) -> [f64; 3] {
    let along_n = || {
        let a = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        [n[0] / a, n[1] / a, n[2] / a]
    };
    let Some(normals) = &semi.interface else {
        return along_n();
    };
    let (gi, gj) = (normals.grad_phi[i], normals.grad_phi[j]);
    let g = [gi[0] + gj[0], gi[1] + gj[1], gi[2] + gj[2]];
    let norm = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
    if norm == 0.0 || !norm.is_finite() {
        return along_n();
    }
    let sign = if semi.material()[j] == normals.toward { 1.0 } else { -1.0 };
    [sign * g[0] / norm, sign * g[1] / norm, sign * g[2] / norm]
}

/// The cavitation cut-off of a two-phase problem between `a` and `b`: the larger of their
/// defaults ([`PressureCutoff::default_for`]: the vapour pressure of water for a liquid, none for
/// a perfect gas).
#[inline]
pub fn cutoff(a: &Eos, b: &Eos) -> PressureCutoff {
    let p_cut = PressureCutoff::default_for(a).p_cut.max(PressureCutoff::default_for(b).p_cut);
    PressureCutoff { p_cut }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bc::BoundaryCondition;
    use crate::flux::{two_phase_flux_with_cutoff, FluxScheme};
    use crate::mesh::boxmesh::{BoxCells, BoxSpec, FACE_NAMES};
    use crate::mesh::geometry::{dot, sub};
    use crate::mesh::Mesh;
    use crate::riemann::{self, State1d};
    use crate::semidiscretization::{InterfaceNormals, Numerics};

    const WATER: Eos = Eos::StiffenedGas { gamma: 4.4, p_c: 6e8 };
    const GAS: Eos = Eos::PerfectGas { gamma: 1.4 };

    /// Gas (material 1) where `x + y < 0.45` on a box of hexes, water (0) elsewhere: a planar
    /// interface at 45° to the x and y edges; with `interface`, `∇φ = (-1, -1, 0)` (φ >= 0 on
    /// the gas side) at every node.
    fn oblique(interface: bool) -> Semidiscretization {
        let mesh = Mesh::build(
            BoxSpec::uniform([0.0; 3], [1.0; 3], [4, 4, 1], BoxCells::Hex).raw().unwrap(),
        )
        .unwrap();
        let material = mesh.coords.iter().map(|x| u8::from(x[0] + x[1] < 0.45)).collect();
        let walls: Vec<(String, BoundaryCondition)> =
            FACE_NAMES.iter().map(|n| (n.to_string(), BoundaryCondition::SlipWall)).collect();
        let mut semi = Semidiscretization::with_materials(
            mesh,
            vec![WATER, GAS],
            material,
            Numerics::default(),
            &walls,
        )
        .unwrap();
        if interface {
            let n = semi.mesh.n_nodes();
            semi.interface =
                Some(InterfaceNormals { grad_phi: vec![[-1.0, -1.0, 0.0]; n], toward: 1 });
        }
        semi
    }

    /// With a level set every edge between the fluids solves its problem along the interface
    /// normal, pointing from its first end's fluid into the second's; without one, along the
    /// edge. At gas (10 MPa) | water (1 MPa) at rest the star velocity is then the planar
    /// problem's `u*` on an edge at 45° to the interface, and along the edge the same `u*` again
    /// (the whole jump carried along the edge, whose normal projection is `u*/√2`).
    #[test]
    fn an_oblique_edge_solves_the_problem_along_the_interface_normal() {
        let (with, without) = (oblique(true), oblique(false));
        let m = with.material();
        let e = (0..with.mesh.n_edges())
            .find(|&e| {
                let [i, j] = with.mesh.edges[e];
                m[i as usize] != m[j as usize]
            })
            .unwrap();
        let [i, j] = with.mesh.edges[e].map(|k| k as usize);
        let n = with.mesh.edge_normals[e];
        let d = direction(&with, i, j, &n);
        let s = std::f64::consts::FRAC_1_SQRT_2;
        let sign = if m[j] == 1 { -1.0 } else { 1.0 };
        for k in 0..2 {
            assert!((d[k] - sign * s).abs() < 1e-15, "{d:?}");
        }
        assert_eq!(d[2], 0.0);
        // From i's fluid into j's: along d, x_j lies beyond x_i.
        assert!(dot(d, sub(with.mesh.coords[j], with.mesh.coords[i])) > 0.0);
        let a = dot(n, n).sqrt();
        let along_edge = direction(&without, i, j, &n);
        assert!((0..3).all(|k| (along_edge[k] - n[k] / a).abs() < 1e-15));

        let (gas, water) = ([10.0, 0.0, 0.0, 0.0, 1e7], [1000.0, 0.0, 0.0, 0.0, 1e6]);
        let (wi, wj) = if m[i] == 1 { (gas, water) } else { (water, gas) };
        let (ei, ej) = (with.eos_at(i), with.eos_at(j));
        let planar = riemann::solve(
            ei,
            State1d { rho: wi[0], u: 0.0, p: wi[4] },
            ej,
            State1d { rho: wj[0], u: 0.0, p: wj[4] },
        )
        .unwrap();
        let cut = cutoff(ei, ej);
        let f = two_phase_flux_along(FluxScheme::Roe, ei, &wi, ej, &wj, &n, d, cut).unwrap();
        let g = two_phase_flux_with_cutoff(FluxScheme::Roe, ei, &wi, ej, &wj, &n, cut).unwrap();
        assert!((f.star.u - planar.u).abs() < 1e-9 * planar.u.abs(), "{} {}", f.star.u, planar.u);
        assert!((g.star.u - planar.u).abs() < 1e-9 * planar.u.abs());
        // The same problem when the direction is the edge's own.
        let h = two_phase_flux_along(FluxScheme::Roe, ei, &wi, ej, &wj, &n, along_edge, cut);
        assert_eq!(h.unwrap().flux_i, g.flux_i);
    }
}
