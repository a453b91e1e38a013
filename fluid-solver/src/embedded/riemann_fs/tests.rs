//! Alg. 5.1 at cut edges: the wall flux of `flux/wall.rs` recovered, the star state of the
//! one-sided problem, the j-side sign, the cut-off count and the errors.

use super::*;
use crate::embedded::test_cuts::brute_force_cuts;
use crate::flux::{physical_flux, wall_flux};
use crate::mesh::boxmesh::{BoxCells, BoxSpec};
use crate::riemann::fluid_structure;
use interface_protocol::messages::SurfaceElement;

const AIR: Eos = Eos::PerfectGas { gamma: 1.4 };

/// A 2x2x2 hex mesh of the unit cube, nodes at 0, 0.5, 1 along each axis.
fn cube() -> Mesh {
    Mesh::build(BoxSpec::uniform([0.0; 3], [1.0; 3], [2, 2, 2], BoxCells::Hex).raw().unwrap())
        .unwrap()
}

/// A plane quad through `c` with in-plane axes `a`, `b` (half-widths), moving at `v`.
fn plane(c: [f64; 3], a: [f64; 3], b: [f64; 3], v: [f64; 3]) -> Surface {
    let corner = |s: f64, t: f64| [0, 1, 2].map(|k| c[k] + s * a[k] + t * b[k]);
    let x = vec![corner(-1.0, -1.0), corner(1.0, -1.0), corner(1.0, 1.0), corner(-1.0, 1.0)];
    let e = SurfaceElement { nodes: [0, 1, 2, 3], n_nodes: 4, ..Default::default() };
    let mut s = Surface::new(&[e], x, 0).unwrap();
    s.v_b = vec![v; 4];
    s
}

fn view<'a>(
    mesh: &'a Mesh,
    surface: &'a Surface,
    prim: &'a [[f64; 5]],
    active: &'a [bool],
    materials: &'a [WallMaterial],
    material: &'a [u8],
) -> WallFluxView<'a> {
    WallFluxView {
        mesh,
        surface,
        t: 0.0,
        scheme: FluxScheme::Roe,
        active,
        material,
        materials,
        prim,
        grad: None,
        limiter: Limiter::VanAlbada,
    }
}

fn air() -> [WallMaterial; 1] {
    [WallMaterial { eos: AIR, cutoff: PressureCutoff::OFF }]
}

/// A wall moving with the fluid's normal velocity leaves `W* = W_i`: the flux is the physical
/// flux, and with the wall at rest and the flow tangential, pressure only. It agrees with
/// `flux::wall_flux` bitwise for any wall motion.
#[test]
fn wall_moving_with_the_fluid_gives_the_wall_flux() {
    let mesh = cube();
    let n = mesh.n_nodes();
    let (mats, material, active) = (air(), vec![0u8; n], vec![true; n]);
    for (u, wall) in [(2.0, [2.0, 0.3, 0.0]), (0.0, [0.0; 3]), (-3.0, [5.0, 1.0, -2.0])] {
        let surface = plane([0.3, 0.5, 0.5], [0.0, 0.7, 0.0], [0.0, 0.0, 0.7], wall);
        let cuts = brute_force_cuts(&mesh, &surface, 0.0);
        assert_eq!(cuts.len(), 9, "the x-edges from x = 0 to 0.5");
        let prim = vec![[1.2, u, 0.7, -0.4, 1e5]; n];
        let v = view(&mesh, &surface, &prim, &active, &mats, &material);
        for cut in &cuts {
            let [i, j] = mesh.edges[cut.edge as usize];
            let nu = mesh.edge_normals[cut.edge as usize];
            // The wall normal from i points along x_j - x_i.
            let sx = (mesh.coords[j as usize][0] - mesh.coords[i as usize][0]).signum();
            for (end, node, n_wall, facet) in
                [(End::I, i, [sx, 0.0, 0.0], nu), (End::J, j, [-sx, 0.0, 0.0], nu.map(|c| -c))]
            {
                let w = prim[node as usize];
                let s = one_sided(&v, cut, end).unwrap();
                let reference = wall_flux(FluxScheme::Roe, &AIR, &w, &facet, &n_wall, &wall);
                assert_eq!(s.flux, reference.unwrap().flux);
                if u == wall[0] {
                    assert_eq!((s.p, s.rho), (1e5, 1.2));
                    let f = physical_flux(&AIR, &w, &facet);
                    for k in 0..5 {
                        assert!((s.flux[k] - f[k]).abs() <= 1e-12 * 1e5 * norm(facet), "{k}");
                    }
                    if u == 0.0 {
                        assert!(s.flux[0].abs() <= 1e-13 && s.flux[4].abs() <= 1e-9);
                        assert!((s.flux[1] - 1e5 * facet[0]).abs() <= 1e-9);
                    }
                }
            }
        }
    }
}

