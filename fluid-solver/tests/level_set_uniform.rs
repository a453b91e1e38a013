//! A uniform flow carrying a water | air interface at equal pressure and velocity (thesis
//! §3.3.2): the level set moves the interface with the flow, the nodes it crosses take the other
//! fluid's state from the two-phase Riemann problem, and pressure and velocity stay constant to
//! round-off, on a 1D tube and on perturbed 3D tets with an oblique interface.

use fluid_solver::bc::BoundaryCondition;
use fluid_solver::eos::Eos;
use fluid_solver::levelset::{LevelSet, LevelSetWorkspace};
use fluid_solver::mesh::boxmesh::{BoxCells, BoxSpec};
use fluid_solver::mesh::{perturb, Mesh};
use fluid_solver::semidiscretization::{Numerics, Semidiscretization};
use fluid_solver::state::{State, Workspace};
use fluid_solver::time::TimeStepping;

const WATER: Eos = Eos::StiffenedGas { gamma: 4.4, p_c: 6e8 };
const AIR: Eos = Eos::PerfectGas { gamma: 1.4 };

/// Water where `phi(x) < 0`, air elsewhere, both at velocity `u` and 1e5 Pa; far fields at xmin
/// (water, inflow) and xmax (air, outflow), symmetry planes across. Runs `steps` steps; returns
/// the largest relative deviations of p and of the velocity (relative to |u|) at any node and
/// step, and the number of nodes that changed fluid.
fn carry(mesh: Mesh, u: [f64; 3], phi: impl Fn([f64; 3]) -> f64, steps: u64) -> (f64, f64, usize) {
    let water = [1000.0, u[0], u[1], u[2], 1e5];
    let air = [1.2, u[0], u[1], u[2], 1e5];
    let mut bcs: Vec<(String, BoundaryCondition)> = ["ymin", "ymax", "zmin", "zmax"]
        .iter()
        .map(|n| (n.to_string(), BoundaryCondition::Symmetry))
        .collect();
    bcs.push(("xmin".into(), BoundaryCondition::FarField { state: water }));
    bcs.push(("xmax".into(), BoundaryCondition::FarField { state: air }));
    let phi: Vec<f64> = mesh.coords.iter().map(|&x| phi(x)).collect();
    // Air is material 1, on φ >= 0.
    let material: Vec<u8> = phi.iter().map(|&p| u8::from(p >= 0.0)).collect();
    let cons = material
        .iter()
        .map(|&m| if m == 0 { WATER.prim_to_cons(&water) } else { AIR.prim_to_cons(&air) })
        .collect();
    let mut semi = Semidiscretization::with_materials(
        mesh,
        vec![WATER, AIR],
        material.clone(),
        Numerics::default(),
        &bcs,
    )
    .unwrap();
    let ls = LevelSet::new(&semi, [0, 1], 5);
    let mut state = State { cons, material, phi };
    ls.check(&state).unwrap();
    let n = semi.mesh.n_nodes();
    let (mut ws, mut lws) = (Workspace::new(n), LevelSetWorkspace::new(n));
    let start = state.material.clone();
    let speed = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
    let (mut dp, mut du): (f64, f64) = (0.0, 0.0);
    for step in 1..=steps {
        let stepping = TimeStepping::Global { cfl: 0.8 };
        ls.step(&mut semi, &mut state, &mut ws, &mut lws, stepping, 1.0, step).unwrap();
        ls.check(&state).unwrap();
        for (i, q) in state.cons.iter().enumerate() {
            let w = semi.eos_at(i).cons_to_prim(q);
            dp = dp.max((w[4] - 1e5).abs() / 1e5);
            for k in 0..3 {
                du = du.max((w[1 + k] - u[k]).abs() / speed);
            }
        }
    }
    let changed = state.material.iter().zip(&start).filter(|(a, b)| a != b).count();
    (dp, du, changed)
}

#[test]
fn a_uniform_flow_carries_the_interface_at_round_off_in_a_tube() {
    let mesh =
        Mesh::build(BoxSpec::tube(0.0, 1.0, 50, 0.02, BoxCells::Tet).raw().unwrap()).unwrap();
    let (dp, du, changed) = carry(mesh, [100.0, 0.0, 0.0], |x| x[0] - 0.3, 300);
    println!("tube: |Δp|/p <= {dp:e}, |Δu|/|u| <= {du:e}, {changed} nodes changed fluid");
    // 300 steps at CFL 0.8 move the interface past several stations.
    assert!(changed >= 8, "{changed} nodes changed fluid");
    assert!(dp < 1e-10 && du < 1e-10, "p {dp:e}, u {du:e}");
}

#[test]
fn a_uniform_flow_carries_an_oblique_interface_at_round_off_on_perturbed_tets() {
    let mut raw = BoxSpec::uniform([0.0; 3], [1.0; 3], [10, 8, 8], BoxCells::Tet).raw().unwrap();
    perturb(&mut raw, 0.2, 5);
    let mesh = Mesh::build(raw).unwrap();
    // The plane x + 0.6 y + 0.3 z = 0.95 leaves the inflow face x = 0 all water.
    let plane = |x: [f64; 3]| (x[0] + 0.6 * x[1] + 0.3 * x[2] - 0.95) / 1.204_159_457_879_229_5;
    let (dp, du, changed) = carry(mesh, [80.0, 0.0, 0.0], plane, 150);
    println!("oblique: |Δp|/p <= {dp:e}, |Δu|/|u| <= {du:e}, {changed} nodes changed fluid");
    assert!(changed >= 20, "{changed} nodes changed fluid");
    assert!(dp < 1e-10 && du < 1e-10, "p {dp:e}, u {du:e}");
}
