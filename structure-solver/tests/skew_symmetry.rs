//! Symmetry planes of any normal (`FeModel::symmetry_plane`): a pressurised quarter cylinder
//! on axis-aligned planes against the same model with the mesh and its planes rotated by 30°
//! about a skew axis (static and explicit dynamic), and a ±15° wedge of a long cylinder
//! against the membrane solution.

use std::f64::consts::PI;

use nalgebra::{Matrix3, Rotation3, Unit, Vector3};
use structure_solver::assembly::{Curve, FeModel, Part};
use structure_solver::elements::ShellSection;
use structure_solver::mesh::{generate, Mesh};
use structure_solver::model::Model;
use structure_solver::statics::{load_steps, NewtonSettings};
use structure_solver::time::{CentralDifference, Implicit, ImplicitScheme};

const SEC: ShellSection = ShellSection { e: 1e7, nu: 0.3, rho: 1.0, h: 0.02 };
const P: f64 = 100.0;

/// A quarter cylinder (`R = 1`, `L = 1`, θ ∈ [0°, 90°]) under pressure on the planes `y = 0`,
/// `x = 0`, `z = 0` and `z = L`, all rotated by `q` (mesh and normals).
fn quarter_cylinder(q: &Matrix3<f64>) -> (FeModel, Mesh) {
    let mut mesh = generate::cylinder(1.0, 1.0, [0.0, 0.5 * PI], 8, 4);
    for p in &mut mesh.nodes {
        *p = (q * Vector3::from(*p)).into();
    }
    let mut m = FeModel::new(&mesh, |_| Part::Shell(SEC)).unwrap();
    let n = |a: usize| -> [f64; 3] { (q * Vector3::ith(a, 1.0)).into() };
    m.symmetry_plane(mesh.node_set("u0").unwrap(), n(1)).unwrap();
    m.symmetry_plane(mesh.node_set("u1").unwrap(), n(0)).unwrap();
    m.symmetry_plane(mesh.node_set("v0").unwrap(), n(2)).unwrap();
    m.symmetry_plane(mesh.node_set("v1").unwrap(), n(2)).unwrap();
    let all = mesh.cell_set("all").unwrap().to_vec();
    m.pressure(&all, P, Curve::Linear);
    (m, mesh)
}

fn skew_rotation() -> Matrix3<f64> {
    let axis = Unit::new_normalize(Vector3::new(1.0, 2.0, 3.0));
    *Rotation3::from_axis_angle(&axis, 30f64.to_radians()).matrix()
}

fn displacements(m: &FeModel) -> Vec<Vector3<f64>> {
    let mut u = vec![[0.0; 3]; m.n_nodes()];
    m.displacement(&mut u);
    u.into_iter().map(Vector3::from).collect()
}

/// `max |u_rot - Q u_ref| / max |u_ref|`.
fn rotated_difference(q: &Matrix3<f64>, u_ref: &[Vector3<f64>], u_rot: &[Vector3<f64>]) -> f64 {
    let scale = u_ref.iter().map(|u| u.norm()).fold(0.0, f64::max);
    let diff = u_ref.iter().zip(u_rot).map(|(a, b)| (q * a - b).norm()).fold(0.0, f64::max);
    diff / scale
}

fn static_solve(m: &mut FeModel) {
    let s = NewtonSettings { tol: 1e-11, ..NewtonSettings::default() };
    load_steps(m, &[1.0], &s, |_, _| {}).unwrap();
}

