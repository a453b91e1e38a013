//! What guards a run alone and what `check` does, through the binary on
//! `cases/structure-cantilever-plate`: a step far above the stable one stops at the first
//! non-finite state naming step, node and dof and saying the step is unstable, with `run.json`
//! failed and the newest checkpoint from before the blow-up (it restarts); an output folder that
//! holds a run is refused without `--force`, a restart continues in its own folder under `--force` and says
//! which checkpoint it used when the newest is damaged; step
//! counts past `MAX_STEPS` are refused naming the keys; `check` validates alone and coupled
//! cases without writing anything.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use interface_protocol::io::checkpoint::{self, Checkpoint};
use interface_protocol::io::report::RunReport;

fn exe() -> Command {
    Command::new(env!("CARGO_BIN_EXE_structure-solver"))
}

fn case(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../cases").join(name).join("case.toml")
}

/// `structure-solver run` of the cantilever plate into `out` with `args`.
fn run(out: &Path, args: &[&str]) -> Output {
    exe()
        .arg("run")
        .arg(case("structure-cantilever-plate"))
        .args(["--quiet", "--out"])
        .arg(out)
        .args(args)
        .output()
        .unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The number after the first `step ` of the line of `text` that reports the non-finite value.
fn step_in(text: &str) -> u64 {
    let text = text.lines().find(|l| l.contains("non-finite value")).expect("the error line");
    let at = text.find("step ").expect("a step") + 5;
    text[at..].split(|c: char| !c.is_ascii_digit()).next().unwrap().parse().unwrap()
}

#[test]
fn an_unstable_step_stops_at_the_first_non_finite_state() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("blow-up");
    // the stable step of the 24 x 2 plate is about 6e-6 s
    let args = ["--set", "structure.dt=1e-5", "--set", "output.checkpoint_every=5"];
    let o = run(&out, &args);
    let err = stderr(&o);
    println!("{err}");
    assert!(!o.status.success());
    assert!(err.contains("non-finite value") && err.contains("at node") && err.contains(" dof "));
    assert!(err.contains("dt = 1.000e-5 s is above the stable step"), "{err}");
    let failed_at = step_in(&err);
    // run.json says how it ended
    let report = RunReport::read(&out.join("run.json")).unwrap();
    assert!(report.status.contains("non-finite value"), "{}", report.status);
    assert_eq!(report.steps, failed_at - 1);
    // every checkpoint is of a finite state from before the blow-up
    let found = checkpoint::latest(&out.join("checkpoints"), &["structure"]).unwrap().unwrap();
    assert!(found.step < failed_at && found.step + 5 >= failed_at, "{} {failed_at}", found.step);
    let ck = Checkpoint::read(&out.join("checkpoints"), &found.tag, "structure").unwrap();
    for name in ck.names() {
        if let Ok(v) = ck.f64(name) {
            assert!(v.iter().all(|x| x.is_finite()), "checkpoint array {name}");
        }
    }
    // and restarts: to its own time, the state it holds is the last written
    let again = dir.path().join("again");
    let t = format!("structure.t_end={:e}", found.time);
    let o = run(&again, &["--restart", out.to_str().unwrap(), "--set", &t]);
    let err = stderr(&o);
    assert!(o.status.success(), "{err}");
    assert!(err.contains(&format!("restarting from checkpoint {}", found.tag)), "{err}");
    let probes = std::fs::read_to_string(again.join("structure_probes.csv")).unwrap();
    let row: Vec<f64> =
        probes.lines().nth(1).unwrap().split(',').map(|v| v.parse().unwrap()).collect();
    assert!(row.iter().all(|v| v.is_finite()), "{row:?}");
    assert!((row[0] - found.time).abs() <= 1e-12 * found.time, "{row:?} at {}", found.time);
    assert_eq!(RunReport::read(&again.join("run.json")).unwrap().status, "completed");
}

