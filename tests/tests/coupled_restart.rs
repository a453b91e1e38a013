//! `fsi run CASE --restart DIR` through the real binaries (issue 12): a coupled run stopped
//! early and continued from its newest common checkpoint writes probe files equal byte for byte
//! to an uninterrupted run's: the rows up to the checkpoint kept, the rows the stopped run wrote
//! past it dropped, every later row continued bitwise. (a) `rigid-structure` + `fluid-solver` on
//! `cases/gas-piston` (C0, CSS); (b) `structure-solver` (a clamped MITC4 plate) + `fluid-solver`
//! (the air column it closes), C0 and A6.
//!
//! The stopped run ends at an earlier `coupling.t_end` that is not a checkpoint step, so it
//! writes rows past its last checkpoint; `coupling.dt` is a power of two so that t^n = n Δt of
//! the shorter run is the longer run's to the bit (`fsi_system_tests::restart`).
//!
//! Build first: `cargo build --release --workspace --bins`.

use fsi_system_tests::restart::{self, ok, restart_is_bitwise, sets};
use fsi_system_tests::{unique_run_id, Fsi, Scratch};
use std::path::Path;
use std::time::Duration;

fn gas_piston_restart(scheme: &str) {
    restart::gas_piston(scheme, &[]);
}

#[test]
fn gas_piston_c0_restart_continues_bitwise() {
    gas_piston_restart("C0");
}

#[test]
fn gas_piston_css_restart_continues_bitwise() {
    gas_piston_restart("CSS");
}

/// The clamped plate of `structure-solver/tests/clamped_plate.toml` (0.2 m steel, MITC4, 4 x 4,
/// 5 mm) in the plane z = 0, closing a column of air at 1e5 Pa below it (x, y in [0.075, 0.125],
/// z in [-0.305, 0.105], dz = 0.01: the plate half-way between two node layers); no fluid above
/// the plate.
fn plate_case(scheme: &str) -> String {
    const PLATE: &str = include_str!("../../structure-solver/tests/clamped_plate.toml");
    format!(
        r#"[case]
name = "plate-air"
[coupling]
scheme = "{scheme}"
dt = 1.9073486328125e-6
t_end = 1e-4
timeout_s = 30
[fluid]
command = ["fluid-solver"]
eos = {{ kind = "perfect_gas", gamma = 1.4 }}
probes = [{{ name = "below", at = [0.1, 0.1, -0.02] }}]
[fluid.mesh]
box = {{ lo = [0.075, 0.075, -0.305], hi = [0.125, 0.125, 0.105], cells = [1, 1, 41], shape = "tet" }}
[fluid.initial]
state = [1.2, 0.0, 0.0, 0.0, 1e5]
[fluid.boundary]
xmin = {{ kind = "symmetry" }}
xmax = {{ kind = "symmetry" }}
ymin = {{ kind = "symmetry" }}
ymax = {{ kind = "symmetry" }}
zmin = {{ kind = "slip_wall" }}
zmax = {{ kind = "slip_wall" }}
[fluid.embedded]
tracking = "collision"
loads = "facets"
seeds = [{{ at = [0.1, 0.1, -0.15], active = true }}, {{ at = [0.1, 0.1, 0.05], active = false }}]
[fluid.numerics]
flux = "roe"
limiter = "van_albada"
cfl = 0.5
[fluid.time]
t_end = 1e-4
[output]
fields_every = 0
checkpoint_every = 8
{PLATE}"#
    )
}

fn plate_restart(scheme: &str) {
    let scratch = Scratch::new();
    let case = scratch.case("plate-air", &plate_case(scheme));
    let moved = restart_is_bitwise(&case, &[], 1.9073486328125e-6, (16, 20, 36));
    eprintln!("{scheme}: largest plate-centre displacement {moved:e} m");
    assert!(moved > 1e-7, "the plate does not move: {moved:e}");
}

