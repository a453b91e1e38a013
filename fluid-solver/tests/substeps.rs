//! `fluid.time.substeps = M`: coupled, the fluid crosses each coupling interval in exactly `M`
//! equal steps (the probe rows, one per step, fall on `t_from + k h`); a step the stable step
//! cuts short stops the run with an error naming the key and the substeps needed; a run alone
//! is warned that the key does not apply. Sod's tube (`cases/sod-tube`, 50 cells).

use fluid_solver::setup::{problem, Mode};
use fluid_solver::solver::{FluidRun, RunOptions};
use interface_protocol::case::Case;
use std::path::Path;

fn sod(overrides: &[&str]) -> Case {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../cases/sod-tube/case.toml");
    let mut all = vec!["fluid.mesh.box.cells=[50,1,1]".to_string(), "fluid.lines=[]".into()];
    all.extend(overrides.iter().map(|s| s.to_string()));
    Case::load(&path, &all).unwrap()
}

/// Opens `case` coupled (the launcher makes the output folder) in a fresh temporary folder.
fn coupled<'a>(case: &'a Case, dir: &Path) -> FluidRun<'a> {
    let opts = RunOptions { out: dir.join("fluid"), quiet: true, ..Default::default() };
    std::fs::create_dir(&opts.out).unwrap();
    FluidRun::open(case, "", &opts, Mode::Coupled).unwrap()
}

fn probe_times(dir: &Path) -> Vec<f64> {
    let text = std::fs::read_to_string(dir.join("fluid/probes.csv")).unwrap();
    text.lines().skip(1).map(|l| l.split(',').next().unwrap().parse().unwrap()).collect()
}

#[test]
fn each_coupling_interval_takes_exactly_the_fixed_substeps() {
    let case = sod(&["fluid.time.substeps=24"]);
    let dir = tempfile::tempdir().unwrap();
    let mut run = coupled(&case, dir.path());
    let (h, dt) = (0.025, 0.025 / 24.0);
    for n in 1..=3u64 {
        let reached = run.advance_to(n as f64 * h).unwrap();
        assert_eq!((reached.step, reached.t), (24 * n, n as f64 * h), "interval {n}");
    }
    run.finish().unwrap();
    let times = probe_times(dir.path());
    assert_eq!(times.len(), 73, "the start and 72 steps: {times:?}");
    for (k, t) in times.iter().enumerate() {
        assert!((t - k as f64 * dt).abs() < 1e-14, "step {k} ends at {t}, not {}", k as f64 * dt);
    }
}

#[test]
fn a_fixed_step_beyond_the_stable_step_stops_the_run_naming_the_key() {
    let case = sod(&["fluid.time.substeps=1"]);
    let dir = tempfile::tempdir().unwrap();
    let mut run = coupled(&case, dir.path());
    let err = run.advance_to(0.025).unwrap_err().to_string();
    assert!(run.failed());
    for part in ["stopped at step 1", "fluid.time.substeps = 1", "exceeds the stable step"] {
        assert!(err.contains(part), "`{part}` not in: {err}");
    }
    // The substeps it asks for are enough: they cross the interval.
    let needed: u64 =
        err.split("at least ").nth(1).unwrap().split(' ').next().unwrap().parse().unwrap();
    assert!(needed >= 2, "{err}");
    let case = sod(&[&format!("fluid.time.substeps={needed}")]);
    let dir = tempfile::tempdir().unwrap();
    let mut run = coupled(&case, dir.path());
    assert_eq!(run.advance_to(0.025).unwrap().step, needed, "{err}");
}

#[test]
fn a_run_alone_is_warned_that_fixed_substeps_are_for_coupled_runs() {
    let warnings = problem(&sod(&["fluid.time.substeps=4"]), Mode::Alone).unwrap().warnings;
    assert!(
        warnings.iter().any(|w| w.contains("fluid.time.substeps") && w.contains("coupled runs")),
        "{warnings:?}"
    );
    assert!(problem(&sod(&[]), Mode::Alone).unwrap().warnings.is_empty());
}
