//! `fsi check` asks each participant to check its own section (`<command...> check CASE
//! [--set K=V]...`): a refusal is reported verbatim with the participant's role and program, a
//! missing program is an error, a participant without `check` is a warning, a check that hangs is
//! killed at `coupling.timeout_s`.

use fsi_system_tests::{Finished, Fsi, Scratch};
use std::path::{Path, PathBuf};
use std::time::Duration;

/// A case whose participants are the given commands (TOML arrays).
fn case(scratch: &Scratch, name: &str, fluid: &str, structure: &str) -> PathBuf {
    let text = format!(
        "[coupling]\nscheme = \"A6\"\ndt = 1e-3\nt_end = 1e-2\ntimeout_s = 1\n\
         [fluid]\ncommand = {fluid}\n[structure]\ncommand = {structure}\n"
    );
    scratch.case(name, &text)
}

/// A participant whose `check` passes, and refuses anything else.
fn passing(scratch: &Scratch) -> String {
    let p = scratch.script("good-solver", r#"[ "$1" = check ] && exit 0; exit 1"#);
    format!("[\"{}\"]", p.display())
}

fn check(scratch: &Scratch, case: &Path, extra: &[&str]) -> Finished {
    let args = [&["check", case.to_str().unwrap()][..], extra].concat();
    Fsi::start(scratch, &args).wait(Duration::from_secs(10))
}

#[test]
fn a_participant_that_refuses_the_case_is_reported_verbatim() {
    let scratch = Scratch::new();
    // It names the case file and the override it was given, as a real solver's error would.
    let body = r#"echo "mesh-solver: error: $2:7:1: structure.mesh.file: no such file (with $3 $4)" >&2
exit 1"#;
    let refusing = scratch.script("mesh-solver", body);
    let structure = format!("[\"{}\"]", refusing.display());
    let case = case(&scratch, "refused", &passing(&scratch), &structure);
    let done = check(&scratch, &case, &["--set", "coupling.dt=2e-3"]);
    println!("participant refused: {}", done.stderr.trim());
    assert_eq!(done.status.code(), Some(2), "{}{}", done.stdout, done.stderr);
    let want = format!(
        "fsi: error: structure participant {}: mesh-solver: error: {}:7:1: structure.mesh.file: \
         no such file (with --set coupling.dt=2e-3)",
        refusing.display(),
        case.display()
    );
    assert!(done.stderr.contains(&want), "expected `{want}` in:\n{}", done.stderr);
    assert!(done.stdout.contains("refused.toml: refused"), "{}", done.stdout);
    assert!(done.stdout.contains("good-solver") && done.stdout.contains("check passed"));
}

#[test]
fn a_missing_participant_program_fails_the_check() {
    let scratch = Scratch::new();
    let case = case(&scratch, "missing", r#"["no-such-solver-xyz"]"#, &passing(&scratch));
    let done = check(&scratch, &case, &[]);
    println!("missing program: {}", done.stderr.trim());
    assert!(!done.status.success(), "fsi check passed:\n{}", done.stdout);
    let want = [
        "missing.toml:7:1: field `fluid.command`: fluid participant `no-such-solver-xyz` not found",
        "[fluid] command",
    ];
    for w in want {
        assert!(done.stderr.contains(w), "no `{w}` in:\n{}", done.stderr);
    }
}

#[test]
fn a_participant_without_check_is_a_warning_not_a_pass() {
    let scratch = Scratch::new();
    // `fake-participant` takes no `check`: clap answers with a usage error (exit code 2).
    let fake = r#"["fake-participant", "--role", "fluid"]"#;
    let case = case(&scratch, "nocheck", fake, &passing(&scratch));
    let done = check(&scratch, &case, &[]);
    println!("no check command: {}", done.stderr.trim());
    assert!(done.status.success(), "{}", done.stderr);
    let want = "nocheck.toml:7:1: field `fluid.command`: the fluid participant `fake-participant` \
                offers no `check` command: its section was not validated";
    assert!(done.stderr.contains(want), "no `{want}` in:\n{}", done.stderr);
    assert!(done.stdout.contains("nocheck.toml: ok"), "{}", done.stdout);
}

#[test]
fn a_check_that_hangs_is_killed_at_the_timeout() {
    let scratch = Scratch::new();
    let hanging = scratch.script("hanging-solver", "exec sleep 30");
    let fluid = format!("[\"{}\"]", hanging.display());
    let case = case(&scratch, "hangs", &fluid, &passing(&scratch));
    let done = check(&scratch, &case, &[]);
    println!("hanging check after {:?}: {}", done.elapsed, done.stderr.trim());
    assert!(!done.status.success(), "fsi check passed:\n{}", done.stdout);
    let want = "did not end within 1 s (coupling.timeout_s) and was killed";
    assert!(done.stderr.contains(want), "no `{want}` in:\n{}", done.stderr);
    assert!(done.elapsed < Duration::from_secs(3), "took {:?}", done.elapsed);
}
