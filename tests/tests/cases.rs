//! Every shipped coupled case runs, and its result is checked against what its README promises.

use fsi_system_tests::{Fsi, Oscillator, Scratch};
use interface_protocol::case::Case;
use std::path::{Path, PathBuf};
use std::time::Duration;

fn case_file(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../cases").join(name).join("case.toml")
}

/// The README's main case: a rigid piston on a spring closing an air column, C0 at the case's own
/// step, against the closed-form damped oscillation over its whole second of simulated time.
#[test]
fn spring_piston_follows_the_damped_oscillation() {
    let path = case_file("spring-piston");
    let case = Case::load(&path, &[]).expect("the case parses");
    let osc = Oscillator::from_case(&case);
    let scratch = Scratch::new();
    let out = scratch.path().join("out");
    let done = Fsi::run(&scratch, &path, &out, &[]).wait(Duration::from_secs(30));
    assert!(done.status.success(), "{}", done.stderr);
    let probe = &case.structure.as_ref().unwrap().rigid.as_ref().unwrap().probe;
    let e = osc.max_error(&out, probe, case.coupling.t_end);
    println!("spring-piston: largest error relative to A p0 / k: {e:.3e}");
    // The radiation damping A ρ0 c0 alone takes the amplitude down by e^2 over the run: a load
    // without it, or with the wrong sign, is off by O(1).
    assert!(e < 2e-2, "relative error {e}");
    check_overhead(&out.join("run.json"));
}

/// `run.json`'s `coupling_overhead` is the stepping wall time less both participants' work.
fn check_overhead(run_json: &Path) {
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(run_json).expect("run.json")).unwrap();
    let o = &r["coupling_overhead"];
    let (stepping, seconds, fraction) = (
        o["stepping_seconds"].as_f64().expect("stepping_seconds"),
        o["seconds"].as_f64().expect("seconds"),
        o["fraction"].as_f64().expect("fraction"),
    );
    let work: f64 = ["fluid", "structure"]
        .iter()
        .map(|p| r["timings"][p]["work"].as_f64().expect("work seconds of each participant"))
        .sum();
    println!("coupling overhead: {seconds:.4} s of {stepping:.4} s stepping ({fraction:.4})");
    assert!(stepping > 0.0 && stepping <= r["wall_seconds"].as_f64().unwrap());
    assert!((seconds - (stepping - work).max(0.0)).abs() < 1e-9 && seconds <= stepping);
    assert!((fraction - seconds / stepping).abs() < 1e-12, "{o}");
}
