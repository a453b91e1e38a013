//! One reduction for every load: a nodal load from outside the model (the coupling's `extra`)
//! goes through the same rigid-body and skew-plane reduction as the case's own loads. A load
//! on a slave of a free rigid body accelerates its mass centre by `F/m` and spins it by
//! `J⁻¹ (r × F)`; a load on a node of a skew symmetry plane acts through its in-plane part.

use nalgebra::Vector3;
use structure_solver::assembly::{FeModel, Part};
use structure_solver::elements::ShellSection;
use structure_solver::mesh::generate;
use structure_solver::model::Model;
use structure_solver::rigid::{ExtraMass, RigidReference};
use structure_solver::time::CentralDifference;

const PLATE: ShellSection = ShellSection { e: 1e6, nu: 0.3, rho: 2.0, h: 0.05 };

fn v3(v: &[f64], d: usize) -> Vector3<f64> {
    Vector3::new(v[d], v[d + 1], v[d + 2])
}

/// A protocol load `F` on one slave corner of a free rigid plate (master at the mass centre):
/// central differences integrate the constant acceleration `F/m` of the mass centre exactly,
/// so after `n` steps the master has moved by `F t²/(2m)` to round-off.
#[test]
fn a_protocol_load_on_a_rigid_slave_moves_the_body_by_f_over_m() {
    let mesh = generate::rectangle(2.0, 1.0, 4, 2);
    let nn = mesh.nodes.len();
    let mut m = FeModel::new(&mesh, |_| Part::Shell(PLATE)).unwrap();
    let total: f64 = (0..nn).map(|n| m.lumped_mass()[6 * n]).sum();
    let all: Vec<usize> = (0..nn).collect();
    let master = m.rigid_body(&all, RigidReference::MassCentre, ExtraMass::default()).unwrap();
    let mass = 2.0 * 1.0 * PLATE.h * PLATE.rho;
    assert!((total - mass).abs() < 1e-12 * mass, "plate mass {total} vs {mass}");
    // a load in the plane of the plate on node 0 (a corner, a slave) only
    let f = Vector3::new(3.0, -2.0, 0.5);
    let mut extra = vec![0.0; m.n_dof()];
    extra[0..3].copy_from_slice(f.as_slice());
    let v0 = vec![0.0; m.n_dof()];
    let mut cd = CentralDifference::new(&mut m, 0.0, v0, Some(&extra));
    let a0 = v3(&cd.state.a, 6 * master);
    let err_a = (a0 - f / mass).norm() / (f / mass).norm();
    println!(
        "rigid plate, slave load: a_master {a0:?}, F/m {:?}, rel. error {err_a:.2e}",
        f / mass
    );
    assert!(err_a < 1e-12, "the mass centre accelerates by F/m: error {err_a:.2e}");
    // the moment about the mass centre spins it: J α = r × F at rest
    let r = Vector3::from(mesh.nodes[0]) - m.positions()[master];
    let alpha = v3(&cd.state.a, 6 * master + 3);
    let moment = r.cross(&f);
    assert!(
        alpha.norm() > 0.0 && alpha.dot(&moment) > 0.0,
        "spin {alpha:?} along r × F {moment:?}"
    );
    let (dt, steps) = (1e-3, 200);
    for _ in 0..steps {
        cd.step(&mut m, dt, Some(&extra));
    }
    let t = dt * steps as f64;
    let u = m.positions()[master] - m.initial_positions()[master];
    let exact = f * (0.5 * t * t / mass);
    let err = (u - exact).norm() / exact.norm();
    println!("rigid plate after t = {t}: u {u:?}, F t²/2m {exact:?}, rel. error {err:.2e}");
    assert!(err < 1e-9, "the mass centre moves by F t²/(2m): error {err:.2e}");
}

/// A plate whose edge `x = 0` lies on the skew plane of normal `n = (1, 1, 0)/√2` (the edge
/// nodes keep `u·n = 0`): a protocol load `F` on an edge node reaches its acceleration as the
/// in-plane part `F - (F·n) n` over the node's mass, at rest; the out-of-plane part is
/// carried by the plane.
#[test]
fn a_protocol_load_on_a_skew_plane_node_is_reduced_to_the_plane() {
    let mesh = generate::rectangle(1.0, 1.0, 2, 2);
    let mut m = FeModel::new(&mesh, |_| Part::Shell(PLATE)).unwrap();
    let edge = mesh.nodes_where(|p| p[0].abs() < 1e-12);
    let normal = Vector3::new(1.0, 1.0, 0.0).normalize();
    let node = edge[1];
    // the node's own mass (the plane's reduction leaves none on its dependent dof)
    let mass = m.lumped_mass()[6 * node];
    m.symmetry_plane(&edge, normal.into()).unwrap();
    let f = Vector3::new(2.0, -1.0, 0.7);
    let mut extra = vec![0.0; m.n_dof()];
    extra[6 * node..6 * node + 3].copy_from_slice(f.as_slice());
    let v0 = vec![0.0; m.n_dof()];
    let cd = CentralDifference::new(&mut m, 0.0, v0, Some(&extra));
    let a = v3(&cd.state.a, 6 * node);
    let expected = (f - normal * f.dot(&normal)) / mass;
    let err = (a - expected).norm() / expected.norm();
    println!("skew-plane node: a {a:?}, in-plane F/m {expected:?}, rel. error {err:.2e}");
    assert!(err < 1e-12, "the skew-plane node gets the reduced force: error {err:.2e}");
    assert!(a.dot(&normal).abs() < 1e-12 * a.norm(), "a·n = {:.2e}", a.dot(&normal));
}