/// `(ρ*, p*)` is the one-sided solution along the normal oriented from the end node, for an
/// oblique moving surface and a varied state; the flux is the scheme's `F(W_i, W*, ±ν)`.
#[test]
fn star_state_is_the_fluid_structure_solution() {
    let mesh = cube();
    let n = mesh.n_nodes();
    let (mats, material, active) = (air(), vec![0u8; n], vec![true; n]);
    let a = [0.3, 0.8, 0.1];
    let b = [0.2, -0.1, 0.9];
    let surface = plane([0.47, 0.52, 0.55], a, b, [3.0, -20.0, 7.0]);
    let cuts = brute_force_cuts(&mesh, &surface, 0.0);
    assert!(cuts.len() > 10);
    let prim: Vec<[f64; 5]> = mesh
        .coords
        .iter()
        .map(|x| [1.0 + x[0], 10.0 * x[1] - 3.0, 5.0 * x[2], -4.0 * x[0], 1e5 * (1.0 + x[1])])
        .collect();
    let v = view(&mesh, &surface, &prim, &active, &mats, &material);
    for cut in &cuts {
        let [i, j] = mesh.edges[cut.edge as usize];
        let d = sub(mesh.coords[j as usize], mesh.coords[i as usize]);
        let towards_j = if dot(cut.normal, d) > 0.0 { cut.normal } else { cut.normal.map(|c| -c) };
        let (_, wall) = surface.point_at(cut.triangle as usize, cut.bary, 0.0);
        for (end, node, n_wall) in [(End::I, i, towards_j), (End::J, j, towards_j.map(|c| -c))] {
            let w = prim[node as usize];
            let un = w[1] * n_wall[0] + w[2] * n_wall[1] + w[3] * n_wall[2];
            let exact = fluid_structure(&AIR, w[0], un, w[4], dot(wall, n_wall)).unwrap();
            let s = one_sided(&v, cut, end).unwrap();
            assert_eq!((s.p, s.rho), (exact.p, exact.rho));
            assert!(!s.clipped);
        }
    }
}

