//! The launcher's supervision through real processes: a participant killed or stopped, `fsi`
//! killed or hung up, a handshake refused, a participant that never starts, one that answers
//! `Failed`, a run id used twice. Each ends with a clear error within its deadline, no process
//! left and no shared-memory file of the run remaining. Every case here has `timeout_s <= 2`;
//! `scripts/fault-loop` runs this file repeatedly.
//!
//! The faults of a running pair (a participant killed or stopped, `fsi` killed, `SIGTERM` to
//! `fsi`) run one test body for each [`Pair`]: the analytic participants (`piston-fluid` and
//! `rigid-structure`) and the real solvers (`fluid-solver` and `structure-solver` on
//! `cases/gas-piston/case-structure.toml`, coarsened, made endless and given the test's
//! timeout through `--set`).

use fsi_system_tests::{
    alive, run_files, signal, unique_run_id, wait_gone, Finished, Fsi, Scratch,
};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// The participant pair of a fault test and how to start its endless run.
#[derive(Debug, Clone, Copy)]
enum Pair {
    /// `piston-fluid` and `rigid-structure` on `endless_case`.
    Analytic,
    /// `fluid-solver` (embedded plate) and `structure-solver` (a rigid part on a spring) on
    /// `cases/gas-piston/case-structure.toml`.
    Solvers,
}

/// One participant of a pair.
#[derive(Debug, Clone, Copy)]
enum Side {
    Fluid,
    Structure,
}

impl Side {
    fn other(self) -> Side {
        match self {
            Side::Fluid => Side::Structure,
            Side::Structure => Side::Fluid,
        }
    }
}

impl Pair {
    /// The program name of `side`.
    fn name(self, side: Side) -> &'static str {
        match (self, side) {
            (Pair::Analytic, Side::Fluid) => "piston-fluid",
            (Pair::Analytic, Side::Structure) => "rigid-structure",
            (Pair::Solvers, Side::Fluid) => "fluid-solver",
            (Pair::Solvers, Side::Structure) => "structure-solver",
        }
    }

    /// Starts a run that only ends when the test ends it, with `timeout_s`, its output in
    /// `<scratch>/out`; returns `fsi` once both participants are stepping, with them as
    /// (pid, name).
    fn start(self, scratch: &Scratch, timeout_s: f64) -> (Fsi, PathBuf, Vec<(i32, String)>) {
        let out = scratch.path().join("out");
        let fsi = match self {
            Pair::Analytic => Fsi::run(scratch, &endless_case(scratch, timeout_s), &out, &[]),
            Pair::Solvers => {
                let case = Path::new(env!("CARGO_MANIFEST_DIR"))
                    .join("../cases/gas-piston/case-structure.toml");
                let sets = [
                    "coupling.t_end=1e3".to_string(),
                    format!("coupling.timeout_s={timeout_s:?}"),
                    // dx = 0.05 m: the plate at 1.005 m between the nodes at 1.00 and 1.05.
                    "fluid.mesh.box.cells=[22,1,1]".into(),
                ];
                let args: Vec<&str> = sets.iter().flat_map(|s| ["--set", s.as_str()]).collect();
                Fsi::run(scratch, &case, &out, &args)
            }
        };
        let kids = running(&fsi, &out);
        (fsi, out, kids)
    }
}

/// A piston case that would run for hours: it only ends when a test ends it.
fn endless_case(scratch: &Scratch, timeout_s: f64) -> PathBuf {
    scratch.case("endless", &endless_case_text(timeout_s))
}

