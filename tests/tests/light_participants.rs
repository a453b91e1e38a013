//! The light participants (`rigid-structure`, `piston-fluid`) as a user meets them: a coupled
//! run that diverges is reported `failed` with no NaN in its probes, `check` validates without
//! writing, and a run alone follows the output-folder rule of every binary.

use fsi_system_tests::{Fsi, Probes, Scratch};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Duration;

fn spring_piston() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../cases/spring-piston/case.toml")
}

fn piston(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_piston-fluid"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("start piston-fluid")
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// `fsi run cases/spring-piston/case.toml --set coupling.dt=0.03 --set coupling.t_end=20`: the
/// step is above the spring's stable step 2/ω = 0.02 s, the state overflows after a few hundred
/// steps, and the run must say so instead of completing with NaN rows.
#[test]
fn a_coupled_run_that_diverges_fails_naming_the_stable_step_with_no_nan_row() {
    let scratch = Scratch::new();
    let out = scratch.path().join("out");
    let set = ["--set", "coupling.dt=0.03", "--set", "coupling.t_end=20"];
    let done = Fsi::run(&scratch, &spring_piston(), &out, &set).wait(Duration::from_secs(30));
    assert!(!done.status.success(), "a diverged run exited 0: {}", done.stdout);
    assert!(done.stderr.contains("above the stable step 2e-2 s"), "{}", done.stderr);
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).unwrap()).unwrap();
    let status = report["status"].as_str().unwrap();
    assert!(status.starts_with("failed"), "run.json status: {status}");
    assert!(status.contains("of DOF \"x\"") && status.contains("coupling step"), "{status}");
    for file in ["structure_probes.csv", "probes.csv"] {
        let probes = Probes::read(&out.join(file));
        assert!(probes.rows.len() > 100, "{file}: {} rows", probes.rows.len());
        let last = probes.rows.last().unwrap()[0];
        assert!(last < 20.0, "{file} reaches t = {last}: the run did not stop");
        for (i, row) in probes.rows.iter().enumerate() {
            assert!(row.iter().all(|x| x.is_finite()), "{file} row {}: {row:?}", i + 1);
        }
    }
}

#[test]
fn piston_fluid_check_summarises_or_names_the_error_and_writes_nothing() {
    let scratch = Scratch::new();
    let case = spring_piston();
    let case = case.to_str().unwrap();
    let ok = piston(scratch.path(), &["check", case]);
    assert!(ok.status.success(), "{}", text(&ok.stderr));
    let out = text(&ok.stdout);
    assert_eq!(out.lines().count(), 1, "{out}");
    assert!(out.contains("case.toml: ok: face `face`, area 1e-1 m²"), "{out}");
    assert!(out.contains("1000 coupling steps"), "{out}");
    for (set, says) in [
        ("fluid.piston.probe=\"\"", "field `fluid.piston.probe`"),
        ("fluid.piston.c0=-1", "fluid.piston.c0"),
        ("fluid.piston.normal=[1.0, 1.0, 0.0]", "expected a unit vector"),
        ("coupling.dt=1e-300", "coupling.t_end / coupling.dt"),
    ] {
        let o = piston(scratch.path(), &["check", case, "--set", set]);
        let err = text(&o.stderr);
        assert!(!o.status.success(), "{set}: passed");
        assert!(err.contains("case.toml") && err.contains(says), "{set}: {err}");
    }
    let no_section = scratch.case("bare", "[coupling]\ndt = 1e-3\n");
    let o = piston(scratch.path(), &["check", no_section.to_str().unwrap()]);
    assert!(text(&o.stderr).contains("bare.toml: piston-fluid needs a [fluid.piston] section"));
    let mut left: Vec<_> = std::fs::read_dir(scratch.path()).unwrap().flatten().collect();
    left.retain(|e| e.file_name() != "bare.toml");
    assert!(left.is_empty(), "check wrote {:?}", left[0].path());
}

#[test]
fn piston_fluid_alone_refuses_a_folder_holding_a_run_unless_forced() {
    let scratch = Scratch::new();
    let case = spring_piston();
    let out = scratch.path().join("alone");
    let args = ["run", case.to_str().unwrap(), "--out", out.to_str().unwrap()];
    let first = piston(scratch.path(), &args);
    assert!(first.status.success(), "{}", text(&first.stderr));
    let before = std::fs::read(out.join("probes.csv")).unwrap();
    let short = [&args[..], &["--set", "coupling.t_end=0.01"]].concat();
    let again = piston(scratch.path(), &short);
    let err = text(&again.stderr);
    assert!(!again.status.success(), "a second run overwrote the first");
    assert!(err.contains("not empty") && err.contains("--force"), "{err}");
    assert_eq!(std::fs::read(out.join("probes.csv")).unwrap(), before);
    let forced = piston(scratch.path(), &[&short[..], &["--force"]].concat());
    assert!(forced.status.success(), "{}", text(&forced.stderr));
    let rows = Probes::read(&out.join("probes.csv")).rows;
    assert_eq!(rows.len(), 11, "t = 0, 1e-3, ..., 1e-2");
    // Coupled, it writes into the launcher's folder and needs it to exist.
    let missing = scratch.path().join("missing");
    let o = piston(
        scratch.path(),
        &["run", case.to_str().unwrap(), "--couple", "nobody", "--out", missing.to_str().unwrap()],
    );
    assert!(!o.status.success());
    assert!(text(&o.stderr).contains("does not exist"), "{}", text(&o.stderr));
}

/// Coupled checkpoints are named as a solver alone names them (`step_0000000100`), and the
/// rigid body's part is a checksummed checkpoint file `latest` can restart from.
#[test]
fn coupled_checkpoints_use_the_one_folder_naming() {
    use interface_protocol::io::checkpoint;
    let scratch = Scratch::new();
    let out = scratch.path().join("out");
    let set = ["--set", "coupling.t_end=0.3", "--set", "output.checkpoint_every=100"];
    let done = Fsi::run(&scratch, &spring_piston(), &out, &set).wait(Duration::from_secs(30));
    assert!(done.status.success(), "{}", done.stderr);
    let dir = out.join("checkpoints");
    let mut tags: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    tags.sort();
    let expected: Vec<String> = [100, 200, 300].map(checkpoint::tag_for_step).to_vec();
    assert_eq!(tags, expected);
    let found = checkpoint::latest(&dir, &["structure"]).unwrap().unwrap();
    assert_eq!((found.step, found.tag.as_str()), (300, "step_0000000300"));
    assert!((found.time - 0.3).abs() < 1e-12, "t = {}", found.time);
}
