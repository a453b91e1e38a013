//! Loads: follower pressure on a quarter of an open cylinder (hoop stress only, exact radial
//! displacement `u = p R² / (E h)`), and gravity (total force = total mass times g).

use structure_solver::assembly::{Curve, FeModel, Part};
use structure_solver::elements::ShellSection;
use structure_solver::mesh::generate;
use structure_solver::model::Model;
use structure_solver::statics::{load_steps, NewtonSettings};

#[test]
fn pressure_on_an_open_cylinder_gives_the_hoop_displacement() {
    let (r, l, h, e) = (2.0, 1.0, 0.02, 1e7);
    let mesh = generate::cylinder(r, l, [0.0, generate::QUARTER], 24, 6);
    let sec = ShellSection { e, nu: 0.3, rho: 1.0, h };
    let mut m = FeModel::new(&mesh, |_| Part::Shell(sec)).unwrap();
    m.symmetry(mesh.node_set("u0").unwrap(), 1);
    m.symmetry(mesh.node_set("u1").unwrap(), 0);
    m.symmetry(mesh.node_set("v0").unwrap(), 2);
    let p = 10.0; // outward (cells ordered θ, z: normal = radial)
    m.pressure(mesh.cell_set("all").unwrap(), p, Curve::Linear);
    let s = NewtonSettings { tol: 1e-9, max_iter: 10, max_cuts: 0 };
    load_steps(&mut m, &[1.0], &s, |_, _| {}).unwrap();
    let mut u = vec![[0.0; 3]; m.n_nodes()];
    m.displacement(&mut u);
    let want = p * r * r / (e * h);
    let mut worst = 0.0f64;
    for (n, x) in mesh.nodes.iter().enumerate() {
        let ur = (u[n][0] * x[0] + u[n][1] * x[1]) / r;
        worst = worst.max((ur - want).abs() / want);
    }
    println!(
        "open cylinder under pressure: u_r = {want:.4e} expected, worst relative error {worst:.2e}"
    );
    // faceted geometry: observed 4.7e-4
    assert!(worst < 2e-3, "radial displacement error {worst}");
}

#[test]
fn gravity_loads_the_total_mass() {
    let mesh = generate::rectangle(2.0, 1.0, 4, 3);
    let sec = ShellSection { e: 1e7, nu: 0.3, rho: 7.0, h: 0.05 };
    let mut m = FeModel::new(&mesh, |_| Part::Shell(sec)).unwrap();
    m.gravity([0.0, 0.0, -9.81], Curve::Constant);
    let mut f = vec![0.0; m.n_dof()];
    m.external_force(0.3, &mut f);
    let fz: f64 = f.iter().skip(2).step_by(6).sum();
    let want = -9.81 * 7.0 * 0.05 * 2.0;
    assert!((fz - want).abs() < 1e-12 * want.abs(), "{fz} vs {want}");
    // the coupled participant's array adds as it is
    m.external_loads_mut()[6 * 3 + 1] = 5.0;
    m.external_force(0.3, &mut f);
    assert_eq!(f[6 * 3 + 1], 5.0);
}
