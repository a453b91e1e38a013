//! The step of central differences recomputed every step (`time::StableStep` on the element
//! bound `Model::stable_dt` at the current configuration): a tet block compressed to 70% of its
//! height gets a smaller step, one that stays below the critical step estimated afresh on the
//! deformed block, and the run stays stable (bounded energy, no element inverted).

use structure_solver::assembly::{Curve, FeModel, Part};
use structure_solver::material::{Elastic, Material};
use structure_solver::mesh::generate;
use structure_solver::model::Model;
use structure_solver::time::{critical_dt, kinetic_energy, CentralDifference, StableStep};

const SOFT: Material = Material::Elastic(Elastic { e: 1e6, nu: 0.3, rho: 1000.0 });

#[test]
fn a_crushed_tet_block_takes_a_smaller_stable_step_and_stays_stable() {
    let mesh = generate::block([1.0, 1.0, 1.0], [3, 3, 3]);
    let mut m = FeModel::new(&mesh, |_| Part::Solid(SOFT)).unwrap();
    m.fix(mesh.node_set("z0").unwrap(), [true, true, true, false, false, false]);
    // the top moves down by 0.3 over `t_end`, slowly against the wave transit time
    let t_end = 0.5;
    let top = mesh.node_set("z1").unwrap();
    m.prescribe(top, 2, -0.3, Curve::Table(vec![(0.0, 0.0), (t_end, 1.0)]));
    m.fix(top, [true, true, false, false, false, false]);
    let initial = critical_dt(&mut m, 0.0, 100, 1e-9);
    let rule = StableStep::new(&initial, 0.9);
    let v0 = vec![0.0; m.n_dof()];
    let mut cd = CentralDifference::new(&mut m, 0.0, v0, None);
    let dt0 = rule.at(&m);
    assert!((dt0 - 0.9 * initial.stable(1.0)).abs() < 1e-12 * dt0, "first step {dt0:e}");
    let (mut steps, mut e_max, mut dt) = (0, 0.0f64, dt0);
    while cd.state.t < t_end {
        dt = rule.at(&m).min(t_end - cd.state.t);
        cd.step(&mut m, dt, None);
        steps += 1;
        e_max = e_max.max(kinetic_energy(&m, &cd.state.v));
        assert!(cd.state.v.iter().all(|v| v.is_finite()), "finite at step {steps}");
    }
    let dt_end = rule.at(&m);
    let fresh = critical_dt(&mut m, t_end, 200, 1e-9);
    println!(
        "crushed tet block: {steps} steps, dt {dt0:.4e} -> {dt_end:.4e} (ratio {:.3}), fresh \
         estimate at the end: element {:.4e}, power {:.4e}, Gershgorin {:.4e}; max kinetic \
         energy {e_max:.3e} J (last step {dt:.3e})",
        dt_end / dt0,
        fresh.element,
        fresh.power,
        fresh.gershgorin
    );
    assert!(dt_end < 0.85 * dt0, "the step shrinks with the elements: {dt0:e} -> {dt_end:e}");
    assert!(dt_end <= fresh.stable(1.0), "below the deformed block's critical step");
    // the work of the moving top bounds the kinetic energy: the strain energy of the crushed
    // block is of order E V ε² / 2 (about 4e4 J); an unstable run grows without bound
    assert!(e_max < 1e4, "kinetic energy stays bounded: {e_max:e}");
    let mut u = vec![[0.0; 3]; m.n_nodes()];
    m.displacement(&mut u);
    let uz: f64 = top.iter().map(|&n| u[n][2]).sum::<f64>() / top.len() as f64;
    assert!((uz + 0.3).abs() < 1e-9, "the top reached its prescribed position: {uz}");
}