#[test]
fn mitc4_plate_c0_restart_continues_bitwise() {
    plate_restart("C0");
}

#[test]
fn mitc4_plate_a6_restart_continues_bitwise() {
    plate_restart("A6");
}

/// A folder without a common checkpoint, and a checkpoint of another scheme or step: refused
/// before anything runs, naming the folder or file and what was expected.
#[test]
fn a_restart_without_a_matching_checkpoint_is_refused() {
    let scratch = Scratch::new();
    let case = restart::gas_piston_case();
    let fsi = |dir: &Path, extra: &[&str]| {
        let id = unique_run_id("norestart");
        let mut args = vec!["run", case.to_str().unwrap(), "--quiet", "--run-id", &id];
        args.extend(["--restart", dir.to_str().unwrap()]);
        args.extend(extra);
        let done = Fsi::start(&scratch, &args).wait(Duration::from_secs(30));
        assert!(!done.status.success(), "fsi run --restart {} succeeded", dir.display());
        done.stderr
    };
    let empty = scratch.path().join("empty");
    std::fs::create_dir(&empty).unwrap();
    let e = fsi(&empty, &[]);
    assert!(e.contains("no common checkpoint") && e.contains("empty/checkpoints"), "{e}");
    // A run of C0 at 2^-12 s with checkpoints every 4 steps, 8 steps long.
    let run = scratch.path().join("run");
    let dt = 2f64.powi(-12);
    let overrides = [format!("coupling.dt={dt:e}"), "output.checkpoint_every=4".to_string()];
    let args = sets(&overrides, 8.0 * dt);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    ok(Fsi::run(&scratch, &case, &run, &args), "fsi run");
    let e =
        fsi(&run, &["--set", "coupling.scheme=\"A6\"", "--set", &format!("coupling.dt={dt:e}")]);
    assert!(e.contains("step_0000000008/launcher.ckpt") && e.contains("asks for A6"), "{e}");
    let e = fsi(&run, &["--set", "coupling.dt=1e-4"]);
    assert!(e.contains("coupling.dt = 1e-4"), "{e}");
    // The run's end is its last checkpoint: nothing to continue without a later t_end.
    let e = fsi(&run, &args);
    assert!(e.contains("nothing to continue"), "{e}");
}

/// A participant whose `Hello` does not announce the restart capability (`piston-fluid`, which
/// keeps no state) is refused after the handshake, by name, even where its checkpoint folder
/// holds a fluid part.
#[test]
fn a_participant_that_cannot_restart_is_refused_by_name() {
    use interface_protocol::io::checkpoint::{tag_for_step, Checkpoint};
    let scratch = Scratch::new();
    let case = Path::new(env!("CARGO_MANIFEST_DIR")).join("../cases/spring-piston/case.toml");
    let run = scratch.path().join("run");
    let overrides = ["output.checkpoint_every=4".to_string()];
    let args = sets(&overrides, 8e-3);
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    ok(Fsi::run(&scratch, &case, &run, &args), "fsi run spring-piston");
    // piston-fluid writes no part of its own; give the folder one so that the search passes.
    let ck = run.join("checkpoints");
    Checkpoint::new(4, 4e-3).write(&ck, &tag_for_step(4), "fluid").unwrap();
    let id = unique_run_id("incapable");
    let restart = sets(&overrides, 16e-3);
    let mut args = vec!["run", case.to_str().unwrap(), "--quiet", "--run-id", &id];
    args.extend(["--restart", run.to_str().unwrap()]);
    args.extend(restart.iter().map(String::as_str));
    let done = Fsi::start(&scratch, &args).wait(Duration::from_secs(30));
    assert!(!done.status.success(), "a restart with piston-fluid succeeded");
    let e = done.stderr;
    assert!(e.contains("piston-fluid (fluid") && e.contains("restart capability"), "{e}");
    assert!(!e.contains("rigid-structure (structure"), "{e}");
}
