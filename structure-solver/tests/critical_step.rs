//! The critical step of central differences from element-by-element eigenvalue bounds
//! (drilling penalty and rotary inertia included) against the assembled system's largest
//! frequency: a bound (Irons 1970), and not more than a factor 2 below it.

use nalgebra::DMatrix;
use structure_solver::assembly::{FeModel, Part, RotaryInertia};
use structure_solver::elements::ShellSection;
use structure_solver::mesh::{generate, Mesh};
use structure_solver::model::Model;

fn assembled_dt(m: &mut FeModel) -> f64 {
    let n = m.n_dof();
    let mut trip = structure_solver::model::Tangent::default();
    m.tangent(0.0, &mut trip);
    let mut k = DMatrix::<f64>::zeros(n, n);
    for t in trip.triplets() {
        k[(t.row, t.col)] += t.val;
    }
    let mass = m.lumped_mass();
    let s =
        DMatrix::from_fn(n, n, |i, j| 0.5 * (k[(i, j)] + k[(j, i)]) / (mass[i] * mass[j]).sqrt());
    let w2 = s.symmetric_eigenvalues().iter().cloned().fold(0.0, f64::max);
    2.0 / w2.sqrt()
}

/// Returns the model for further checks.
fn check(mesh: &Mesh, name: &str) -> FeModel {
    let sec = ShellSection { e: 2e11, nu: 0.3, rho: 7850.0, h: 0.01 };
    let mut m = FeModel::new(mesh, |_| Part::Shell(sec)).unwrap();
    for rot in [RotaryInertia::Physical, RotaryInertia::Scaled] {
        m.set_rotary_inertia(rot);
        let (bound, exact) = (m.stable_dt(), assembled_dt(&mut m));
        println!(
            "{name} {rot:?}: element bound {bound:.4e} s, assembled {exact:.4e} s, ratio {:.3}",
            bound / exact
        );
        assert!(
            bound <= exact * (1.0 + 1e-6) && bound >= 0.5 * exact,
            "{name} {rot:?}: {bound} vs {exact}"
        );
    }
    m
}

#[test]
fn quad_shell_critical_step() {
    let mut mesh = generate::rectangle(1.0, 0.6, 4, 3);
    mesh.nodes[6][0] += 0.05;
    mesh.nodes[6][2] += 0.02;
    let mut m = check(&mesh, "quads");
    // Mindlin rotational modes set the physical step of a thin quad; scaled rotary inertia
    // lifts it well above (the Kirchhoff triangle has no such modes)
    m.set_rotary_inertia(RotaryInertia::Physical);
    let physical = m.stable_dt();
    m.set_rotary_inertia(RotaryInertia::Scaled);
    assert!(m.stable_dt() > 3.0 * physical, "scaled {} vs physical {physical}", m.stable_dt());
}

#[test]
fn triangle_shell_critical_step() {
    check(&generate::rectangle(1.0, 0.6, 4, 3).to_triangles(), "triangles");
}
