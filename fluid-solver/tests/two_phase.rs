//! Two fluids on one mesh (thesis §3.3.2): stiffened-gas water (γ 4.4, p_c 6e8) and perfect-gas
//! air (γ 1.4). A contact at rest at equal pressure stays exact, the residual at the interface
//! is the two-phase ghost-fluid flux with the right signs, the sum of the residuals differs from
//! the boundary flux by exactly the two-phase term, the gradients do not mix fluids, and the
//! result is bitwise the same on 1 and 2 threads.

use fluid_solver::bc::BoundaryCondition;
use fluid_solver::eos::Eos;
use fluid_solver::flux::{physical_flux, two_phase_flux, FluxScheme};
use fluid_solver::mesh::boxmesh::{BoxCells, BoxSpec, FACE_NAMES};
use fluid_solver::mesh::{perturb, Mesh};
use fluid_solver::reconstruct::gradient::LsqGradient;
use fluid_solver::reconstruct::limiter::Limiter;
use fluid_solver::semidiscretization::{Numerics, Semidiscretization};
use fluid_solver::special_edges::SpecialKind;
use fluid_solver::state::{State, Workspace};
use fluid_solver::time::{rk2_step, TimeStepping};

const WATER: Eos = Eos::StiffenedGas { gamma: 4.4, p_c: 6e8 };
const AIR: Eos = Eos::PerfectGas { gamma: 1.4 };

fn walls() -> Vec<(String, BoundaryCondition)> {
    FACE_NAMES.iter().map(|n| (n.to_string(), BoundaryCondition::SlipWall)).collect()
}

fn perturbed_box(cells: [usize; 3], seed: u64) -> Mesh {
    let mut raw = BoxSpec::uniform([0.0; 3], [1.0; 3], cells, BoxCells::Tet).raw().unwrap();
    perturb(&mut raw, 0.2, seed);
    Mesh::build(raw).unwrap()
}

/// Water (material 0) where `in_water(x)`, air (material 1) elsewhere, with the primitive states
/// `water(x)` and `air(x)`.
fn two_fluids(
    mesh: Mesh,
    in_water: impl Fn([f64; 3]) -> bool,
    water: impl Fn([f64; 3]) -> [f64; 5],
    air: impl Fn([f64; 3]) -> [f64; 5],
    numerics: Numerics,
    bcs: &[(String, BoundaryCondition)],
) -> (Semidiscretization, State) {
    let material: Vec<u8> = mesh.coords.iter().map(|&x| u8::from(!in_water(x))).collect();
    let cons = mesh
        .coords
        .iter()
        .zip(&material)
        .map(
            |(&x, &m)| {
                if m == 0 {
                    WATER.prim_to_cons(&water(x))
                } else {
                    AIR.prim_to_cons(&air(x))
                }
            },
        )
        .collect();
    let semi =
        Semidiscretization::with_materials(mesh, vec![WATER, AIR], material.clone(), numerics, bcs)
            .unwrap();
    (semi, State::with_materials(cons, material))
}

/// An oblique plane through the box: water on the side of the origin.
fn oblique(x: [f64; 3]) -> bool {
    x[0] + 0.6 * x[1] + 0.3 * x[2] < 0.93
}

/// Water and air at rest at 1e5 Pa for 50 RK2 steps (CFL 0.9): the largest change of a
/// conserved variable relative to its scale (|ρ|, |E|, and ρc for the momentum).
fn drift_at_rest(semi: &Semidiscretization, mut state: State) -> f64 {
    let initial = state.clone();
    let mut ws = Workspace::new(semi.mesh.n_nodes());
    for _ in 0..50 {
        rk2_step(semi, &mut state, &mut ws, TimeStepping::Global { cfl: 0.9 }, 1.0).unwrap();
    }
    let mut worst: f64 = 0.0;
    for (i, (q, q0)) in state.cons.iter().zip(&initial.cons).enumerate() {
        let w = semi.eos_at(i).cons_to_prim(q0);
        let momentum = w[0] * semi.eos_at(i).sound_speed(w[0], w[4]);
        for k in 0..5 {
            let scale = if (1..4).contains(&k) { momentum } else { q0[k].abs() };
            worst = worst.max((q[k] - q0[k]).abs() / scale);
        }
    }
    assert_eq!(state.material, initial.material);
    worst
}

#[test]
fn water_and_air_at_rest_at_equal_pressure_stay_exact() {
    let water = |_| [1000.0, 0.0, 0.0, 0.0, 1e5];
    let air = |_| [1.2, 0.0, 0.0, 0.0, 1e5];
    let tube =
        Mesh::build(BoxSpec::tube(0.0, 1.0, 40, 0.025, BoxCells::Tet).raw().unwrap()).unwrap();
    let (semi, state) =
        two_fluids(tube, |x| x[0] < 0.49, water, air, Numerics::default(), &walls());
    assert!(!semi.special_edges().is_empty());
    let tube_drift = drift_at_rest(&semi, state);
    let (semi, state) =
        two_fluids(perturbed_box([8, 8, 8], 4), oblique, water, air, Numerics::default(), &walls());
    assert!(semi.special_edges().len() > 100, "{} interface edges", semi.special_edges().len());
    let box_drift = drift_at_rest(&semi, state);
    println!("relative drift after 50 steps: tube {tube_drift:e}, oblique box {box_drift:e}");
    assert!(tube_drift < 1e-12 && box_drift < 1e-12, "tube {tube_drift:e}, box {box_drift:e}");
}

