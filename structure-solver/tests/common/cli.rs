//! Running `structure-solver` on case files in tests: the binary, the case folders, a run's
//! probe table, and a case text run from a temporary folder.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

pub fn exe() -> Command {
    Command::new(env!("CARGO_BIN_EXE_structure-solver"))
}

pub fn cases(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../cases").join(name)
}

/// `structure-solver run <case>/case.toml --out <out> --quiet <args>`.
pub fn run(case: &str, out: &Path, args: &[&str]) -> Output {
    exe()
        .args(["run", cases(case).join("case.toml").to_str().unwrap(), "--quiet", "--out"])
        .arg(out)
        .args(args)
        .output()
        .unwrap()
}

/// The rows of a CSV file with a header, as numbers, and the header.
pub fn table(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(str::to_string).collect();
    let rows = lines.map(|l| l.split(',').map(|v| v.parse().unwrap()).collect()).collect();
    (header, rows)
}

/// Runs `case`, which must succeed, and returns the probe rows.
pub fn probes(case: &str, out: &Path, args: &[&str]) -> Vec<Vec<f64>> {
    let o = run(case, out, args);
    assert!(o.status.success(), "{case}: {}", String::from_utf8_lossy(&o.stderr));
    table(&out.join("structure_probes.csv")).1
}

/// Runs `case` with `from` replaced by `to` (which must occur); returns the error output of
/// the run, which must fail.
pub fn fails(case: &str, from: &str, to: &str) -> String {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(cases(case).join("case.toml")).unwrap();
    assert!(text.contains(from), "{case} has no `{from}`");
    let out = run_in(dir.path(), &text.replacen(from, to, 1));
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!out.status.success() && !err.contains("panicked"), "{err}");
    assert!(err.contains("case.toml"), "the error names no file: {err}");
    err
}

/// Writes `text` as `case.toml` in a new folder and runs it; returns the folder and the output.
pub fn run_text(text: &str) -> (tempfile::TempDir, Output) {
    let dir = tempfile::tempdir().unwrap();
    let out = run_in(dir.path(), text);
    (dir, out)
}

/// The last probe row of a run of `text`, which must succeed.
pub fn last_row(text: &str) -> Vec<f64> {
    let (dir, o) = run_text(text);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    table(&dir.path().join("out/structure_probes.csv")).1.pop().unwrap()
}

/// Writes `text` as `case.toml` in `dir` and runs it with the output in `dir/out`.
pub fn run_in(dir: &Path, text: &str) -> Output {
    let path = dir.join("case.toml");
    std::fs::write(&path, text).unwrap();
    exe()
        .args(["run", path.to_str().unwrap(), "--quiet", "--out"])
        .arg(dir.join("out"))
        .output()
        .unwrap()
}
