//! Explicit shells of several materials on a triangle mesh through the `structure-solver`
//! command line: a steel/aluminium strip in series (two `bt4` parts on a mesh of triangles,
//! so BLT3 of two materials) pulled by a slowly ramped end traction settles at the closed-form
//! end displacement; J2 `bt4` parts of different thickness points are refused, naming the
//! field.

use std::path::Path;
use std::process::{Command, Output};

/// The strip: `[0, 1] x [0, 0.1]`, 20 x 2 cells split into triangles, steel for x < 0.5 and
/// aluminium beyond (ν = 0), clamped at x = 0; the end traction σ = 1 MPa on h = 0.01 as
/// consistent nodal forces (a quarter of σ b h at the corners, half at the middle node),
/// ramped over `ramp` and held to `t_end`. `extra` is appended to both materials.
fn strip_case(ramp: f64, t_end: f64, extra: &str, points: [usize; 2]) -> String {
    let p = 1e6 * 0.1 * 0.01;
    format!(
        r#"[case]
name = "bimaterial-strip"

[structure]
mesh = {{ generator = "rectangle", lx = 1.0, ly = 0.1, nx = 20, ny = 2, triangles = true }}
integrator = "central_difference"
safety = 0.8
t_end = {t_end:e}
output_every = 5

[structure.materials.steel]
e = 200e9
nu = 0.0
rho = 7800.0
{extra}
[structure.materials.aluminium]
e = 70e9
nu = 0.0
rho = 2700.0
{extra}
[[structure.parts]]
set = "left"
element = "bt4"
material = "steel"
thickness = 0.01
points = {p0}

[[structure.parts]]
set = "right"
element = "bt4"
material = "aluminium"
thickness = 0.01
points = {p1}

[structure.sets]
left = {{ min = [-1.0, -1.0, -1.0], max = [0.500001, 1.0, 1.0] }}
right = {{ min = [0.499999, -1.0, -1.0], max = [2.0, 1.0, 1.0] }}
corners = {{ min = [0.999999, -1.0, -1.0], max = [1.000001, 0.01, 1.0] }}
corner2 = {{ min = [0.999999, 0.09, -1.0], max = [1.000001, 1.0, 1.0] }}
middle = {{ min = [0.999999, 0.04, -1.0], max = [1.000001, 0.06, 1.0] }}

[[structure.bc]]
set = "u0"
fixed = ["ux", "uy", "uz", "rx", "ry", "rz"]

[[structure.loads]]
set = "corners"
dof = "ux"
value = {q:e}
curve = {{ ramp = {ramp:e} }}

[[structure.loads]]
set = "corner2"
dof = "ux"
value = {q:e}
curve = {{ ramp = {ramp:e} }}

[[structure.loads]]
set = "middle"
dof = "ux"
value = {h:e}
curve = {{ ramp = {ramp:e} }}

[[structure.probes]]
name = "tip"
point = [1.0, 0.05, 0.0]
"#,
        q = 0.25 * p,
        h = 0.5 * p,
        p0 = points[0],
        p1 = points[1],
    )
}

fn run(dir: &Path, case: &str) -> Output {
    let path = dir.join("case.toml");
    std::fs::write(&path, case).unwrap();
    Command::new(env!("CARGO_BIN_EXE_structure-solver"))
        .args(["run", path.to_str().unwrap(), "--quiet", "--out"])
        .arg(dir.join("out"))
        .output()
        .unwrap()
}

#[test]
fn bimaterial_triangle_strip_settles_at_the_closed_form_end_displacement() {
    let (steel, alu) = ((200e9, 7800.0), (70e9, 2700.0));
    let exact = 1e6 * 0.5 * (1.0 / steel.0 + 1.0 / alu.0);
    // first axial period of the strip: 2 (L1/c1 + L2/c2)
    let c = |m: (f64, f64)| (m.0 / m.1).sqrt();
    let period = 2.0 * (0.5 / c(steel) + 0.5 / c(alu)) * 2.0;
    let (ramp, t_end) = (10.0 * period, 20.0 * period);
    let dir = tempfile::tempdir().unwrap();
    let out = run(dir.path(), &strip_case(ramp, t_end, "", [5, 5]));
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = std::fs::read_to_string(dir.path().join("out/structure_probes.csv")).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next().unwrap(), "time,tip.ux,tip.uy,tip.uz,tip.vx,tip.vy,tip.vz");
    let rows: Vec<Vec<f64>> =
        lines.map(|l| l.split(',').map(|v| v.parse().unwrap()).collect()).collect();
    // the mean over the hold (after the ramp): the residual oscillation averages out
    let held: Vec<f64> = rows.iter().filter(|r| r[0] > ramp).map(|r| r[1]).collect();
    let mean = held.iter().sum::<f64>() / held.len() as f64;
    let swing = held.iter().fold(0.0f64, |m, u| m.max((u - mean).abs()));
    println!(
        "bimaterial strip on 80 BLT3 triangles: mean u(L) {mean:.6e} vs σ L/2 (1/E1 + 1/E2) \
         {exact:.6e} ({:+.3}%), oscillation ±{:.2}%, {} probe rows held",
        100.0 * (mean / exact - 1.0),
        100.0 * swing / exact,
        held.len()
    );
    assert!(held.len() > 100);
    assert!((mean / exact - 1.0).abs() < 0.005, "mean end displacement {mean:e} vs {exact:e}");
    // the stress is the uniform σ (the oscillation aside): von Mises 1 MPa in every cell
    let cells = std::fs::read_to_string(dir.path().join("out/structure_cells.csv")).unwrap();
    let mut l = cells.lines();
    let header: Vec<&str> = l.next().unwrap().split(',').collect();
    let k = header.iter().position(|h| *h == "von_mises").expect("a von_mises column");
    let vm: Vec<f64> = l.map(|r| r.split(',').nth(k).unwrap().parse().unwrap()).collect();
    let worst = vm.iter().fold(0.0f64, |m, v| m.max((v / 1e6 - 1.0).abs()));
    println!("final von Mises of {} cells within {:.2}% of σ", vm.len(), 100.0 * worst);
    assert_eq!(vm.len(), 80);
    assert!(worst < 0.05, "cell stress off by {worst}");
}

#[test]
fn j2_bt4_parts_of_different_thickness_points_are_refused_by_field() {
    let dir = tempfile::tempdir().unwrap();
    let j2 = "sigma_y = 250e6\nhardening = 1e9\n";
    let out = run(dir.path(), &strip_case(1e-3, 2e-3, j2, [5, 8]));
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!out.status.success() && !err.contains("panicked"), "{err}");
    for w in ["structure.parts[1].points", "structure.parts[0] has 5, this part 8"] {
        assert!(err.contains(w), "the error lacks `{w}`: {err}");
    }
}