/// A water/air shock tube (water at 1e9 Pa, air at 1e5 Pa, both at rest) between walls: every
/// facet of a node carries the pressure flux `p ν` of its own uniform state (so those sum to
/// zero) except the interface facets, so the first residual is
/// `R_i = Σ (F_i - p_i ν)` at the water ends and `R_j = Σ (p_j ν - F_j)` at the air ends of the
/// interface edges, with `(F_i, F_j)` from `two_phase_flux`, and zero elsewhere.
#[test]
fn the_first_residual_at_the_interface_is_the_two_phase_flux() {
    for (cells, flux) in [(BoxCells::Hex, FluxScheme::Roe), (BoxCells::Tet, FluxScheme::Hllc)] {
        let tube = Mesh::build(BoxSpec::tube(0.0, 1.0, 20, 0.05, cells).raw().unwrap()).unwrap();
        let numerics = Numerics { flux, limiter: Limiter::VanAlbada };
        let left = [1000.0, 0.0, 0.0, 0.0, 1e9];
        let right = [50.0, 0.0, 0.0, 0.0, 1e5];
        let (semi, state) =
            two_fluids(tube, |x| x[0] < 0.52, |_| left, |_| right, numerics, &walls());
        let mut ws = Workspace::new(semi.mesh.n_nodes());
        semi.residual(&state.cons, &mut ws).unwrap();
        let mut expected = vec![[0.0; 5]; semi.mesh.n_nodes()];
        let mut big: f64 = 0.0;
        for s in semi.special_edges().all() {
            assert_eq!(s.kind, SpecialKind::TwoMaterial);
            let e = s.edge as usize;
            let [i, j] = semi.mesh.edges[e].map(|v| v as usize);
            let n = semi.mesh.edge_normals[e];
            let (wi, wj) = (ws.prim[i], ws.prim[j]);
            let f = two_phase_flux(flux, semi.eos_at(i), &wi, semi.eos_at(j), &wj, &n).unwrap();
            let (pi, pj) =
                (physical_flux(semi.eos_at(i), &wi, &n), physical_flux(semi.eos_at(j), &wj, &n));
            for k in 0..5 {
                expected[i][k] += f.flux_i[k] - pi[k];
                expected[j][k] += pj[k] - f.flux_j[k];
            }
            big = big.max(pi.iter().chain(&pj).map(|v| v.abs()).fold(0.0, f64::max));
            // The exact star pressure lies between the two.
            assert!(f.star.p > 1e5 && f.star.p < 1e9, "p* = {}", f.star.p);
        }
        let mut worst: f64 = 0.0;
        for (r, x) in ws.residual.iter().zip(&expected) {
            for k in 0..5 {
                worst = worst.max((r[k] - x[k]).abs());
            }
        }
        let moved = expected.iter().filter(|x| x.iter().any(|v| v.abs() > 1e-3 * big)).count();
        println!(
            "{cells:?}/{flux:?}: |R - R_hand| <= {worst:e} (p ν up to {big:e}), {moved} nodes"
        );
        assert!(moved >= 8, "only {moved} interface nodes have a residual");
        assert!(worst <= 1e-12 * big, "{cells:?}/{flux:?}: {worst:e} vs {big:e}");
    }
}

/// A smooth state in each fluid.
fn wavy_water(x: [f64; 3]) -> [f64; 5] {
    let s = (3.0 * x[0] + 2.0 * x[1] - x[2]).sin();
    let c = (2.0 * x[0] - x[1] + 4.0 * x[2]).cos();
    [1000.0 * (1.0 + 0.01 * s), 2.0 * c, -s, 0.5 * s * c, 1e5 * (1.0 + 0.5 * c)]
}

fn wavy_air(x: [f64; 3]) -> [f64; 5] {
    let s = (2.0 * x[0] - 3.0 * x[1] + x[2]).sin();
    let c = (x[0] + 2.0 * x[1] + 3.0 * x[2]).cos();
    [1.2 * (1.0 + 0.2 * s), 20.0 * c, 10.0 * s, -5.0 * c, 1e5 * (1.0 + 0.2 * s * c)]
}