/// The text of `endless_case`.
fn endless_case_text(timeout_s: f64) -> String {
    format!(
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
    )
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
fn kill_participant(pair: Pair, side: Side) {
    let (victim, survivor) = (pair.name(side), pair.name(side.other()));
    let scratch = Scratch::new();
    let (fsi, _, kids) = pair.start(&scratch, 2.0);
    let run_id = fsi.run_id.clone();
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

/// SIGKILL of fsi: both participants exit within 1 s, and the next launcher (whatever its run
/// id) removes the files the dead run left.
fn kill_fsi(pair: Pair) {
    let scratch = Scratch::new();
    let (fsi, _, kids) = pair.start(&scratch, 2.0);
    let run_id = fsi.run_id.clone();
    let pids: Vec<i32> = kids.iter().map(|k| k.0).collect();
    signal(fsi.pid(), libc::SIGKILL);
    let gone = wait_gone(&pids, Duration::from_secs(5));
    let _ = fsi.wait(Duration::from_secs(5));
    let gone =
        gone.unwrap_or_else(|| panic!("participants {kids:?} still alive 5 s after fsi died"));
    println!("fsi killed: participants gone {gone:?} later");
    assert!(gone < Duration::from_secs(1), "participants took {gone:?} to exit");
    // Nobody was left to remove the run's files (its lock and iceoryx2's global_mgmt at least):
    // the next launcher, whatever its run id, removes every one of them at once.
    let left = run_files(&run_id);
    assert!(!left.is_empty(), "a killed fsi left no file: the test proves nothing");
    let later = quick_case(&scratch, "later");
    let done = Fsi::run(&scratch, &later, &scratch.path().join("later"), &[]).wait(LIMIT);
    assert!(done.status.success(), "the later run failed:\n{}", done.stderr);
    let still = run_files(&run_id);
    // Leave nothing behind even when the assertion fails.
    let _ = interface_protocol::shm::cleanup_run(&run_id);
    assert!(still.is_empty(), "the later run left files of the dead run: {still:?} (of {left:?})");
}

/// `signal` to fsi: it exits with 128 + signal, naming it; both participants are gone, no file
/// of the run remains and `run.json` says the run was interrupted and by what.
fn stop_fsi_with(pair: Pair, signal_number: i32, name: &str) {
    let scratch = Scratch::new();
    let (fsi, out, kids) = pair.start(&scratch, 2.0);
    let run_id = fsi.run_id.clone();
    signal(fsi.pid(), signal_number);
    let done = fsi.wait(Duration::from_secs(5));
    println!("fsi got {name}: exited after {:?}: {}", done.elapsed, done.stderr.trim());
    assert_eq!(done.status.code(), Some(128 + signal_number), "{}", done.stderr);
    let why = format!("stopped by {name}");
    assert!(done.stderr.contains(&why), "{}", done.stderr);
    for (pid, name) in &kids {
        assert!(!alive(*pid), "{name} (pid {pid}) survived");
    }
    assert_no_run_files(&run_id);
    let report = std::fs::read_to_string(out.join("run.json")).expect("run.json");
    assert_eq!(status_of(&report), format!("interrupted: {why}"), "{report}");
}

#[test]
fn a_second_run_with_the_same_id_is_refused_and_the_first_finishes_untouched() {
    let scratch = Scratch::new();
    // About 1e4 steps: long enough to be running while the second launcher tries.
    let case = scratch.case("first", &endless_case_text(2.0).replace("t_end = 1e3", "t_end = 0.1"));
    let out = scratch.path().join("first");
    let first = Fsi::run(&scratch, &case, &out, &[]);
    let run_id = first.run_id.clone();
    running(&first, &out);
    let second_out = scratch.path().join("second");
    let args = ["run", case.to_str().unwrap(), "--out", second_out.to_str().unwrap(), "--quiet"];
    let second = Fsi::start(&scratch, &[&args[..], &["--run-id", &run_id]].concat());
    let refused = second.wait(Duration::from_secs(5));
    println!("second launcher: exited after {:?}: {}", refused.elapsed, refused.stderr.trim());
    let want = format!("run id {run_id} is in use by pid {}", first.pid());
    assert_failed_naming(&refused, &[&want]);
    assert!(refused.elapsed < Duration::from_secs(1), "refused after {:?}", refused.elapsed);
    assert!(!second_out.exists(), "the refused run created its output folder");
    let done = first.wait(LIMIT);
    assert!(done.status.success(), "the first run failed:\n{}", done.stderr);
    assert!(done.stderr.trim().is_empty(), "the first run printed:\n{}", done.stderr);
    let report = std::fs::read_to_string(out.join("run.json")).expect("run.json");
    assert_eq!(status_of(&report), "completed");
    assert_no_run_files(&run_id);
}

#[test]
fn a_protocol_version_mismatch_is_refused_naming_both_versions() {
    let scratch = Scratch::new();
    let stub = r#"["fake-participant", "--role", "structure", "--protocol-version", "99"]"#;
    let case = case_with(&scratch, "version", r#"["piston-fluid"]"#, stub, 2.0);
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
    let case = case_with(&scratch, "nodes", stub, r#"["rigid-structure"]"#, 2.0);
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
        case_with(&scratch, "missing", r#"["no-such-solver-xyz"]"#, r#"["rigid-structure"]"#, 2.0);
    let out = scratch.path().join("out");
    let fsi = Fsi::run(&scratch, &case, &out, &[]);
    let run_id = fsi.run_id.clone();
    let done = fsi.wait(Duration::from_secs(10));
    println!("missing binary after {:?}: {}", done.elapsed, done.stderr.trim());
    assert_failed_naming(&done, &["no-such-solver-xyz", "not found", "fluid"]);
    assert!(done.elapsed < Duration::from_secs(3), "took {:?}", done.elapsed);
    assert_no_run_files(&run_id);
}

/// SIGSTOP of one participant: fsi blames it (whose reply is missing), never the other one
/// (whose own wait for a command is longer than the launcher's for a reply), after the timeout.
fn stop_participant(pair: Pair, side: Side) {
    let (victim, other) = (pair.name(side), pair.name(side.other()));
    let scratch = Scratch::new();
    let timeout_s = 1.0;
    let (fsi, _, kids) = pair.start(&scratch, timeout_s);
    let run_id = fsi.run_id.clone();
    let v = pid_of(&kids, victim);
    let stopped = Instant::now();
    signal(v, libc::SIGSTOP);
    let done = fsi.wait(Duration::from_secs(15));
    let after = stopped.elapsed();
    let error = fsi_error(&done);
    println!("{victim} stopped: fsi exited {after:?} later: {error}");
    assert!(!done.status.success(), "fsi succeeded:\n{}", done.stderr);
    for w in [victim, "did not answer", "its process is stopped"] {
        assert!(error.contains(w), "the error does not name `{w}`: {error}");
    }
    assert!(!error.contains(other), "the error blames {other}: {error}");
    let limit = Duration::from_secs_f64(timeout_s + 2.0);
    assert!(after < limit, "fsi took {after:?} after {victim} stopped (timeout {timeout_s} s)");
    for (pid, name) in &kids {
        assert!(!alive(*pid), "{name} (pid {pid}) survived");
    }
    assert_no_run_files(&run_id);
}

#[test]
fn a_failed_reply_finishes_the_other_participant_and_reports_the_message() {
    let scratch = Scratch::new();
    let fluid = r#"["fake-participant", "--role", "fluid", "--fail-init", "mesh file cylinder.msh missing"]"#;
    let case = case_with(&scratch, "failed", fluid, r#"["rigid-structure"]"#, 2.0);
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
    let report = std::fs::read_to_string(out.join("run.json")).expect("run.json");
    assert!(status_of(&report).starts_with("failed: fluid failed at Init"), "{report}");
}

/// A `Failed` reply in any phase of the scheme fails the run with the participant's message:
/// non-zero exit, `run.json` status `failed: ...`, both participants finished.
#[test]
fn a_failed_reply_in_any_phase_fails_the_run_with_its_message() {
    let scratch = Scratch::new();
    let phases = [
        ("structure", "init", 0, "Init"),
        ("fluid", "init", 0, "Init"),
        ("structure", "start", 0, "Advance START"),
        ("fluid", "start", 0, "Advance START"),
        ("structure", "predict", 2, "Advance PREDICT step 2"),
        ("fluid", "advance", 2, "Advance NONE step 2"),
        ("structure", "correct", 2, "Advance CORRECT step 2"),
        ("structure", "checkpoint", 2, "Checkpoint"),
        ("fluid", "checkpoint", 4, "Checkpoint"),
        ("structure", "finish", 0, "Finish"),
        ("fluid", "finish", 0, "Finish"),
    ];
    for (role, on, step, command) in phases {
        let message = format!("state not finite ({role} {on} {step})");
        let fake = |r: &str| {
            let mut words = vec!["fake-participant".to_string(), "--role".into(), r.into()];
            if r == role {
                let step = step.to_string();
                words.extend(
                    ["--fail", &message, "--fail-on", on, "--fail-step", &step].map(String::from),
                );
            } else {
                words.push("--serve".into());
            }
            format!("{words:?}")
        };
        let text = format!(
            "[coupling]\nscheme = \"C0\"\ndt = 1e-3\nt_end = 5e-3\ntimeout_s = 2\n\
             [output]\ncheckpoint_every = 2\n[fluid]\ncommand = {}\n[structure]\ncommand = {}\n",
            fake("fluid"),
            fake("structure")
        );
        let name = format!("{role}-{on}");
        let case = scratch.case(&name, &text);
        let out = scratch.path().join(&name);
        let fsi = Fsi::run(&scratch, &case, &out, &[]);
        let run_id = fsi.run_id.clone();
        let done = fsi.wait(Duration::from_secs(10));
        let error = fsi_error(&done);
        println!("{role} failing at {on}: after {:?}: {error}", done.elapsed);
        let at = format!("{role} failed at {command}");
        assert_failed_naming(&done, &[&at, &message]);
        assert!(done.elapsed < Duration::from_secs(3), "{name}: took {:?}", done.elapsed);
        let report = std::fs::read_to_string(out.join("run.json")).expect("run.json");
        let status = status_of(&report);
        assert!(status.starts_with("failed: ") && status.contains(&message), "{name}: {report}");
        assert_no_run_files(&run_id);
    }
}

/// Wait limit of a run that should complete.
const LIMIT: Duration = Duration::from_secs(30);

/// A coupled piston run of ten steps.
fn quick_case(scratch: &Scratch, name: &str) -> PathBuf {
    let text = endless_case_text(2.0).replace("dt = 1e-5\nt_end = 1e3", "dt = 1e-3\nt_end = 1e-2");
    scratch.case(name, &text)
}

/// The `status` of a `run.json`.
fn status_of(report: &str) -> String {
    let v: serde_json::Value = serde_json::from_str(report).expect("run.json is JSON");
    v["status"].as_str().expect("a status").to_string()
}

/// fsi's own error line (`fsi: error: ...`), without the participants' lines around it.
fn fsi_error(done: &Finished) -> String {
    let line = done.stderr.lines().find(|l| l.starts_with("fsi: error:"));
    line.unwrap_or_else(|| panic!("no `fsi: error:` line in:\n{}", done.stderr)).to_string()
}

#[test]
fn run_ids_of_tests_are_unique() {
    assert_ne!(unique_run_id("a"), unique_run_id("a"));
}

/// One test per fault and participant pair, each a call of the fault's one body.
macro_rules! fault_tests {
    ($($name:ident: $body:expr;)*) => {
        $(
            #[test]
            fn $name() {
                $body
            }
        )*
    };
}

fault_tests! {
    killing_the_structure_stops_the_run_within_a_second: kill_participant(Pair::Analytic, Side::Structure);
    killing_the_fluid_stops_the_run_within_a_second: kill_participant(Pair::Analytic, Side::Fluid);
    killing_the_structure_solver_stops_the_run_within_a_second: kill_participant(Pair::Solvers, Side::Structure);
    killing_the_fluid_solver_stops_the_run_within_a_second: kill_participant(Pair::Solvers, Side::Fluid);
    killing_fsi_ends_both_participants_and_a_later_run_removes_its_files: kill_fsi(Pair::Analytic);
    killing_fsi_ends_both_solvers_and_a_later_run_removes_its_files: kill_fsi(Pair::Solvers);
    sigterm_to_fsi_stops_both_participants_cleanly: stop_fsi_with(Pair::Analytic, libc::SIGTERM, "SIGTERM");
    sigterm_to_fsi_stops_both_solvers_cleanly: stop_fsi_with(Pair::Solvers, libc::SIGTERM, "SIGTERM");
    sighup_to_fsi_stops_both_participants_cleanly: stop_fsi_with(Pair::Analytic, libc::SIGHUP, "SIGHUP");
    a_stopped_fluid_is_blamed_after_the_timeout: stop_participant(Pair::Analytic, Side::Fluid);
    a_stopped_structure_is_blamed_after_the_timeout: stop_participant(Pair::Analytic, Side::Structure);
    a_stopped_fluid_solver_is_blamed_after_the_timeout: stop_participant(Pair::Solvers, Side::Fluid);
    a_stopped_structure_solver_is_blamed_after_the_timeout: stop_participant(Pair::Solvers, Side::Structure);
}
