//! The launcher's supervision through real processes: a participant killed, `fsi` killed, a
//! handshake refused, a participant that never starts or stops answering. Each ends with a clear
//! error within its deadline, no process left and no shared-memory file of the run remaining.

use fsi_system_tests::{
    alive, run_files, signal, unique_run_id, wait_gone, Finished, Fsi, Scratch,
};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// A piston case that would run for hours: it only ends when a test ends it.
fn endless_case(scratch: &Scratch, timeout_s: f64) -> PathBuf {
    let text = format!(
        r#"[coupling]
scheme = "C0"
dt = 1e-5
t_end = 1e3
timeout_s = {timeout_s}
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
stiffness = 3947.8
probe = "piston"
"#
    );
    scratch.case("endless", &text)
}

/// A case with the given participant commands (TOML arrays) and timeout.
fn case_with(
    scratch: &Scratch,
    name: &str,
    fluid: &str,
    structure: &str,
    timeout_s: f64,
) -> PathBuf {
    let text = format!(
        r#"[coupling]
scheme = "A6"
dt = 1e-3
t_end = 1e-2
timeout_s = {timeout_s}
[fluid]
command = {fluid}
[fluid.piston]
area = 1e-3
p0 = 1e5
rho0 = 1.2
c0 = 340.0
[structure]
command = {structure}
[structure.rigid]
mass = 1.0
stiffness = 3947.8
"#
    );
    scratch.case(name, &text)
}

/// Waits until the run is stepping (the structure wrote probe rows), then returns both
/// participants as (pid, name).
fn running(fsi: &Fsi, out: &Path) -> Vec<(i32, String)> {
    let deadline = Instant::now() + Duration::from_secs(10);
    let probes = out.join("structure_probes.csv");
    while std::fs::read_to_string(&probes).map_or(0, |t| t.lines().count()) < 3 {
        assert!(Instant::now() < deadline, "the run did not start stepping within 10 s");
        std::thread::sleep(Duration::from_millis(10));
    }
    let kids = fsi.participants(Duration::from_secs(2));
    assert_eq!(kids.len(), 2, "participants of fsi: {kids:?}");
    kids
}

fn pid_of(kids: &[(i32, String)], name: &str) -> i32 {
    kids.iter()
        .find(|(_, n)| name.starts_with(n.as_str()))
        .map(|k| k.0)
        .unwrap_or_else(|| panic!("no participant named {name} among {kids:?}"))
}

fn assert_failed_naming(done: &Finished, words: &[&str]) {
    assert!(!done.status.success(), "fsi succeeded:\n{}", done.stderr);
    for w in words {
        assert!(done.stderr.contains(w), "the error does not name `{w}`:\n{}", done.stderr);
    }
}

fn assert_no_run_files(run_id: &str) {
    let left = run_files(run_id);
    assert!(left.is_empty(), "files of run {run_id} remain: {left:?}");
}

/// SIGKILL of one participant: fsi exits non-zero within 1 s naming it and the signal, the
/// other participant is gone and no file of the run remains.
fn kill_participant(victim: &str, survivor: &str) {
    let scratch = Scratch::new();
    let case = endless_case(&scratch, 10.0);
    let out = scratch.path().join("out");
    let fsi = Fsi::run(&scratch, &case, &out, &[]);
    let run_id = fsi.run_id.clone();
    let kids = running(&fsi, &out);
    let (v, s) = (pid_of(&kids, victim), pid_of(&kids, survivor));
    let killed = Instant::now();
    signal(v, libc::SIGKILL);
    let done = fsi.wait(Duration::from_secs(10));
    let after = killed.elapsed();
    println!("{victim} killed: fsi exited {after:?} later: {}", done.stderr.trim());
    assert!(after < Duration::from_secs(1), "fsi took {after:?} to exit after the kill");
    assert_failed_naming(&done, &[victim, "SIGKILL"]);
    assert!(!alive(s), "{survivor} (pid {s}) is still running");
    assert_no_run_files(&run_id);
}

#[test]
fn killing_the_structure_stops_the_run_within_a_second() {
    kill_participant("rigid-structure", "piston-fluid");
}