#[test]
fn a_folder_holding_a_run_is_refused_without_force() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let short = ["--set", "structure.t_end=2e-4", "--set", "output.checkpoint_every=10"];
    let o = run(&out, &short);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = run(&out, &short);
    let err = stderr(&o);
    assert!(!o.status.success());
    assert!(err.contains(out.to_str().unwrap()) && err.contains("--force"), "{err}");
    let forced: Vec<&str> = short.iter().copied().chain(["--force"]).collect();
    let o = run(&out, &forced);
    assert!(o.status.success(), "{}", stderr(&o));
    // a restart into the run's own folder is refused without --force, and continues there
    // with it, its checkpoints kept
    let newest = checkpoint::latest(&out.join("checkpoints"), &["structure"]).unwrap().unwrap();
    let longer = ["--set", "structure.t_end=4e-4", "--restart", out.to_str().unwrap()];
    let mut longer: Vec<&str> = longer.iter().copied().chain(short[2..].iter().copied()).collect();
    let o = run(&out, &longer);
    assert!(!o.status.success() && stderr(&o).contains("--force"), "{}", stderr(&o));
    longer.push("--force");
    let o = run(&out, &longer);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(out.join("checkpoints").join(&newest.tag).is_dir());
    let after = checkpoint::latest(&out.join("checkpoints"), &["structure"]).unwrap().unwrap();
    assert!(after.step > newest.step, "{} after {}", after.step, newest.step);
    let tag = checkpoint::tag_for_step(after.step);
    assert_eq!(after.tag, tag);
    // a damaged newest checkpoint: the restart says which one it skipped and which it used
    std::fs::write(out.join("checkpoints").join(&tag).join("structure.ckpt"), b"cut").unwrap();
    let used = checkpoint::latest(&out.join("checkpoints"), &["structure"]).unwrap().unwrap();
    let o = run(&dir.path().join("from-damaged"), &["--restart", out.to_str().unwrap()]);
    let err = stderr(&o);
    println!("{err}");
    assert!(o.status.success(), "{err}");
    assert!(err.contains(&tag), "{err}");
    assert!(err.contains(&format!("restarting from checkpoint {} (step", used.tag)), "{err}");
}

#[test]
fn step_counts_past_the_cap_are_refused_naming_the_keys() {
    let dir = tempfile::tempdir().unwrap();
    let o = run(&dir.path().join("out"), &["--set", "structure.dt=1e-20"]);
    let err = stderr(&o);
    println!("{err}");
    assert!(!o.status.success());
    assert!(err.contains("field `structure.t_end`: structure.t_end / structure.dt"), "{err}");
    assert!(err.contains("more than the 1000000000 one run may take"), "{err}");
    assert!(!dir.path().join("out").exists(), "nothing written");
}

fn check(case: &Path, args: &[&str]) -> Output {
    exe().arg("check").arg(case).args(args).output().unwrap()
}

#[test]
fn check_validates_alone_and_coupled_cases_without_writing() {
    let o = check(&case("structure-cantilever-plate"), &[]);
    let text = String::from_utf8_lossy(&o.stdout);
    println!("{text}");
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(text.contains("structure ok") && text.contains("75 nodes, 48 cells"), "{text}");
    assert!(text.contains("central_difference") && text.contains("stable step"), "{text}");
    assert!(text.contains("probe      tip at node 24"), "{text}");
    // an unstable step is pointed out, and a step count past the cap refused, as by `run`
    let o = check(&case("structure-cantilever-plate"), &["--set", "structure.dt=1e-4"]);
    assert!(String::from_utf8_lossy(&o.stdout).contains("is above the stable step"));
    let o = check(&case("structure-cantilever-plate"), &["--set", "structure.dt=1e-20"]);
    assert!(!o.status.success() && stderr(&o).contains("structure.t_end / structure.dt"));
    // coupled: the wet surface must exist
    let o = check(&case("plate-piston"), &[]);
    let text = String::from_utf8_lossy(&o.stdout);
    println!("{text}");
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(text.contains("wet surface `all` of 25 nodes and 16 faces"), "{text}");
    let o = check(&case("plate-piston"), &["--set", "structure.wet_set=\"lid\""]);
    let err = stderr(&o);
    assert!(!o.status.success());
    assert!(err.contains("field `structure.wet_set`") && err.contains("lid"), "{err}");
    assert!(text.contains("substeps   1 per coupling step"), "{text}");
    // a coupling step past the stable one is subcycled unless the substeps are fixed
    let o = check(&case("plate-piston"), &["--set", "coupling.dt=1e-4"]);
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        text.contains("substeps   13 per coupling step of 1.000e-4 s (from the stable step)"),
        "{text}"
    );
    let o = check(
        &case("plate-piston"),
        &["--set", "coupling.dt=1e-4", "--set", "structure.substeps=1"],
    );
    let err = stderr(&o);
    assert!(!o.status.success() && err.contains("exceeds the stable step"), "{err}");
}

#[test]
fn check_names_an_unknown_set() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(case("structure-cantilever-plate"))
        .unwrap()
        .replace("set = \"clamp\"", "set = \"clamped\"");
    let path = dir.path().join("case.toml");
    std::fs::write(&path, text).unwrap();
    let o = check(&path, &[]);
    let err = stderr(&o);
    assert!(!o.status.success());
    assert!(err.contains("field `structure.bc[0].set`: no set \"clamped\""), "{err}");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1, "check writes nothing");
}
