//! A water/air tube run from a case with named fluids: material ids reach the lines (`phi` NaN
//! there: no level set), the field output and the checkpoints, a restarted run is bitwise
//! identical to an uninterrupted one, and the case errors of named fluids name their field.

use fluid_solver::check;
use fluid_solver::eos::Eos;
use fluid_solver::riemann::{self, State1d};
use fluid_solver::solver::{self, read_checkpoint, RunOptions};
use interface_protocol::case::Case;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Water at 1e7 Pa (x < 0.51) against air at 1e5 Pa, at rest, between slip walls; 40 hexes.
const CASE: &str = r#"
[case]
name = "water-air-tube"

[fluid]
lines = [{ name = "axis", from = [0.0, 0.0, 0.0], to = [1.0, 0.0, 0.0], points = 41, times = [1e-5] }]
probes = [{ name = "mid", at = [0.5, 0.0, 0.0] }]

[fluid.fluids.water]
eos = { kind = "stiffened_gas", gamma = 4.4, p_c = 6e8 }

[fluid.fluids.air]
eos = { kind = "perfect_gas", gamma = 1.4 }

[fluid.mesh]
box = { lo = [0.0, 0.0, 0.0], hi = [1.0, 0.025, 0.025], cells = [40, 1, 1], shape = "hex" }

