//! `rigid-structure check` and `run` alone through the binary: the summary or the error, no
//! file from `check`, the output-folder rule and the stop on a diverging state.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const CASE: &str = "[case]\nname = \"spring\"\n\
[coupling]\nscheme = \"C0\"\ndt = 1e-3\nt_end = 0.05\n\
[structure.rigid]\nmass = 10.0\nstiffness = 1e5\nu0 = 0.01\nprobe = \"piston\"\n\
[output]\ndir = \"out\"\n";

fn rigid(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rigid-structure"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("start rigid-structure")
}

fn case(dir: &Path, text: &str) -> PathBuf {
    let p = dir.join("case.toml");
    std::fs::write(&p, text).unwrap();
    p
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

fn entries(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn check_prints_one_summary_line_and_creates_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    case(tmp.path(), CASE);
    let o = rigid(tmp.path(), &["check", "case.toml"]);
    let (out, err) = (text(&o.stdout), text(&o.stderr));
    assert!(o.status.success(), "{err}");
    assert_eq!(out.lines().count(), 1, "{out}");
    assert!(out.contains("case.toml: ok") && out.contains("1 DOF (x)"), "{out}");
    assert!(out.contains("stable step 2e-2 s") && out.contains("50 steps"), "{out}");
    assert!(err.is_empty(), "{err}");
    assert_eq!(entries(tmp.path()), ["case.toml"], "check wrote a file");
}

#[test]
fn check_reports_what_run_would_refuse_and_exits_non_zero() {
    let tmp = tempfile::tempdir().unwrap();
    for (text_, set, says) in [
        ("[coupling]\ndt = 1e-3\n", None, "needs a [structure.rigid] section"),
        (CASE, Some("structure.rigid.probe=\"a,b\""), "field `structure.rigid.probe`"),
        (CASE, Some("structure.rigid.dofs=[\"q\"]"), "unknown DOF \"q\""),
        (CASE, Some("coupling.dt=1e-300"), "coupling.t_end / coupling.dt"),
        (CASE, Some("structure.rigid.mas=1"), "mas"),
    ] {
        case(tmp.path(), text_);
        let mut args = vec!["check", "case.toml"];
        if let Some(s) = set {
            args.extend(["--set", s]);
        }
        let o = rigid(tmp.path(), &args);
        let err = text(&o.stderr);
        assert!(!o.status.success(), "{args:?} passed");
        assert!(err.contains("case.toml") && err.contains(says), "{args:?}: {err}");
        assert!(o.stdout.is_empty(), "{args:?}: {}", text(&o.stdout));
        assert_eq!(entries(tmp.path()), ["case.toml"], "check wrote a file");
    }
    // A step above the stable one passes, with a warning saying so.
    case(tmp.path(), CASE);
    let o = rigid(tmp.path(), &["check", "case.toml", "--set", "coupling.dt=0.03"]);
    assert!(o.status.success());
    let err = text(&o.stderr);
    assert!(err.contains("warning: coupling.dt = 3e-2 s") && err.contains("stable step"), "{err}");
}

#[test]
fn run_alone_refuses_a_folder_holding_a_run_unless_forced() {
    let tmp = tempfile::tempdir().unwrap();
    case(tmp.path(), CASE);
    let first = rigid(tmp.path(), &["run", "case.toml"]);
    assert!(first.status.success(), "{}", text(&first.stderr));
    let probes = tmp.path().join("out/structure_probes.csv");
    let before = std::fs::read(&probes).unwrap();
    std::fs::write(tmp.path().join("out/notes.txt"), "mine").unwrap();
    let again = rigid(tmp.path(), &["run", "case.toml", "--set", "coupling.t_end=0.01"]);
    let err = text(&again.stderr);
    assert!(!again.status.success(), "a second run overwrote the first");
    assert!(err.contains("out") && err.contains("not empty") && err.contains("--force"), "{err}");
    assert_eq!(std::fs::read(&probes).unwrap(), before, "the first run's probes changed");
    let forced =
        rigid(tmp.path(), &["run", "case.toml", "--set", "coupling.t_end=0.01", "--force"]);
    assert!(forced.status.success(), "{}", text(&forced.stderr));
    let rows = std::fs::read_to_string(&probes).unwrap().lines().count();
    assert_eq!(rows, 1 + 11, "header and the 11 rows of t = 0..0.01");
    assert_eq!(std::fs::read_to_string(tmp.path().join("out/notes.txt")).unwrap(), "mine");
}

#[test]
fn run_alone_stops_at_the_first_non_finite_state_naming_the_stable_step() {
    let tmp = tempfile::tempdir().unwrap();
    case(tmp.path(), CASE);
    let o = rigid(
        tmp.path(),
        &["run", "case.toml", "--set", "coupling.dt=0.03", "--set", "coupling.t_end=20"],
    );
    let err = text(&o.stderr);
    assert!(!o.status.success(), "a diverged run exited 0");
    assert!(err.contains("of DOF \"x\" is") && err.contains("coupling step"), "{err}");
    assert!(err.contains("above the stable step 2e-2 s"), "{err}");
    let csv = std::fs::read_to_string(tmp.path().join("out/structure_probes.csv")).unwrap();
    for (i, line) in csv.lines().enumerate().skip(1) {
        assert!(
            line.split(',').all(|x| x.parse::<f64>().is_ok_and(f64::is_finite)),
            "line {}: {line}",
            i + 1
        );
    }
}