/// Mirror-symmetric states about a wall at rest half-way along x-edges: the two ends get the same
/// mass and energy fluxes and opposite normal-momentum fluxes; inactive ends get nothing.
#[test]
fn j_side_sign_is_the_mirror_of_the_i_side() {
    let mesh = cube();
    let n = mesh.n_nodes();
    let (mats, material) = (air(), vec![0u8; n]);
    let surface = plane([0.25, 0.5, 0.5], [0.0, 0.0, 0.8], [0.0, 0.8, 0.0], [0.0; 3]);
    let cuts = brute_force_cuts(&mesh, &surface, 0.0);
    assert_eq!(cuts.len(), 9);
    let prim: Vec<[f64; 5]> = mesh
        .coords
        .iter()
        .map(|x| {
            let u = if x[0] < 0.25 { 30.0 } else { -30.0 };
            [1.3, u, 4.0, -2.0, 1e5]
        })
        .collect();
    let active = vec![true; n];
    let v = view(&mesh, &surface, &prim, &active, &mats, &material);
    for cut in &cuts {
        let fi = one_sided(&v, cut, End::I).unwrap();
        let fj = one_sided(&v, cut, End::J).unwrap();
        let scale = 1e5 * norm(mesh.edge_normals[cut.edge as usize]);
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * scale;
        assert!(fi.p > 1e5 && fi.p == fj.p, "the wall compresses both sides equally");
        assert!(close(fi.flux[0], fj.flux[0]) && close(fi.flux[4], fj.flux[4]));
        let nu = mesh.edge_normals[cut.edge as usize];
        assert!(close(fi.flux[1], -fj.flux[1]) && fi.flux[1] * nu[0] > 0.0);
        assert!(close(fi.flux[2], fj.flux[2]) && close(fi.flux[3], fj.flux[3]));
    }
    // The block loop: both ends added; an inactive end gets no flux and a NaN p*.
    let mut active = vec![true; n];
    let [_, j0] = mesh.edges[cuts[0].edge as usize];
    active[j0 as usize] = false;
    let v = view(&mesh, &surface, &prim, &active, &mats, &material);
    let mut r = vec![[0.0; 5]; n];
    let mut p_star = vec![[0.0; 2]; cuts.len()];
    let clips = add_wall_fluxes(&v, &cuts, &mut Window::new(0, &mut r), &mut p_star).unwrap();
    assert_eq!(clips, 0);
    assert!(p_star[0][1].is_nan() && r[j0 as usize] == [0.0; 5]);
    let [i0, _] = mesh.edges[cuts[0].edge as usize];
    assert_eq!(r[i0 as usize], one_sided(&v, &cuts[0], End::I).unwrap().flux);
    assert_eq!(cuts_in(&cuts, 0..mesh.n_edges()), 0..cuts.len());
    assert_eq!(cuts_in(&cuts, 0..cuts[0].edge as usize), 0..0);
}

/// Tait water behind a wall receding at 1000 m/s (beyond the escape speed): without the cut-off
/// an error naming the edge, node and element; with it every active end clipped to `p_cut`.
#[test]
fn receding_wall_in_water_errors_without_cutoff_and_clips_with_it() {
    let mesh = cube();
    let n = mesh.n_nodes();
    let tait = Eos::tait(2.07e9, 7.15, 1000.0, 1e5);
    let surface = plane([0.25, 0.5, 0.5], [0.0, 0.8, 0.0], [0.0, 0.0, 0.8], [1000.0, 0.0, 0.0]);
    let cuts = brute_force_cuts(&mesh, &surface, 0.0);
    let prim = vec![[1000.0, 0.0, 0.0, 0.0, tait.tait_pressure(1000.0)]; n];
    let (material, mut active) = (vec![0u8; n], vec![true; n]);
    for (k, x) in mesh.coords.iter().enumerate() {
        active[k] = x[0] < 0.25;
    }
    let mut r = vec![[0.0; 5]; n];
    let mut p_star = vec![[0.0; 2]; cuts.len()];
    let off = [WallMaterial { eos: tait, cutoff: PressureCutoff::OFF }];
    let v = view(&mesh, &surface, &prim, &active, &off, &material);
    let err = add_wall_fluxes(&v, &cuts, &mut Window::new(0, &mut r), &mut p_star).unwrap_err();
    assert_eq!(err.edge, cuts[0].edge);
    let [i0, j0] = mesh.edges[cuts[0].edge as usize];
    assert_eq!(err.node, if active[i0 as usize] { i0 } else { j0 });
    assert_eq!(err.element, 0);
    assert!(matches!(err.error, RiemannError::Vacuum { .. }));
    let msg = err.to_string();
    assert!(msg.contains(&format!("cut edge {}", err.edge)) && msg.contains("structure element 0"));
    let on = [WallMaterial { eos: tait, cutoff: PressureCutoff::default_for(&tait) }];
    let v = view(&mesh, &surface, &prim, &active, &on, &material);
    let clips = add_wall_fluxes(&v, &cuts, &mut Window::new(0, &mut r), &mut p_star).unwrap();
    assert_eq!(clips, cuts.len());
    for (c, p) in cuts.iter().zip(&p_star) {
        let [i, _] = mesh.edges[c.edge as usize];
        let (wet, dry) = if active[i as usize] { (p[0], p[1]) } else { (p[1], p[0]) };
        assert!(wet == 2339.0 && dry.is_nan(), "{p:?}");
    }
}