#[test]
fn killing_the_fluid_stops_the_run_within_a_second() {
    kill_participant("piston-fluid", "rigid-structure");
}

#[test]
fn killing_fsi_ends_both_participants_within_a_second() {
    let scratch = Scratch::new();
    let case = endless_case(&scratch, 10.0);
    let out = scratch.path().join("out");
    let fsi = Fsi::run(&scratch, &case, &out, &[]);
    let run_id = fsi.run_id.clone();
    let kids = running(&fsi, &out);
    let pids: Vec<i32> = kids.iter().map(|k| k.0).collect();
    signal(fsi.pid(), libc::SIGKILL);
    let gone = wait_gone(&pids, Duration::from_secs(5));
    let _ = fsi.wait(Duration::from_secs(5));
    // Nobody is left to remove the run's files: the next launcher removes stale runs; here the
    // test does, so nothing accumulates.
    let _ = interface_protocol::shm::cleanup_run(&run_id);
    let gone =
        gone.unwrap_or_else(|| panic!("participants {kids:?} still alive 5 s after fsi died"));
    println!("fsi killed: participants gone {gone:?} later");
    assert!(gone < Duration::from_secs(1), "participants took {gone:?} to exit");
}

#[test]
fn sigterm_to_fsi_stops_both_participants_cleanly() {
    let scratch = Scratch::new();
    let case = endless_case(&scratch, 10.0);
    let out = scratch.path().join("out");
    let fsi = Fsi::run(&scratch, &case, &out, &[]);
    let run_id = fsi.run_id.clone();
    let kids = running(&fsi, &out);
    signal(fsi.pid(), libc::SIGTERM);
    let done = fsi.wait(Duration::from_secs(5));
    println!("fsi got SIGTERM: exited after {:?}: {}", done.elapsed, done.stderr.trim());
    assert_eq!(done.status.code(), Some(128 + libc::SIGTERM), "{}", done.stderr);
    assert!(done.stderr.contains("stopped by SIGTERM"), "{}", done.stderr);
    for (pid, name) in &kids {
        assert!(!alive(*pid), "{name} (pid {pid}) survived");
    }
    assert_no_run_files(&run_id);
    // run.json says why the run stopped.
    let report = std::fs::read_to_string(out.join("run.json")).expect("run.json");
    assert!(report.contains("stopped by SIGTERM"), "{report}");
}

