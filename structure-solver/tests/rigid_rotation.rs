//! Rigid rotation of a prestressed element about a skew axis, in one increment: the
//! corotated deformation (hence the local stress) is unchanged and the global internal forces
//! rotate with the body (DESIGN §8). Quads, triangles and beams; 90° and 360°.

use nalgebra::{Matrix3, Rotation3, Unit, Vector3};
use structure_solver::assembly::{FeModel, Part};
use structure_solver::elements::{BeamSection, ShellSection};
use structure_solver::mesh::{generate, Mesh};
use structure_solver::model::Model;

fn check(mesh: &Mesh, part: Part, name: &str) {
    let mut m = FeModel::new(mesh, |_| part).unwrap();
    let n = m.n_nodes();
    // prestress: a deformation with stretch, bending and twist, and nodal rotations
    let mut du = vec![0.0; 6 * n];
    for i in 0..n {
        let p = mesh.nodes[i];
        let v = [
            0.01 * p[0] + 0.004 * p[1],
            -0.006 * p[0] + 0.008 * p[1],
            0.02 * p[0] * p[1] + 0.01 * p[0] * p[0],
            0.03 * p[1],
            -0.02 * p[0],
            0.01 * (p[0] - p[1]),
        ];
        du[6 * i..6 * i + 6].copy_from_slice(&v);
    }
    m.apply_increment(&du);
    let d0: Vec<Vec<f64>> = deformations(&m);
    let mut f0 = vec![0.0; 6 * n];
    m.internal_force(&mut f0);
    let fscale = f0.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    assert!(fscale > 0.0);
    let axis = Unit::new_normalize(Vector3::new(1.0, -2.0, 3.0));
    for deg in [90.0f64, 360.0] {
        let mut mr = m.clone();
        let q = Rotation3::from_axis_angle(&axis, deg.to_radians());
        // one increment: translations to the rotated positions, spin = the rotation vector
        let mut inc = vec![0.0; 6 * n];
        let x = mr.positions().to_vec();
        for i in 0..n {
            let dx = q * x[i] - x[i];
            inc[6 * i..6 * i + 3].copy_from_slice(dx.as_slice());
            let w = axis.into_inner() * deg.to_radians();
            inc[6 * i + 3..6 * i + 6].copy_from_slice(w.as_slice());
        }
        mr.apply_increment(&inc);
        let d1 = deformations(&mr);
        let mut f1 = vec![0.0; 6 * n];
        mr.internal_force(&mut f1);
        let mut dd = 0.0f64;
        for (a, b) in d0.iter().zip(&d1) {
            for (x, y) in a.iter().zip(b) {
                dd = dd.max((x - y).abs());
            }
        }
        let qm: Matrix3<f64> = q.into_inner();
        let mut df = 0.0f64;
        for i in 0..n {
            for blk in [0, 3] {
                let v0 = Vector3::from_column_slice(&f0[6 * i + blk..6 * i + blk + 3]);
                let v1 = Vector3::from_column_slice(&f1[6 * i + blk..6 * i + blk + 3]);
                df = df.max((qm * v0 - v1).norm());
            }
        }
        println!(
            "{name}, {deg}°: max |Δd| = {dd:.2e}, max |Q f0 - f1| / |f| = {:.2e}",
            df / fscale
        );
        assert!(dd < 1e-12, "{name} {deg}: corotated deformation changed by {dd:e}");
        assert!(df / fscale < 1e-9, "{name} {deg}: forces did not rotate ({:e})", df / fscale);
    }
}

fn deformations(m: &FeModel) -> Vec<Vec<f64>> {
    let (x, r) = (m.positions(), m.rotations());
    m.elements()
        .iter()
        .map(|e| {
            let xs: Vec<_> = e.nodes.iter().map(|&i| x[i]).collect();
            let rs: Vec<_> = e.nodes.iter().map(|&i| r[i]).collect();
            e.deformation(&xs, &rs).unwrap()
        })
        .collect()
}

const SHELL: ShellSection = ShellSection { e: 1e6, nu: 0.3, rho: 1.0, h: 0.05 };

#[test]
fn quad_rotated_rigidly_keeps_its_stress() {
    check(&generate::rectangle(1.0, 0.8, 1, 1), Part::Shell(SHELL), "quad");
}

#[test]
fn triangle_rotated_rigidly_keeps_its_stress() {
    check(&generate::rectangle(1.0, 0.8, 1, 1).to_triangles(), Part::Shell(SHELL), "triangles");
}

#[test]
fn beam_rotated_rigidly_keeps_its_stress() {
    let sec = BeamSection::rectangle(2e11, 0.3, 7850.0, 0.02, 0.01);
    check(
        &generate::line([0.0, 0.0, 0.0], [1.0, 0.3, 0.2], 1),
        Part::Beam(sec, [0.0, 0.0, 1.0]),
        "beam",
    );
}
