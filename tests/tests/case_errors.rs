//! Malformed case files through `fsi check`: each error names the file, the line and the field,
//! and says what was expected; a valid case prints its summary.

use fsi_system_tests::{Finished, Fsi, Scratch};
use std::time::Duration;

fn check(scratch: &Scratch, name: &str, text: &str) -> Finished {
    let case = scratch.case(name, text);
    Fsi::start(scratch, &["check", case.to_str().unwrap()]).wait(Duration::from_secs(10))
}

/// The error of `fsi check` on `text` names `<name>.toml:<line>:` and every word of `words`.
fn rejects(name: &str, text: &str, line: usize, words: &[&str]) {
    let scratch = Scratch::new();
    let done = check(&scratch, name, text);
    assert!(!done.status.success(), "{name}: fsi check accepted it:\n{}", done.stdout);
    let at = format!("{name}.toml:{line}:");
    assert!(done.stderr.contains(&at), "{name}: the error does not say `{at}`:\n{}", done.stderr);
    for w in words {
        assert!(done.stderr.contains(w), "{name}: the error does not name `{w}`:\n{}", done.stderr);
    }
}

const GOOD: &str = r#"[case]
name = "piston"
[coupling]
scheme = "A6"
dt = 1e-3
t_end = 2.5e-2
[fluid]
command = ["piston-fluid"]
[fluid.piston]
area = 1e-3
p0 = 1e5
rho0 = 1.2
c0 = 340.0
[structure]
command = ["rigid-structure"]
[structure.rigid]
mass = 1.0
stiffness = 100.0
"#;

#[test]
fn a_valid_case_prints_its_summary() {
    let scratch = Scratch::new();
    let done = check(&scratch, "good", GOOD);
    assert!(done.status.success(), "{}", done.stderr);
    for w in ["good.toml: ok", "A6", "25 steps", "piston-fluid", "rigid-structure", "case hash"] {
        assert!(done.stdout.contains(w), "the summary lacks `{w}`:\n{}", done.stdout);
    }
}

#[test]
fn a_missing_field_names_its_table_and_line() {
    let text = GOOD.replace("c0 = 340.0\n", "");
    rejects("missing", &text, 9, &["fluid.piston", "c0"]);
}

#[test]
fn a_wrong_type_names_the_field_and_line() {
    let text = GOOD.replace("dt = 1e-3", "dt = \"fast\"");
    rejects("wrong-type", &text, 5, &["coupling.dt"]);
}

#[test]
fn an_unknown_key_names_the_key_and_line() {
    let text = GOOD.replace("[structure.rigid]\n", "[structure.rigid]\nmas = 2.0\n");
    rejects("unknown-key", &text, 17, &["structure.rigid.mas", "mass"]);
}

#[test]
fn a_bad_enum_value_lists_the_choices() {
    let text = GOOD.replace("scheme = \"A6\"", "scheme = \"C1\"");
    rejects("bad-enum", &text, 4, &["coupling.scheme", "CSS", "C0", "A6"]);
}

#[test]
fn an_invalid_value_names_the_field_and_line() {
    let text = GOOD.replace("mass = 1.0", "mass = -1.0");
    rejects("negative-mass", &text, 17, &["structure.rigid.mass", "> 0"]);
}

#[test]
fn a_missing_case_file_is_an_error_not_a_panic() {
    let scratch = Scratch::new();
    let done =
        Fsi::start(&scratch, &["check", "/nonexistent/case.toml"]).wait(Duration::from_secs(10));
    assert!(!done.status.success());
    assert!(
        done.stderr.contains("/nonexistent/case.toml") && !done.stderr.contains("panicked"),
        "{}",
        done.stderr
    );
}
