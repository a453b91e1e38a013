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
    assert!(out.join("run.json").is_file());
}
