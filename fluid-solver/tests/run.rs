//! Stand-alone runs of a case (`cases/sod-tube`, shrunk): every output is written and readable
//! (meshio opens the XDMF/HDF5 series), the solution matches the exact one, a restarted run is
//! bitwise identical to an uninterrupted one, and failures stop with named errors.

mod common;

use common::ExactTube;
use fluid_solver::eos::Eos;
use fluid_solver::solver::{self, read_checkpoint, RunOptions};
use interface_protocol::case::Case;
use interface_protocol::io::report::RunReport;
use std::path::{Path, PathBuf};
use std::process::Command;

fn case_path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../cases/sod-tube/case.toml")
}

fn small(extra: &[&str]) -> Vec<String> {
    let mut v =
        vec!["fluid.mesh.box.cells=[50,1,1]".to_string(), "fluid.time.t_end=0.1".to_string()];
    v.extend(extra.iter().map(|s| s.to_string()));
    v
}

fn run_case(
    out: &Path,
    overrides: &[String],
    restart: Option<PathBuf>,
) -> anyhow::Result<solver::RunSummary> {
    let path = case_path();
    let case = Case::load(&path, overrides)?;
    let text = std::fs::read_to_string(&path)?;
    solver::run(
        &case,
        &text,
        &RunOptions { out: out.to_path_buf(), quiet: true, restart, force: false },
    )
}

#[test]
fn sod_case_writes_every_output_and_matches_the_exact_solution() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("sod");
    let summary = run_case(&out, &small(&[]), None).unwrap();
    assert!(summary.steps > 10);
    for f in ["fluid.h5", "fluid.xdmf", "probes.csv", "run.json", "lines/axis.csv"] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    let report = RunReport::read(&out.join("run.json")).unwrap();
    assert_eq!(report.status, "completed");
    assert_eq!(report.steps, summary.steps);
    assert!(report.timings["fluid"].contains_key("residual"));
    let probes = std::fs::read_to_string(out.join("probes.csv")).unwrap();
    assert!(
        probes.starts_with("time,left.rho,left.vx,left.vy,left.vz,left.p,right.rho"),
        "{probes}"
    );
    assert_eq!(probes.lines().count() as u64, summary.steps + 2);
    // The line at the end against the exact solution: mean |Δρ| small on 50 cells.
    let exact = ExactTube::new(
        Eos::PerfectGas { gamma: 1.4 },
        [1.0, 0.0, 0.0, 0.0, 1.0],
        [0.125, 0.0, 0.0, 0.0, 0.1],
        0.3,
        0.1,
    );
    let line = std::fs::read_to_string(out.join("lines/axis.csv")).unwrap();
    let mut err = 0.0;
    let mut n = 0.0;
    for row in line.lines().skip(1) {
        let v: Vec<f64> = row.split(',').map(|s| s.parse().unwrap()).collect();
        err += (v[4] - exact.at(v[0])[0]).abs();
        n += 1.0;
    }
    assert!(err / n < 0.02, "mean density error along the line {}", err / n);
    // meshio reads the series: the last step's density has the right size and range.
    let script = format!(
        "import meshio\nwith meshio.xdmf.TimeSeriesReader('{}') as r:\n    pts, cells = r.read_points_cells()\n    \
         n = r.num_steps\n    t, pd, cd = r.read_data(n - 1)\n    rho = pd['rho']\n    print(len(pts), n, t, rho.min(), rho.max())\n",
        out.join("fluid.xdmf").display()
    );
    let py = Command::new("python3").arg("-c").arg(&script).output().expect("python3 with meshio");
    assert!(py.status.success(), "meshio failed: {}", String::from_utf8_lossy(&py.stderr));
    let text = String::from_utf8_lossy(&py.stdout);
    let v: Vec<f64> = text.split_whitespace().map(|s| s.parse().unwrap()).collect();
    assert_eq!(v[0] as usize, 51 * 4);
    assert!((v[2] - 0.1).abs() < 1e-12, "{text}");
    assert!(v[3] > 0.12 && v[3] < 0.13 && v[4] > 0.99 && v[4] < 1.01, "{text}");
}