#[test]
fn rotated_quarter_cylinder_statics_match_the_axis_aligned_planes() {
    let q = skew_rotation();
    let (mut a, _) = quarter_cylinder(&Matrix3::identity());
    let (mut b, _) = quarter_cylinder(&q);
    static_solve(&mut a);
    static_solve(&mut b);
    let (ua, ub) = (displacements(&a), displacements(&b));
    let d = rotated_difference(&q, &ua, &ub);
    // the planes hold in the rotated model: u·n = 0 on each
    let mesh = quarter_cylinder(&q).1;
    let mut plane = 0.0f64;
    for (set, axis) in [("u0", 1), ("u1", 0), ("v0", 2), ("v1", 2)] {
        let n = q * Vector3::ith(axis, 1.0);
        for &k in mesh.node_set(set).unwrap() {
            plane = plane.max(ub[k].dot(&n).abs());
        }
    }
    let umax = ua.iter().map(|u| u.norm()).fold(0.0, f64::max);
    println!(
        "skew planes, static quarter cylinder: |u| max {umax:.4e}, rotated vs reference {d:.2e}, max |u·n| on planes {:.1e}",
        plane / umax
    );
    assert!(d < 1e-9, "rotated solution differs by {d:.3e}");
    assert!(plane < 1e-12 * umax, "u·n = {plane:.3e} on a plane");
}

/// Displacements after a suddenly applied pressure (the `Linear` curve would be tiny at
/// these times) advanced by `run` in the reference and the rotated model, and their
/// difference (`rotated_difference`) with the reference's largest displacement.
fn dynamic_difference(run: impl Fn(&mut FeModel)) -> (f64, f64) {
    let q = skew_rotation();
    let mut u = Vec::new();
    for rot in [Matrix3::identity(), q] {
        let (mut m, mesh) = quarter_cylinder(&rot);
        m.pressure(mesh.cell_set("all").unwrap(), P, Curve::Constant);
        run(&mut m);
        u.push(displacements(&m));
    }
    let umax = u[0].iter().map(|u| u.norm()).fold(0.0, f64::max);
    (rotated_difference(&q, &u[0], &u[1]), umax)
}

#[test]
fn rotated_quarter_cylinder_explicit_dynamics_match_the_axis_aligned_planes() {
    let (d, umax) = dynamic_difference(|m| {
        let dt = 0.5 * m.stable_dt();
        let n = m.n_dof();
        let mut cd = CentralDifference::new(m, 0.0, vec![0.0; n], None);
        for _ in 0..300 {
            cd.step(m, dt, None);
        }
    });
    println!("skew planes, explicit (300 steps): |u| max {umax:.4e}, rotated vs reference {d:.2e}");
    assert!(umax > 1e-4, "nothing moved");
    assert!(d < 1e-9, "rotated explicit solution differs by {d:.3e}");
}

#[test]
fn rotated_quarter_cylinder_implicit_dynamics_match_the_axis_aligned_planes() {
    let (d, umax) = dynamic_difference(|m| {
        let dt = 20.0 * m.stable_dt();
        let n = m.n_dof();
        let mut im = Implicit::new(m, ImplicitScheme::Newmark, 0.0, vec![0.0; n], None);
        for _ in 0..8 {
            im.step(m, dt, None).unwrap();
        }
    });
    println!(
        "skew planes, implicit Newmark (8 steps): |u| max {umax:.4e}, rotated vs reference {d:.2e}"
    );
    assert!(umax > 1e-4, "nothing moved");
    assert!(d < 1e-9, "rotated implicit solution differs by {d:.3e}");
}