/// The orientation rule: towards the wall by `n_E · d`, by the facet for an edge parallel to the
/// surface, `+n_E` when both vanish.
#[test]
fn wall_normal_orientation_rule() {
    let n_e = [0.0, 0.0, 1.0];
    assert_eq!(wall_normal_from_i(n_e, [0.0, 0.0, -2.0], [0.0, 0.0, -1.0]), [0.0, 0.0, -1.0]);
    assert_eq!(wall_normal_from_i(n_e, [1.0, 0.0, 1e-10], [0.0, 0.0, -1.0]), [0.0, 0.0, -1.0]);
    assert_eq!(wall_normal_from_i(n_e, [1.0, 0.0, 0.0], [1.0, 0.0, 0.0]), n_e);
}

/// The second-order interface on a linear field whose velocity at the wall is the wall's: the
/// wall state is the field at the intersection, so both facet states are the field at the edge
/// midpoint and the flux is its physical flux, for walls before and beyond the midpoint and from
/// both ends; the first-order form is off by the field's change over half an edge. A uniform
/// state the wall moves with gives the physical flux to round-off.
#[test]
fn second_order_interface_is_exact_for_linear_fields() {
    let mesh = cube();
    let n = mesh.n_nodes();
    let (mats, material, active) = (air(), vec![0u8; n], vec![true; n]);
    let g = [[0.2, 0.0, 0.0], [40.0, 0.0, 0.0], [0.0; 3], [0.0; 3], [2e4, 0.0, 0.0]];
    let field =
        |x: [f64; 3]| [1.2 + g[0][0] * x[0], 5.0 + g[1][0] * x[0], 0.7, -0.4, 1e5 + g[4][0] * x[0]];
    let prim: Vec<[f64; 5]> = mesh.coords.iter().map(|&x| field(x)).collect();
    let grad = vec![g; n];
    for x_wall in [0.1, 0.2, 0.35, 0.45] {
        let u_wall = field([x_wall, 0.0, 0.0])[1];
        let surface =
            plane([x_wall, 0.5, 0.5], [0.0, 0.7, 0.0], [0.0, 0.0, 0.7], [u_wall, 0.3, -0.2]);
        let cuts = brute_force_cuts(&mesh, &surface, 0.0);
        assert_eq!(cuts.len(), 9);
        let mut v = view(&mesh, &surface, &prim, &active, &mats, &material);
        v.grad = Some(&grad);
        let first = view(&mesh, &surface, &prim, &active, &mats, &material);
        for cut in &cuts {
            let [i, j] = mesh.edges[cut.edge as usize];
            let (xi, xj) = (mesh.coords[i as usize], mesh.coords[j as usize]);
            let mid: [f64; 3] = std::array::from_fn(|k| 0.5 * (xi[k] + xj[k]));
            let nu = mesh.edge_normals[cut.edge as usize];
            let scale = 1e5 * norm(nu);
            for (end, facet) in [(End::I, nu), (End::J, nu.map(|c| -c))] {
                let s = one_sided(&v, cut, end).unwrap();
                let exact = physical_flux(&AIR, &field(mid), &facet);
                let wall = field([x_wall, 0.0, 0.0]);
                assert!((s.p - wall[4]).abs() < 1e-9 * 1e5, "p* {} at {x_wall}", s.p);
                for k in 0..5 {
                    assert!((s.flux[k] - exact[k]).abs() < 1e-11 * scale, "{x_wall} {end:?} {k}");
                }
                let f1 = one_sided(&first, cut, end).unwrap();
                assert!((f1.flux[1] - exact[1]).abs() > 1e-4 * scale, "{x_wall} {end:?}");
            }
        }
    }
    // A uniform state moving with the wall: W* = W_i and the physical flux, to round-off.
    let w = [1.3, 10.0, 0.0, 0.0, 1e5];
    let prim = vec![w; n];
    let zero = vec![[[0.0; 3]; 5]; n];
    let surface = plane([0.3, 0.5, 0.5], [0.0, 0.7, 0.0], [0.0, 0.0, 0.7], [10.0, 0.0, 0.0]);
    let mut v = view(&mesh, &surface, &prim, &active, &mats, &material);
    v.grad = Some(&zero);
    for cut in &brute_force_cuts(&mesh, &surface, 0.0) {
        let nu = mesh.edge_normals[cut.edge as usize];
        let s = one_sided(&v, cut, End::I).unwrap();
        let exact = physical_flux(&AIR, &w, &nu);
        for k in 0..5 {
            assert!((s.flux[k] - exact[k]).abs() <= 1e-12 * 1e5 * norm(nu), "{k}");
        }
    }
}