/// `Σ_i R_i = Σ_b F_b + Σ_interface (F_i - F_j)`: the ordinary edges cancel in the sum, the
/// two-phase ones leave the jump between their two one-sided fluxes.
#[test]
fn residuals_sum_to_the_boundary_flux_plus_the_two_phase_term() {
    let mut bcs = walls();
    bcs[1].1 = BoundaryCondition::FarField { state: [1.2, 10.0, 0.0, 0.0, 1e5] };
    bcs[4].1 = BoundaryCondition::Outflow { pressure: 1.1e5 };
    let mesh = perturbed_box([6, 7, 5], 5);
    let (semi, state) = two_fluids(mesh, oblique, wavy_water, wavy_air, Numerics::default(), &bcs);
    let mut ws = Workspace::new(semi.mesh.n_nodes());
    semi.residual(&state.cons, &mut ws).unwrap();
    let boundary = semi.boundary_flux_total(&ws.prim).unwrap();
    let mut jump = [0.0; 5];
    for s in semi.special_edges().all() {
        let e = s.edge as usize;
        let [i, j] = semi.mesh.edges[e].map(|v| v as usize);
        let f = two_phase_flux(
            semi.numerics.flux,
            semi.eos_at(i),
            &ws.prim[i],
            semi.eos_at(j),
            &ws.prim[j],
            &semi.mesh.edge_normals[e],
        )
        .unwrap();
        for k in 0..5 {
            jump[k] += f.flux_i[k] - f.flux_j[k];
        }
    }
    for k in 0..5 {
        let sum: f64 = ws.residual.iter().map(|r| r[k]).sum();
        let scale: f64 = ws.residual.iter().map(|r| r[k].abs()).sum();
        let defect = sum - boundary[k];
        println!("component {k}: Σ R - Σ F_b = {defect:e}, two-phase term {:e}", jump[k]);
        assert!((defect - jump[k]).abs() < 1e-13 * scale, "component {k}");
    }
    // The term is there: the interface is not in equilibrium.
    assert!(jump[4].abs() > 1e-6 * ws.residual.iter().map(|r| r[4].abs()).sum::<f64>());
}

/// Piecewise-constant fluids: every node's same-fluid neighbours hold its own state, so the
/// masked gradients are exactly zero; the unmasked operator would see the density jump.
#[test]
fn gradients_use_only_neighbours_of_the_same_fluid() {
    let water = |_| [1000.0, 1.0, 0.0, 0.0, 2e5];
    let air = |_| [1.2, 0.0, 3.0, 0.0, 1e5];
    let (semi, _) =
        two_fluids(perturbed_box([6, 6, 6], 8), oblique, water, air, Numerics::default(), &walls());
    let mut prim = vec![[0.0; 5]; semi.mesh.n_nodes()];
    for (i, w) in prim.iter_mut().enumerate() {
        *w = if semi.material()[i] == 0 { water([0.0; 3]) } else { air([0.0; 3]) };
    }
    let mut grad = vec![[[0.0; 3]; 5]; prim.len()];
    semi.gradient.compute(&semi.mesh, &prim, &mut grad);
    assert!(grad.iter().flatten().flatten().all(|&g| g == 0.0));
    LsqGradient::new(&semi.mesh).compute(&semi.mesh, &prim, &mut grad);
    let mixed = grad.iter().filter(|g| g[0].iter().any(|&v| v.abs() > 1.0)).count();
    assert!(mixed > 50, "the unmasked gradient mixes fluids at {mixed} nodes");
}

/// Five RK2 steps of two non-uniform fluids in a pool of `threads` threads.
fn five_steps(threads: usize) -> Vec<[f64; 5]> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    pool.install(|| {
        let mesh = perturbed_box([14, 12, 10], 9);
        let (semi, mut state) =
            two_fluids(mesh, oblique, wavy_water, wavy_air, Numerics::default(), &walls());
        assert!(semi.mesh.blocks.len() >= 6, "{} edge blocks", semi.mesh.blocks.len());
        let blocks_with_interface = (0..semi.mesh.blocks.len())
            .filter(|&b| !semi.special_edges().block(b).is_empty())
            .count();
        assert!(blocks_with_interface >= 4, "{blocks_with_interface} blocks hold the interface");
        let mut ws = Workspace::new(semi.mesh.n_nodes());
        for _ in 0..5 {
            rk2_step(&semi, &mut state, &mut ws, TimeStepping::Global { cfl: 0.9 }, 1.0).unwrap();
        }
        state.cons
    })
}

#[test]
fn two_fluids_give_bitwise_identical_results_on_one_and_two_threads() {
    let one = five_steps(1);
    let two = five_steps(2);
    assert!(one
        .iter()
        .zip(&two)
        .all(|(a, b)| a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())));
}

/// A material id outside the table, or one id too few, is refused naming the node.
#[test]
fn a_bad_material_layout_is_refused() {
    let mesh = perturbed_box([3, 3, 3], 1);
    let n = mesh.n_nodes();
    let mut material = vec![0u8; n];
    material[5] = 2;
    let e = Semidiscretization::with_materials(
        mesh.clone(),
        vec![WATER, AIR],
        material,
        Numerics::default(),
        &walls(),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("node 5") && e.contains("material 2") && e.contains("2 fluids"), "{e}");
    let e = Semidiscretization::with_materials(
        mesh,
        vec![WATER],
        vec![0; n - 1],
        Numerics::default(),
        &walls(),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains(&format!("{} material ids", n - 1)), "{e}");
}
