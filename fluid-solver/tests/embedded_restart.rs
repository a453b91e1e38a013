//! Restarts of a fluid-alone run with an embedded surface (`cases/harmonic-body` on 80 cells):
//! - run to `T` in one go, or stopped halfway with a checkpoint and restarted to `T`: the probes,
//!   the surface forces, the lines and the final checkpoints (fluid and embedded parts) are equal
//!   byte for byte;
//! - the same over a whole period of the body, restarted a quarter in, so that nodes the body
//!   uncovers and covers again change side between the checkpoint and the end;
//! - a checkpoint that does not fit the case (another surface, motion or mesh, or none of the
//!   embedded state) is refused, naming the file and what differs.

use fluid_solver::solver::{self, RunOptions, RunSummary};
use interface_protocol::case::Case;
use interface_protocol::io::checkpoint::{tag_for_step, Checkpoint};
use std::path::{Path, PathBuf};

fn case_path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../cases/harmonic-body/case.toml")
}

/// The case on 80 cells to `t_end`, the axis line at `t_end`, plus `extra` overrides.
fn coarse(t_end: f64, extra: &[&str]) -> Vec<String> {
    let mut v = vec![
        "fluid.mesh.box.cells=[80,1,1]".to_string(),
        format!("fluid.time.t_end={t_end:e}"),
        format!(
            "fluid.lines=[{{name=\"axis\",from=[-4.0,-0.225,-0.225],to=[0.5,-0.225,-0.225],\
             points=81,times=[{t_end:e}]}}]"
        ),
    ];
    v.extend(extra.iter().map(|s| s.to_string()));
    v
}

fn run(out: &Path, overrides: &[String], restart: Option<&Path>) -> anyhow::Result<RunSummary> {
    let case = Case::load(&case_path(), overrides)?;
    let text = std::fs::read_to_string(case_path())?;
    let restart = restart.map(Path::to_path_buf);
    solver::run(
        &case,
        &text,
        &RunOptions { out: out.to_path_buf(), quiet: true, restart, force: false },
    )
}