#[test]
fn restarted_run_is_bitwise_identical() {
    let dir = tempfile::tempdir().unwrap();
    let full = dir.path().join("full");
    let first = dir.path().join("first");
    let second = dir.path().join("second");
    let a = run_case(&full, &small(&[]), None).unwrap();
    let b = run_case(&first, &small(&["fluid.time.max_steps=7"]), None).unwrap();
    assert_eq!(b.steps, 7);
    let c = run_case(&second, &small(&[]), Some(first.clone())).unwrap();
    assert_eq!((a.steps, a.time.to_bits()), (c.steps, c.time.to_bits()));
    let (sa, _, _) = read_checkpoint(&full, a.nodes).unwrap();
    let (sc, _, _) = read_checkpoint(&second, c.nodes).unwrap();
    assert!(sa
        .cons
        .iter()
        .zip(&sc.cons)
        .all(|(x, y)| x.iter().zip(y).all(|(p, q)| p.to_bits() == q.to_bits())));
}

#[test]
fn an_invalid_state_stops_the_run_naming_node_time_and_values() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("vacuum");
    // Two streams leaving each other at Mach 12: the pressure between them goes negative.
    let o = small(&[
        "fluid.initial.state=[1.0,-4.0,0.0,0.0,0.1]",
        "fluid.initial.regions=[{region={shape=\"half_space\",point=[0.5,0,0],normal=[1,0,0]},state=[1.0,4.0,0.0,0.0,0.1]}]",
        "fluid.boundary.xmin={kind=\"far_field\",state=[1.0,-4.0,0.0,0.0,0.1]}",
        "fluid.boundary.xmax={kind=\"far_field\",state=[1.0,4.0,0.0,0.0,0.1]}",
        "fluid.numerics.limiter=\"unlimited\"",
    ]);
    let e = run_case(&out, &o, None).unwrap_err().to_string();
    assert!(e.contains("node") && e.contains("t =") && e.contains("stopped at step"), "{e}");
    let report = RunReport::read(&out.join("run.json")).unwrap();
    assert_ne!(report.status, "completed");
    // The last good state is kept as a checkpoint and it is valid.
    let (state, _, _) = read_checkpoint(&out, 204).unwrap();
    let eos = Eos::PerfectGas { gamma: 1.4 };
    assert!(state.cons.iter().all(|q| eos.check(&eos.cons_to_prim(q)).is_ok()));
}

#[test]
fn case_errors_name_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let e = run_case(
        &dir.path().join("a"),
        &small(&["fluid.boundary.inlet={kind=\"slip_wall\"}"]),
        None,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("fluid.boundary.inlet") && e.contains("xmin"), "{e}");
    let e = run_case(
        &dir.path().join("b"),
        &small(&["fluid.eos={kind=\"perfect_gas\",gamma=0.5}"]),
        None,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("fluid.eos") && e.contains("gamma"), "{e}");
    let e = Case::load(&case_path(), &small(&["fluid.numerics.limiter=\"superbee\""]))
        .unwrap_err()
        .to_string();
    assert!(e.contains("fluid.numerics.limiter") && e.contains("van_albada"), "{e}");
}

#[test]
fn the_binary_runs_a_case() {
    let exe = env!("CARGO_BIN_EXE_fluid-solver");
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("cli");
    let mut cmd = Command::new(exe);
    cmd.arg("run").arg(case_path()).arg("--out").arg(&out).arg("--quiet");
    for s in small(&[]) {
        cmd.arg("--set").arg(s);
    }
    let r = cmd.output().unwrap();
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    assert!(r.stderr.is_empty(), "stderr not clean: {}", String::from_utf8_lossy(&r.stderr));
    assert!(out.join("fluid.xdmf").is_file());
}