#[test]
fn a_protocol_version_mismatch_is_refused_naming_both_versions() {
    let scratch = Scratch::new();
    let stub = r#"["fake-participant", "--role", "structure", "--protocol-version", "99"]"#;
    let case = case_with(&scratch, "version", r#"["piston-fluid"]"#, stub, 5.0);
    let out = scratch.path().join("out");
    let fsi = Fsi::run(&scratch, &case, &out, &[]);
    let run_id = fsi.run_id.clone();
    let done = fsi.wait(Duration::from_secs(10));
    println!("version mismatch after {:?}: {}", done.elapsed, done.stderr.trim());
    assert_failed_naming(&done, &["protocol version", "structure 99"]);
    assert!(done.elapsed < Duration::from_secs(4), "took {:?}: not refused at once", done.elapsed);
    assert_no_run_files(&run_id);
}

#[test]
fn a_node_count_mismatch_is_refused_naming_both_counts() {
    let scratch = Scratch::new();
    let stub = r#"["fake-participant", "--role", "fluid", "--nodes", "5"]"#;
    let case = case_with(&scratch, "nodes", stub, r#"["rigid-structure"]"#, 5.0);
    let out = scratch.path().join("out");
    let fsi = Fsi::run(&scratch, &case, &out, &[]);
    let run_id = fsi.run_id.clone();
    let done = fsi.wait(Duration::from_secs(10));
    println!("node-count mismatch after {:?}: {}", done.elapsed, done.stderr.trim());
    assert_failed_naming(&done, &["fluid expects 5, structure has 1"]);
    assert!(done.elapsed < Duration::from_secs(4), "took {:?}: not refused at once", done.elapsed);
    assert_no_run_files(&run_id);
}

#[test]
fn a_participant_that_never_sends_hello_is_named_after_the_timeout() {
    let scratch = Scratch::new();
    let silent = scratch.script("silent-solver", "exec sleep 1000");
    let structure = format!("[\"{}\"]", silent.display());
    let case = case_with(&scratch, "silent", r#"["piston-fluid"]"#, &structure, 1.5);
    let out = scratch.path().join("out");
    let fsi = Fsi::run(&scratch, &case, &out, &[]);
    let run_id = fsi.run_id.clone();
    let done = fsi.wait(Duration::from_secs(10));
    println!("no hello after {:?}: {}", done.elapsed, done.stderr.trim());
    // Either the launcher's wait for the Hello runs out first, or the fluid's wait for its first
    // command does and the launcher says what it was waiting for: both name the silent solver.
    assert_failed_naming(&done, &["silent-solver", "structure", "Hello"]);
    let limit = Duration::from_secs_f64(1.5 + 2.0);
    assert!(done.elapsed < limit, "took {:?}", done.elapsed);
    assert_no_run_files(&run_id);
}

#[test]
fn a_missing_participant_binary_is_named_at_once() {
    let scratch = Scratch::new();
    let case =
        case_with(&scratch, "missing", r#"["no-such-solver-xyz"]"#, r#"["rigid-structure"]"#, 5.0);
    let out = scratch.path().join("out");
    let fsi = Fsi::run(&scratch, &case, &out, &[]);
    let run_id = fsi.run_id.clone();
    let done = fsi.wait(Duration::from_secs(10));
    println!("missing binary after {:?}: {}", done.elapsed, done.stderr.trim());
    assert_failed_naming(&done, &["no-such-solver-xyz", "not found", "fluid"]);
    assert!(done.elapsed < Duration::from_secs(3), "took {:?}", done.elapsed);
    assert_no_run_files(&run_id);
}

#[test]
fn a_participant_that_stops_answering_ends_the_run_after_the_timeout() {
    let scratch = Scratch::new();
    let timeout_s = 1.5;
    let case = endless_case(&scratch, timeout_s);
    let out = scratch.path().join("out");
    let fsi = Fsi::run(&scratch, &case, &out, &[]);
    let run_id = fsi.run_id.clone();
    let kids = running(&fsi, &out);
    let fluid = pid_of(&kids, "piston-fluid");
    let stopped = Instant::now();
    signal(fluid, libc::SIGSTOP);
    let done = fsi.wait(Duration::from_secs(15));
    let after = stopped.elapsed();
    println!("fluid stopped: fsi exited {after:?} later: {}", done.stderr.trim());
    // The stopped fluid is named, whether the launcher's wait for it or the structure's wait for
    // the next command runs out first.
    assert_failed_naming(&done, &["piston-fluid"]);
    let limit = Duration::from_secs_f64(timeout_s + 2.0);
    assert!(after < limit, "fsi took {after:?} after the fluid stopped (timeout {timeout_s} s)");
    for (pid, name) in &kids {
        assert!(!alive(*pid), "{name} (pid {pid}) survived");
    }
    assert_no_run_files(&run_id);
}

#[test]
fn a_failed_reply_finishes_the_other_participant_and_reports_the_message() {
    let scratch = Scratch::new();
    let fluid = r#"["fake-participant", "--role", "fluid", "--fail-init", "mesh file cylinder.msh missing"]"#;
    let case = case_with(&scratch, "failed", fluid, r#"["rigid-structure"]"#, 5.0);
    let out = scratch.path().join("out");
    let fsi = Fsi::run(&scratch, &case, &out, &[]);
    let run_id = fsi.run_id.clone();
    let done = fsi.wait(Duration::from_secs(10));
    println!("failed init after {:?}: {}", done.elapsed, done.stderr.trim());
    assert_failed_naming(&done, &["fluid failed at Init", "mesh file cylinder.msh missing"]);
    assert!(done.elapsed < Duration::from_secs(4), "took {:?}", done.elapsed);
    // The structure was told to finish, and did: it reports no error of its own.
    assert!(!done.stderr.contains("rigid-structure:"), "{}", done.stderr);
    assert_no_run_files(&run_id);
}

#[test]
fn run_ids_of_tests_are_unique() {
    assert_ne!(unique_run_id("a"), unique_run_id("a"));
}