/// A 30° wedge (planes at ±15°, normals off the axes) of a long cylinder, `u_z = 0` at both
/// ends (plane strain): `u_r = p R² (1 - ν²) / (E h)`.
#[test]
fn cylinder_wedge_on_skew_planes_matches_the_membrane_solution() {
    let t = 15f64.to_radians();
    let mut errors = Vec::new();
    for n_theta in [2, 4] {
        let mesh = generate::cylinder(1.0, 0.5, [-t, t], n_theta, 2);
        let mut m = FeModel::new(&mesh, |_| Part::Shell(SEC)).unwrap();
        m.symmetry_plane(mesh.node_set("u0").unwrap(), [t.sin(), t.cos(), 0.0]).unwrap();
        m.symmetry_plane(mesh.node_set("u1").unwrap(), [-t.sin(), t.cos(), 0.0]).unwrap();
        m.symmetry_plane(mesh.node_set("v0").unwrap(), [0.0, 0.0, 1.0]).unwrap();
        m.symmetry_plane(mesh.node_set("v1").unwrap(), [0.0, 0.0, 1.0]).unwrap();
        m.pressure(mesh.cell_set("all").unwrap(), P, Curve::Linear);
        static_solve(&mut m);
        let exact = P * (1.0 - SEC.nu * SEC.nu) / (SEC.e * SEC.h);
        let u = displacements(&m);
        let mut err = 0.0f64;
        for (k, x) in mesh.nodes.iter().enumerate() {
            let er = Vector3::new(x[0], x[1], 0.0).normalize();
            let ur = u[k].dot(&er);
            err = err.max((ur / exact - 1.0).abs());
            // no circumferential or axial motion
            let et = Vector3::z().cross(&er);
            assert!(u[k].dot(&et).abs() < 1e-6 * exact && u[k].z.abs() < 1e-6 * exact);
        }
        errors.push(err);
    }
    let order = (errors[0] / errors[1]).log2();
    println!(
        "skew wedge ±15°: u_r vs p R²(1-ν²)/(E h): {:.3e} (2 cells) -> {:.3e} (4 cells), order {order:.2}",
        errors[0], errors[1]
    );
    assert!(errors[1] < 5e-3, "u_r error {:.3e}", errors[1]);
    assert!(order > 1.5, "order {order:.2}");
}

/// The ±15° wedge as a case file, planes given by their normals (`symmetry = [nx, ny, nz]`).
const WEDGE: &str = r#"[structure]
mesh = { generator = "cylinder", radius = 1.0, length = 0.5, n_theta = 4, n_axial = 2, theta_deg = [-15.0, 15.0] }
material = { e = 1e7, nu = 0.3, rho = 1.0 }
element = "shell"
thickness = 0.02
integrator = "static"
steps = 1
[[structure.bc]]
set = "u0"
symmetry = [0.25881904510252074, 0.9659258262890683, 0.0]
[[structure.bc]]
set = "u1"
symmetry = [-0.25881904510252074, 0.9659258262890683, 0.0]
[[structure.bc]]
set = "v0"
symmetry = [0.0, 0.0, 1.0]
[[structure.bc]]
set = "v1"
symmetry = [0.0, 0.0, 1.0]
[[structure.loads]]
pressure = 100.0
[[structure.probes]]
name = "mid"
point = [1.0, 0.0, 0.25]
"#;

/// Runs the command line on `text`; its output directory and result.
fn run_case(text: &str) -> (tempfile::TempDir, std::process::Output) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("case.toml");
    std::fs::write(&path, text).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_structure-solver"))
        .args(["run", path.to_str().unwrap(), "--quiet", "--out"])
        .arg(dir.path().join("out"))
        .output()
        .unwrap();
    (dir, out)
}

#[test]
fn case_file_symmetry_normals_give_the_wedge_membrane_solution() {
    let (dir, o) = run_case(WEDGE);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(dir.path().join("out/structure_probes.csv")).unwrap();
    let last = text.lines().last().unwrap();
    let row: Vec<f64> = last.split(',').map(|v| v.parse().unwrap()).collect();
    let exact = P * (1.0 - SEC.nu * SEC.nu) / (SEC.e * SEC.h);
    let err = row[1] / exact - 1.0;
    println!("skew wedge from a case file: u_r at θ = 0 vs membrane {err:+.3e}");
    assert!(err.abs() < 5e-3 && row[2].abs() < 1e-9 && row[3].abs() < 1e-9, "{row:?}");
    let bad = WEDGE.replacen("[0.0, 0.0, 1.0]", "[0.0, 0.0, 0.0]", 1);
    let (_dir, o) = run_case(&bad);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && err.contains("structure.bc[2].symmetry"), "{err}");
    assert!(err.contains("non-zero normal"), "{err}");
    let bad = WEDGE.replacen("[0.0, 0.0, 1.0]", "\"w\"", 1);
    let (_dir, o) = run_case(&bad);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && err.contains("normal [nx, ny, nz]"), "{err}");
}
