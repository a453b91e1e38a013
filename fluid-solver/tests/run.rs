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
    run_case_forced(out, overrides, restart, false)
}

fn run_case_forced(
    out: &Path,
    overrides: &[String],
    restart: Option<PathBuf>,
    force: bool,
) -> anyhow::Result<solver::RunSummary> {
    let path = case_path();
    let case = Case::load(&path, overrides)?;
    let text = std::fs::read_to_string(&path)?;
    solver::run(&case, &text, &RunOptions { out: out.to_path_buf(), quiet: true, restart, force })
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

/// A restart into its own folder is refused without `--force` (nothing touched) and, with it,
/// reads its checkpoint before the folder is reused, so it continues to the same end state.
#[test]
fn a_restart_into_its_own_folder_needs_force_and_keeps_its_checkpoint() {
    let dir = tempfile::tempdir().unwrap();
    let full = dir.path().join("full");
    let run = dir.path().join("run");
    let a = run_case(&full, &small(&[]), None).unwrap();
    run_case(&run, &small(&["fluid.time.max_steps=7"]), None).unwrap();
    let e = run_case(&run, &small(&[]), Some(run.clone())).unwrap_err().to_string();
    assert!(e.contains("--force"), "{e}");
    let c = run_case_forced(&run, &small(&[]), Some(run.clone()), true).unwrap();
    assert_eq!((a.steps, a.time.to_bits()), (c.steps, c.time.to_bits()));
    let (sa, _, _) = read_checkpoint(&full, a.nodes).unwrap();
    let (sc, _, _) = read_checkpoint(&run, c.nodes).unwrap();
    assert!(sa.cons == sc.cons, "the continued run ends where the uninterrupted one does");
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

/// The times the lines were written at, from their file names `<name>_t<time>.csv`, ascending.
fn line_times(out: &Path, name: &str) -> Vec<f64> {
    let prefix = format!("{name}_t");
    let mut times: Vec<f64> = std::fs::read_dir(out.join("lines"))
        .unwrap()
        .filter_map(|e| {
            let file = e.unwrap().file_name().to_string_lossy().into_owned();
            let t = file.strip_prefix(&prefix)?.strip_suffix(".csv")?.to_string();
            Some(t.parse().unwrap_or_else(|_| panic!("{file}")))
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times
}

/// The mean density error of a line sample against Sod's exact solution at `t`.
fn sod_error(sample: &Path, t: f64) -> f64 {
    let exact = ExactTube::new(
        Eos::PerfectGas { gamma: 1.4 },
        [1.0, 0.0, 0.0, 0.0, 1.0],
        [0.125, 0.0, 0.0, 0.0, 0.1],
        0.3,
        t,
    );
    let text = std::fs::read_to_string(sample).unwrap();
    let rows: Vec<Vec<f64>> =
        text.lines().skip(1).map(|r| r.split(',').map(|s| s.parse().unwrap()).collect()).collect();
    rows.iter().map(|v| (v[4] - exact.at(v[0])[0]).abs()).sum::<f64>() / rows.len() as f64
}

/// `cases/sod-tube` asks for its line at t = 0.1 and runs to 0.2: the step that would pass 0.1
/// is shortened, the line is written at exactly t = 0.1 (and so named) and matches the exact
/// solution at 0.1; the probes have a row at 0.1, and the CFL step resumes after it.
#[test]
fn line_samples_land_exactly_on_their_times() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("sod");
    let o = vec![
        "fluid.mesh.box.cells=[50,1,1]".to_string(),
        "fluid.lines=[{name=\"axis\",from=[0,0,0],to=[1,0,0],points=51,times=[0.0,0.1]}]".into(),
    ];
    let summary = run_case(&out, &o, None).unwrap();
    assert_eq!(summary.time, 0.2);
    assert_eq!(line_times(&out, "axis"), [0.0, 0.1]);
    let at = |t: f64| out.join("lines").join(format!("axis_t{t:.6e}.csv"));
    let err = sod_error(&at(0.1), 0.1);
    println!("{} steps; mean |Δρ| at t = 0.1: {err:.5}", summary.steps);
    assert!(err < 0.02, "mean density error along the line {err}");
    // The initial sample is the initial state: ρ = 1 left of the diaphragm, 0.125 right of it.
    let first = std::fs::read_to_string(at(0.0)).unwrap();
    let rho: Vec<f64> =
        first.lines().skip(1).map(|r| r.split(',').nth(4).unwrap().parse().unwrap()).collect();
    assert!(rho[0] == 1.0 && rho[50] == 0.125, "{rho:?}");
    let probes = std::fs::read_to_string(out.join("probes.csv")).unwrap();
    let times: Vec<f64> =
        probes.lines().skip(1).map(|r| r.split(',').next().unwrap().parse().unwrap()).collect();
    let k = times.iter().position(|&t| t == 0.1).expect("a step ends at t = 0.1");
    // The steps around it: the shortened one, then a full CFL step again.
    let dt: Vec<f64> = times.windows(2).map(|w| w[1] - w[0]).collect();
    assert!(dt[k - 1] < dt[k - 2] && dt[k] > dt[k - 1], "{:?}", &dt[k - 2..=k]);
    assert_eq!(times.len() as u64, summary.steps + 1);
}

/// A restart between two line times writes the later one as the uninterrupted run does.
#[test]
fn a_restart_between_line_times_is_bitwise_identical() {
    let dir = tempfile::tempdir().unwrap();
    let o = |extra: &str| {
        let mut v = vec![
            "fluid.mesh.box.cells=[50,1,1]".to_string(),
            "fluid.time.t_end=0.12".to_string(),
            "fluid.lines=[{name=\"axis\",from=[0,0,0],to=[1,0,0],points=51,times=[0.03,0.1]}]"
                .to_string(),
        ];
        v.extend((!extra.is_empty()).then(|| extra.to_string()));
        v
    };
    let (full, first, second) =
        (dir.path().join("full"), dir.path().join("first"), dir.path().join("second"));
    let a = run_case(&full, &o(""), None).unwrap();
    let b = run_case(&first, &o("fluid.time.max_steps=20"), None).unwrap();
    assert!(b.time > 0.03 && b.time < 0.1, "stopped at {}", b.time);
    let c = run_case(&second, &o(""), Some(first.clone())).unwrap();
    assert_eq!((a.steps, a.time.to_bits()), (c.steps, c.time.to_bits()));
    assert_eq!(line_times(&first, "axis"), [0.03]);
    assert_eq!(line_times(&second, "axis"), [0.1], "only what was not written before");
    let name = format!("lines/axis_t{:.6e}.csv", 0.1);
    assert_eq!(
        std::fs::read(full.join(&name)).unwrap(),
        std::fs::read(second.join(&name)).unwrap()
    );
    let (sa, _, _) = read_checkpoint(&full, a.nodes).unwrap();
    let (sc, _, _) = read_checkpoint(&second, c.nodes).unwrap();
    assert!(sa
        .cons
        .iter()
        .flatten()
        .zip(sc.cons.iter().flatten())
        .all(|(p, q)| p.to_bits() == q.to_bits()));
}

/// Checkpoints are named by `checkpoint::tag_for_step`: every `checkpoint_every` steps and at
/// the end.
#[test]
fn checkpoint_folders_are_named_by_the_shared_tag() {
    use interface_protocol::io::checkpoint::tag_for_step;
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("ck");
    let s = run_case(&out, &small(&["output.checkpoint_every=10"]), None).unwrap();
    let mut found: Vec<String> = std::fs::read_dir(out.join("checkpoints"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    found.sort();
    let mut expected: Vec<String> = (10..=s.steps).step_by(10).map(tag_for_step).collect();
    if s.steps % 10 != 0 {
        expected.push(tag_for_step(s.steps));
    }
    expected.sort();
    assert_eq!(found, expected);
}

/// A folder that holds a run is not overwritten without `--force`.
#[test]
fn the_binary_refuses_a_used_output_folder_unless_forced() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("cli");
    let run = |force: bool| {
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_fluid-solver"));
        cmd.arg("run").arg(case_path()).arg("--out").arg(&out).arg("--quiet");
        if force {
            cmd.arg("--force");
        }
        for s in small(&[]) {
            cmd.arg("--set").arg(s);
        }
        cmd.output().unwrap()
    };
    assert!(run(false).status.success());
    let before = std::fs::read(out.join("run.json")).unwrap();
    let again = run(false);
    let stderr = String::from_utf8_lossy(&again.stderr);
    assert!(!again.status.success() && stderr.contains("--force"), "{stderr}");
    assert_eq!(std::fs::read(out.join("run.json")).unwrap(), before, "left untouched");
    let forced = run(true);
    assert!(forced.status.success(), "{}", String::from_utf8_lossy(&forced.stderr));
    assert_ne!(std::fs::read(out.join("run.json")).unwrap(), before, "a fresh run.json");
}