/// A steep expansion next to a fast receding wall: the node state reconstructed to the wall would
/// separate from it (escape speed 171 m/s against a wall at 800 m/s) while the node's own state
/// does not (1708 m/s): the wall state is the thesis' `W*(W_i)`. A wall faster than the node's own
/// escape speed is still the vacuum error.
#[test]
fn reconstruction_that_opens_a_vacuum_falls_back_on_the_node_wall_state() {
    let mesh = cube();
    let n = mesh.n_nodes();
    let (mats, material) = (air(), vec![0u8; n]);
    let active: Vec<bool> = mesh.coords.iter().map(|x| x[0] < 0.25).collect();
    let w = [1.2, 0.0, 0.0, 0.0, 1e5];
    let prim = vec![w; n];
    // p at the wall (α = 1/2 of the 0.5 edges): 1e5 - 0.25 · 3.96e5 = 1e3.
    let grad = vec![[[0.0; 3], [0.0; 3], [0.0; 3], [0.0; 3], [-3.96e5, 0.0, 0.0]]; n];
    for (speed, opens) in [(800.0, false), (2000.0, true)] {
        let surface = plane([0.25, 0.5, 0.5], [0.0, 0.8, 0.0], [0.0, 0.0, 0.8], [speed, 0.0, 0.0]);
        let cuts = brute_force_cuts(&mesh, &surface, 0.0);
        assert_eq!(cuts.len(), 9);
        let mut v = view(&mesh, &surface, &prim, &active, &mats, &material);
        v.grad = Some(&grad);
        for cut in &cuts {
            let [i, _] = mesh.edges[cut.edge as usize];
            let end = if active[i as usize] { End::I } else { End::J };
            let at_wall = [1.2, 0.0, 0.0, 0.0, 1e3];
            assert!(fluid_structure(&AIR, 1.2, 0.0, 1e3, speed).is_err());
            match (one_sided(&v, cut, end), opens) {
                (Ok(s), false) => {
                    let exact = fluid_structure(&AIR, w[0], 0.0, w[4], speed).unwrap();
                    assert_eq!((s.p, s.rho), (exact.p, exact.rho));
                    assert!(s.flux.iter().all(|f| f.is_finite()) && s.p > 0.0 && s.p < 1e5);
                }
                (Err(e), true) => assert!(matches!(e.error, RiemannError::Vacuum { .. })),
                (r, _) => panic!("wall at {speed} m/s, state at the wall {at_wall:?}: {r:?}"),
            }
        }
    }
}
