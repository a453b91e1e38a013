//! The level set moves with the contact of the ghost-fluid fluxes (thesis §3.3.2, Eq. 3.8 with
//! the contact velocity at the interface): gas at 10 MPa against water at 1 MPa, both at rest,
//! the planar version of the underwater bubble's start. The exact contact moves at the `u*` of
//! the two-phase Riemann problem from the first instant, while the nodal velocities next to it
//! start at zero.

use fluid_solver::bc::BoundaryCondition;
use fluid_solver::eos::Eos;
use fluid_solver::levelset::{LevelSet, LevelSetWorkspace};
use fluid_solver::mesh::boxmesh::{BoxCells, BoxSpec, FACE_NAMES};
use fluid_solver::mesh::Mesh;
use fluid_solver::riemann::{self, State1d};
use fluid_solver::semidiscretization::{Numerics, Semidiscretization};
use fluid_solver::state::{State, Workspace};
use fluid_solver::time::TimeStepping;

const WATER: Eos = Eos::StiffenedGas { gamma: 4.4, p_c: 6e8 };
const GAS: Eos = Eos::PerfectGas { gamma: 1.4 };

/// The zero of `φ` along the nodes of the tube's edge y = z = 0, linearly interpolated.
fn zero(mesh: &Mesh, phi: &[f64]) -> f64 {
    let mut axis: Vec<(f64, f64)> = (0..mesh.n_nodes())
        .filter(|&i| mesh.coords[i][1] == 0.0 && mesh.coords[i][2] == 0.0)
        .map(|i| (mesh.coords[i][0], phi[i]))
        .collect();
    axis.sort_by(|a, b| a.0.total_cmp(&b.0));
    let k = axis.windows(2).position(|w| (w[0].1 >= 0.0) != (w[1].1 >= 0.0)).unwrap();
    let ((xa, pa), (xb, pb)) = (axis[k], axis[k + 1]);
    xa + (xb - xa) * pa / (pa - pb)
}

/// Gas (`φ < 0`, x < x0) at 10 MPa and water at 1 MPa at rest on a tube of `cells` tets, run to
/// `t_end` or for `steps` steps, whichever comes first; returns the zero of `φ` and the exact
/// position of the contact, `x0 + u* t`, in cells.
fn contact_position(cells: usize, t_end: f64, steps: u64) -> (f64, f64) {
    let h = 1.0 / cells as f64;
    let mesh =
        Mesh::build(BoxSpec::tube(0.0, 1.0, cells, h, BoxCells::Tet).raw().unwrap()).unwrap();
    let x0 = 0.5 + 0.31 * h;
    let gas = [10.0, 0.0, 0.0, 0.0, 1e7];
    let water = [1000.0, 0.0, 0.0, 0.0, 1e6];
    // Symmetry planes across, the far fields of each fluid at the ends (the waves leave).
    let mut bcs: Vec<(String, BoundaryCondition)> =
        FACE_NAMES[2..].iter().map(|n| (n.to_string(), BoundaryCondition::Symmetry)).collect();
    bcs.push(("xmin".into(), BoundaryCondition::FarField { state: gas }));
    bcs.push(("xmax".into(), BoundaryCondition::FarField { state: water }));
    let phi: Vec<f64> = mesh.coords.iter().map(|x| x[0] - x0).collect();
    let material: Vec<u8> = phi.iter().map(|&p| u8::from(p < 0.0)).collect();
    let cons = material
        .iter()
        .map(|&m| if m == 1 { GAS.prim_to_cons(&gas) } else { WATER.prim_to_cons(&water) })
        .collect();
    let mut semi = Semidiscretization::with_materials(
        mesh,
        vec![WATER, GAS],
        material.clone(),
        Numerics::default(),
        &bcs,
    )
    .unwrap();
    // Gas where φ < 0, water where φ >= 0.
    let ls = LevelSet::new(&semi, [1, 0], 10);
    let mut state = State { cons, material, phi };
    ls.check(&state).unwrap();
    let n = semi.mesh.n_nodes();
    let (mut ws, mut lws) = (Workspace::new(n), LevelSetWorkspace::new(n));
    let mut t = 0.0;
    let mut step = 0;
    while t < t_end && step < steps {
        step += 1;
        let stepping = TimeStepping::Global { cfl: 0.8 };
        let done = ls.step(&mut semi, &mut state, &mut ws, &mut lws, stepping, t_end - t, step);
        t += done.unwrap().dt;
    }
    let star = riemann::solve(
        &GAS,
        State1d { rho: gas[0], u: 0.0, p: gas[4] },
        &WATER,
        State1d { rho: water[0], u: 0.0, p: water[4] },
    )
    .unwrap();
    (zero(&semi.mesh, &state.phi) / h, (x0 + star.u * t) / h)
}

/// After the contact has moved 1.5 cells, the zero of `φ` is within 0.25 cells of it on 50, 100
/// and 200 cells.
#[test]
fn the_interface_moves_at_the_contact_velocity() {
    for cells in [50, 100, 200] {
        // u* = 5.5 m/s: 1.5 cells.
        let t_end = 1.5 / cells as f64 / 5.5;
        let (zero, exact) = contact_position(cells, t_end, u64::MAX);
        println!("{cells} cells: φ zero {zero:.4} cells, contact {exact:.4} cells");
        assert!(
            (zero - exact).abs() < 0.25,
            "{cells} cells: φ zero {zero}, contact {exact} (cells)"
        );
    }
}

/// From the first step the zero of `φ` moves with the contact, at 0.7 to 1.1 times `u* t` after
/// 1 and 5 steps: the edges between the fluids carry `φ` with the contact velocity of their
/// two-phase Riemann problem, not the mean of the nodal velocities, which are zero at the start.
#[test]
fn the_interface_starts_at_the_contact_velocity() {
    let cells = 100;
    let x0 = 0.5 / (1.0 / cells as f64) + 0.31;
    for steps in [1, 5] {
        let (zero, exact) = contact_position(cells, 1.0, steps);
        let ratio = (zero - x0) / (exact - x0);
        println!(
            "{steps} steps: the φ zero moved {:.4e} cells, the contact {:.4e}",
            zero - x0,
            exact - x0
        );
        // Seen: 0.85 and 0.79 (0.05 and 0.22 with the mean nodal velocity on these edges).
        assert!((0.7..1.1).contains(&ratio), "after {steps} steps the φ zero moved {ratio} × u* t");
    }
}