[fluid.initial]
fluid = "water"
state = [1000.0, 0.0, 0.0, 0.0, 1e7]
regions = [
  { region = { shape = "half_space", point = [0.51, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }, fluid = "air", state = [1.2, 0.0, 0.0, 0.0, 1e5] },
]

[fluid.boundary]
xmin = { kind = "slip_wall" }
xmax = { kind = "far_field", state = [1.2, 0.0, 0.0, 0.0, 1e5] }
ymin = { kind = "symmetry" }
ymax = { kind = "symmetry" }
zmin = { kind = "symmetry" }
zmax = { kind = "symmetry" }

[fluid.numerics]
cfl = 0.5

[fluid.time]
t_end = 2e-5
"#;

fn write_case(dir: &Path, text: &str) -> PathBuf {
    let path = dir.join("case.toml");
    std::fs::write(&path, text).unwrap();
    path
}

fn run(
    case_path: &Path,
    out: &Path,
    overrides: &[&str],
    restart: Option<PathBuf>,
) -> solver::RunSummary {
    let overrides: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    let case = Case::load(case_path, &overrides).unwrap();
    let text = std::fs::read_to_string(case_path).unwrap();
    let opts = RunOptions { out: out.to_path_buf(), quiet: true, restart, force: false };
    solver::run(&case, &text, &opts).unwrap()
}

#[test]
fn a_water_air_run_writes_materials_and_restarts_bitwise() {
    let dir = tempfile::tempdir().unwrap();
    let case = write_case(dir.path(), CASE);
    let full = dir.path().join("full");
    let a = run(&case, &full, &[], None);
    assert!(a.steps >= 5, "{} steps", a.steps);
    // Material ids in name order: air 0, water 1.
    let (state, _, _) = read_checkpoint(&full, a.nodes).unwrap();
    let mesh_x: Vec<f64> = {
        let c = Case::load(&case, &[]).unwrap();
        fluid_solver::setup::mesh(&c).unwrap().coords.iter().map(|x| x[0]).collect()
    };
    for (m, x) in state.material.iter().zip(&mesh_x) {
        assert_eq!(*m, u8::from(*x < 0.51), "material at x = {x}");
    }
    // The lines carry the material column.
    for name in ["axis.csv", "axis_t1.000000e-5.csv"] {
        let text = std::fs::read_to_string(full.join("lines").join(name)).unwrap();
        assert!(text.starts_with("x,y,z,s,rho,vx,vy,vz,p,material,phi\n"), "{text}");
        for row in text.lines().skip(1) {
            let v: Vec<f64> = row.split(',').map(|s| s.parse().unwrap()).collect();
            // No level set in this case: `phi` is NaN.
            assert!(v.len() == 11 && v[10].is_nan(), "{name}: {row}");
            if (v[0] - 0.51).abs() > 0.02 {
                assert_eq!(v[9], f64::from(u8::from(v[0] < 0.51)), "{name}: {row}");
            }
        }
    }
    // The field output holds `material` (read by meshio).
    let script = format!(
        "import meshio\nwith meshio.xdmf.TimeSeriesReader('{}') as r:\n    r.read_points_cells()\n    \
         t, pd, cd = r.read_data(r.num_steps - 1)\n    m = pd['material']\n    print(m.min(), m.max(), (m == 1).sum())\n",
        full.join("fluid.xdmf").display()
    );
    let py = Command::new("python3").arg("-c").arg(&script).output().expect("python3 with meshio");
    assert!(py.status.success(), "meshio failed: {}", String::from_utf8_lossy(&py.stderr));
    let out = String::from_utf8_lossy(&py.stdout);
    let v: Vec<f64> = out.split_whitespace().map(|s| s.parse().unwrap()).collect();
    let water_nodes = state.material.iter().filter(|&&m| m == 1).count();
    assert_eq!((v[0], v[1], v[2] as usize), (0.0, 1.0, water_nodes), "{out}");
    // Interrupted after 4 steps and restarted: the same end state, bit for bit.
    let first = dir.path().join("first");
    let second = dir.path().join("second");
    assert_eq!(run(&case, &first, &["fluid.time.max_steps=4"], None).steps, 4);
    let c = run(&case, &second, &[], Some(first));
    assert_eq!((a.steps, a.time.to_bits()), (c.steps, c.time.to_bits()));
    let (sc, _, _) = read_checkpoint(&second, c.nodes).unwrap();
    assert_eq!(sc.material, state.material);
    assert!(state
        .cons
        .iter()
        .zip(&sc.cons)
        .all(|(x, y)| x.iter().zip(y).all(|(p, q)| p.to_bits() == q.to_bits())));
    // The water expands into the air: its interface node moves at about the exact contact speed
    // (6.07 m/s; the water's impedance is 4000 times the air's, so p* is close to 1e5 Pa and the
    // air is only weakly compressed).
    let star = riemann::solve(
        &Eos::StiffenedGas { gamma: 4.4, p_c: 6e8 },
        State1d { rho: 1000.0, u: 0.0, p: 1e7 },
        &Eos::PerfectGas { gamma: 1.4 },
        State1d { rho: 1.2, u: 0.0, p: 1e5 },
    )
    .unwrap();
    let at = |x: f64| (0..mesh_x.len()).find(|&i| (mesh_x[i] - x).abs() < 1e-9).unwrap();
    let (water, air) = (state.cons[at(0.5)], state.cons[at(0.525)]);
    let u_water = water[1] / water[0];
    println!("u* = {}, p* = {}; interface water node u = {u_water}", star.u, star.p);
    assert!((u_water - star.u).abs() < 0.2 * star.u, "u = {u_water}, u* = {}", star.u);
    assert!(air[0] > 1.2 && air[1] > 0.0, "air at the interface {air:?}");
}

fn check_error(text: &str) -> String {
    let dir = tempfile::tempdir().unwrap();
    let path = write_case(dir.path(), text);
    match Case::load(&path, &[]) {
        Err(e) => e.to_string(),
        Ok(case) => check::check(&case).map(|c| c.summary).unwrap_err().to_string(),
    }
}

#[test]
fn named_fluid_errors_name_the_field() {
    let air_region = r#"fluid = "air", state = [1.2, 0.0, 0.0, 0.0, 1e5]"#;
    // A state valid for water but not for air, given to an air region.
    let e = check_error(
        &CASE.replace(air_region, r#"fluid = "air", state = [1.2, 0.0, 0.0, 0.0, -1e5]"#),
    );
    assert!(e.contains("case.toml:") && e.contains("fluid.initial.regions[0].state"), "{e}");
    assert!(e.contains("its fluid's EOS (material 0, PerfectGas"), "{e}");
    // The same state in a water region is fine.
    let ok = CASE.replace(air_region, r#"fluid = "water", state = [1000.0, 0.0, 0.0, 0.0, -1e5]"#);
    let dir = tempfile::tempdir().unwrap();
    let case = Case::load(&write_case(dir.path(), &ok), &[]).unwrap();
    let summary = check::check(&case).unwrap().summary;
    assert!(summary.contains("material 1 = `water` (164 nodes)"), "{summary}");
    // A boundary state invalid for the fluid on that boundary.
    let e = check_error(&CASE.replace(
        r#"far_field", state = [1.2, 0.0, 0.0, 0.0, 1e5]"#,
        r#"far_field", state = [1.2, 0.0, 0.0, 0.0, -1e5]"#,
    ));
    assert!(e.contains("fluid.boundary.xmax.state") && e.contains("fluid `air`"), "{e}");
    // Unknown names, a missing background fluid, eos and fluids together.
    let e = check_error(&CASE.replace(r#"fluid = "air""#, r#"fluid = "oil""#));
    assert!(e.contains("fluid.initial.regions[0].fluid") && e.contains("air, water"), "{e}");
    let e = check_error(&CASE.replace("fluid = \"water\"\nstate", "state"));
    assert!(e.contains("fluid.initial.fluid") && e.contains("missing"), "{e}");
    let e = check_error(&CASE.replace(
        "[fluid.fluids.water]",
        "[fluid.eos]\nkind = \"perfect_gas\"\ngamma = 1.4\n\n[fluid.fluids.water]",
    ));
    assert!(e.contains("fluid.fluids") && e.contains("not both"), "{e}");
    // A bad EOS of a named fluid names its table.
    let e = check_error(&CASE.replace("gamma = 4.4", "gamma = 0.4"));
    assert!(e.contains("fluid.fluids.water.eos") && e.contains("gamma"), "{e}");
}