fn text(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The rows of the CSV file `name` of the restarted run `second` are the rows of `full` from
/// the first time `second` holds on (the restart writes the probes at its start time too).
fn assert_rows_continue(full: &Path, second: &Path, name: &str) -> usize {
    let (a, b) = (text(&full.join(name)), text(&second.join(name)));
    let (a, b): (Vec<&str>, Vec<&str>) = (a.lines().collect(), b.lines().collect());
    assert_eq!(a[0], b[0], "{name}: header");
    let first = b[1].split(',').next().unwrap();
    let from = a.iter().position(|r| r.split(',').next() == Some(first)).unwrap_or_else(|| {
        panic!("{name}: the full run has no row at t = {first}");
    });
    assert_eq!(&a[from..], &b[1..], "{name}: rows after the restart");
    b.len() - 1
}

/// The files of checkpoint `step` of both runs are equal byte for byte.
fn assert_same_checkpoint(full: &Path, second: &Path, step: u64) {
    for part in ["fluid.ckpt", "embedded.ckpt"] {
        let at = |run: &Path| run.join("checkpoints").join(tag_for_step(step)).join(part);
        let (a, b) = (std::fs::read(at(full)).unwrap(), std::fs::read(at(second)).unwrap());
        assert!(a == b, "checkpoint {step}, {part}: the files differ");
    }
}

/// Runs `t_end` in one go and in two pieces (stopped after `split` steps, restarted) and checks
/// every output of the second piece against the uninterrupted run; returns the full run's steps.
fn restart_is_bitwise(dir: &Path, t_end: f64, split: impl Fn(u64) -> u64, extra: &[&str]) -> u64 {
    let (full, first, second) = (dir.join("full"), dir.join("first"), dir.join("second"));
    let a = run(&full, &coarse(t_end, extra), None).unwrap();
    let k = split(a.steps);
    let stop = format!("fluid.time.max_steps={k}");
    let mut first_extra = extra.to_vec();
    first_extra.push(&stop);
    let b = run(&first, &coarse(t_end, &first_extra), None).unwrap();
    assert_eq!(b.steps, k);
    let c = run(&second, &coarse(t_end, extra), Some(&first)).unwrap();
    assert_eq!((a.steps, a.time.to_bits()), (c.steps, c.time.to_bits()));
    let probes = assert_rows_continue(&full, &second, "probes.csv");
    let forces = assert_rows_continue(&full, &second, "surface_forces.csv");
    assert_eq!((probes as u64, forces as u64), (a.steps - k + 1, a.steps - k));
    let line = format!("lines/axis_t{t_end:.6e}.csv");
    for name in [line.as_str(), "lines/axis.csv"] {
        assert_eq!(text(&full.join(name)), text(&second.join(name)), "{name}");
    }
    assert_same_checkpoint(&full, &second, a.steps);
    println!("{} steps, restarted after {k}: probes, forces, lines, checkpoints equal", a.steps);
    a.steps
}

#[test]
fn a_harmonic_body_restarted_halfway_is_the_uninterrupted_run() {
    let dir = tempfile::tempdir().unwrap();
    let steps = restart_is_bitwise(dir.path(), 0.004, |n| n / 2, &[]);
    assert!(steps > 30, "{steps} steps");
}

/// The number of inactive nodes (inside the body) in the embedded part of checkpoint `step`.
fn inside(run: &Path, step: u64) -> usize {
    let path = run.join("checkpoints").join(tag_for_step(step)).join("embedded.ckpt");
    let ck = Checkpoint::read_file(&path).unwrap();
    ck.u8("status").unwrap().iter().filter(|&&s| s != 0).count()
}

/// Over a whole period the body's face recedes until `t = T/2`, uncovering nodes (filled as they
/// become fluid), and comes back after, covering them again: restarted a quarter in, both kinds
/// of change happen after the checkpoint, and the run is still the uninterrupted one byte for
/// byte.
#[test]
fn nodes_that_change_side_after_the_checkpoint_restart_bitwise() {
    let dir = tempfile::tempdir().unwrap();
    let steps = restart_is_bitwise(dir.path(), 0.01, |n| n / 4, &["output.checkpoint_every=5"]);
    let (full, first) = (dir.path().join("full"), dir.path().join("first"));
    let k = steps / 4;
    let later: Vec<usize> = (k / 5 + 1..=steps / 5).map(|s| inside(&full, 5 * s)).collect();
    let (at_restart, at_end) = (inside(&first, k), inside(&full, steps));
    let fewest = *later.iter().min().unwrap();
    println!(
        "inactive nodes: {at_restart} at the restart, {fewest} at fewest, {at_end} at the end"
    );
    assert!(fewest < at_restart && at_end > fewest, "{at_restart} -> {fewest} -> {at_end}");
}

/// A restart of another case is refused before the output folder is made, naming the checkpoint
/// file and the field that differs.
#[test]
fn a_checkpoint_of_another_case_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let first = dir.path().join("first");
    run(&first, &coarse(0.004, &["fluid.time.max_steps=6"]), None).unwrap();
    let file = first.join("checkpoints").join(tag_for_step(6)).join("embedded.ckpt");
    let refused = |name: &str, extra: &[&str]| {
        let out = dir.path().join(name);
        let e = format!("{:#}", run(&out, &coarse(0.004, extra), Some(&first)).unwrap_err());
        println!("{name}: {e}");
        assert!(!out.exists(), "{name}: the output folder was made");
        e
    };
    let surface = "fluid.embedded.surface.cells=[2,2]";
    let e = refused("surface", &[surface]);
    assert!(e.contains(&file.display().to_string()), "{e}");
    assert!(e.contains("4 surface nodes") && e.contains("surface has 9"), "{e}");
    let motion = "fluid.embedded.motion.amplitude=[0.05,0.0,0.0]";
    let e = refused("motion", &[motion]);
    assert!(e.contains(&file.display().to_string()) && e.contains("motion"), "{e}");
    let e = refused("mesh", &["fluid.mesh.box.cells=[81,1,1]"]);
    assert!(e.contains("nodes") && e.contains(&(82 * 4).to_string()), "{e}");
    std::fs::remove_file(&file).unwrap();
    let e = refused("missing", &[]);
    assert!(e.contains("embedded.ckpt") && e.contains("[fluid.embedded]"), "{e}");
}

/// Water behind the receding face cavitates a few steps in: the run stops naming the state, and
/// the checkpoint it keeps (fluid and embedded parts, the failed step rolled back) is byte for
/// byte the one a run stopped just before that step writes.
#[test]
fn a_failed_step_keeps_the_last_good_embedded_state() {
    let dir = tempfile::tempdir().unwrap();
    let water = [
        "fluid.eos={kind=\"tait\",k1=2.07e9,k2=7.15,rho0=1000.0,p0=1e5}",
        "fluid.initial.state=[1000.0,0.0,0.0,0.0,1e5]",
        "fluid.boundary.xmin={kind=\"far_field\",state=[1000.0,0.0,0.0,0.0,1e5]}",
    ];
    let failed = dir.path().join("failed");
    let e = run(&failed, &coarse(0.004, &water), None).unwrap_err().to_string();
    println!("{e}");
    assert!(e.contains("invalid fluid state"), "{e}");
    let from = e.find("stopped at step ").unwrap() + "stopped at step ".len();
    let step: u64 = e[from..].split(',').next().unwrap().parse().unwrap();
    let stop = format!("fluid.time.max_steps={}", step - 1);
    let mut before = water.to_vec();
    before.push(&stop);
    let good = dir.path().join("good");
    assert_eq!(run(&good, &coarse(0.004, &before), None).unwrap().steps, step - 1);
    assert_same_checkpoint(&good, &failed, step - 1);
}
