//! The `structure-solver` command line: a structure-only case run to half a period against the
//! closed-form dynamic peak of a suddenly loaded cantilever, bad input named by field, and the
//! bench smoke run printing JSON.

use std::path::PathBuf;
use std::process::Command;

fn exe() -> Command {
    Command::new(env!("CARGO_BIN_EXE_structure-solver"))
}

fn case_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../cases/structure-cantilever-plate")
}

#[test]
fn suddenly_loaded_cantilever_peaks_at_twice_the_static_deflection() {
    let out = tempfile::tempdir().unwrap();
    let status = exe()
        .args(["run", case_dir().join("case.toml").to_str().unwrap(), "--out"])
        .arg(out.path())
        .args(["--set", "structure.t_end=0.034", "--set", "structure.output_every=5", "--quiet"])
        .output()
        .unwrap();
    assert!(status.status.success(), "{}", String::from_utf8_lossy(&status.stderr));
    let csv = std::fs::read_to_string(out.path().join("structure_probes.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(lines.next().unwrap(), "time,tip.ux,tip.uy,tip.uz,tip.vx,tip.vy,tip.vz");
    let uz: Vec<f64> = lines.map(|l| l.split(',').nth(3).unwrap().parse().unwrap()).collect();
    let peak = uz.iter().cloned().fold(f64::MIN, f64::max);
    let (p, l, e, i) = (30.0, 1.0, 200e9, 0.1 * 0.02f64.powi(3) / 12.0);
    let delta = p * l * l * l / (3.0 * e * i);
    println!(
        "cantilever: peak tip deflection {peak:.4e} m vs 2δ = {:.4e} m ({:+.2}%)",
        2.0 * delta,
        100.0 * (peak / (2.0 * delta) - 1.0)
    );
    assert!((peak / (2.0 * delta) - 1.0).abs() < 0.05);
}

#[test]
fn a_bad_dof_name_is_reported_with_file_and_field() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(case_dir().join("case.toml"))
        .unwrap()
        .replace("dof = \"uz\"", "dof = \"w\"");
    let path = dir.path().join("case.toml");
    std::fs::write(&path, text).unwrap();
    let out = exe()
        .args(["run", path.to_str().unwrap(), "--quiet", "--out"])
        .arg(dir.path().join("out"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        err.contains("case.toml") && err.contains("structure.loads.dof") && err.contains("\"w\""),
        "{err}"
    );
}

#[test]
fn bench_prints_json_with_both_measurements() {
    let out = exe().args(["bench", "--quick"]).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(v["explicit_bt4"]["element_updates_per_s_per_core"].as_f64().unwrap() > 0.0);
    assert!(v["explicit_bt4"]["plastic_fraction"].as_f64().unwrap() > 0.5);
    assert!(v["implicit_newmark"]["seconds_per_step"].as_f64().unwrap() > 0.0);
}
