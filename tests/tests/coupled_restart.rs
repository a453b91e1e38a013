//! `fsi run CASE --restart DIR` through the real binaries (issue 12): a coupled run stopped
//! early and continued from its newest common checkpoint writes probe files equal byte for byte
//! to an uninterrupted run's: the rows up to the checkpoint kept, the rows the stopped run wrote
//! past it dropped, every later row continued bitwise. (a) `rigid-structure` + `fluid-solver` on
//! `cases/gas-piston` (C0, CSS); (b) `structure-solver` (a clamped MITC4 plate) + `fluid-solver`
//! (the air column it closes), C0 and A6.
//!
//! The stopped run ends at an earlier `coupling.t_end` that is not a checkpoint step, so it
//! writes rows past its last checkpoint; `coupling.dt` is a power of two so that t^n = n Δt of
//! the shorter run is the longer run's to the bit.
//!
//! Build first: `cargo build --release --workspace --bins`.

use fsi_system_tests::{unique_run_id, Fsi, Scratch};
use std::path::{Path, PathBuf};
use std::time::Duration;

/// The probe files both participants write.
const PROBE_FILES: [&str; 2] = ["probes.csv", "structure_probes.csv"];

fn gas_piston() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../cases/gas-piston/case.toml")
}

/// `--set` pairs for the overrides and `coupling.t_end = n dt`.
fn sets(overrides: &[String], t_end: f64) -> Vec<String> {
    let mut v = Vec::new();
    for o in overrides.iter().cloned().chain([format!("coupling.t_end={t_end:e}")]) {
        v.push("--set".to_string());
        v.push(o);
    }
    v
}

fn ok(fsi: Fsi, what: &str) {
    let done = fsi.wait(Duration::from_secs(60));
    assert!(done.status.success(), "{what} failed:\n{}", done.stderr);
}

fn read(dir: &Path, file: &str) -> String {
    std::fs::read_to_string(dir.join(file)).unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
}

/// The times of a probe file's rows.
fn times(text: &str) -> Vec<f64> {
    text.lines().skip(1).map(|l| l.split(',').next().unwrap().parse().unwrap()).collect()
}

/// Runs `case` to step `n_full` uninterrupted, to step `n_stop` (past its last checkpoint, at
/// step `n_ckpt`), then restarts the stopped run to `n_full`; both probe files must equal the
/// uninterrupted run's. Returns the largest displacement component the structure probe saw
/// (the test means something only if the structure moves).
fn restart_is_bitwise(
    case: &Path,
    overrides: &[String],
    dt: f64,
    (n_ckpt, n_stop, n_full): (u32, u32, u32),
) -> f64 {
    let scratch = Scratch::new();
    let (full, part) = (scratch.path().join("full"), scratch.path().join("part"));
    let t_full = f64::from(n_full) * dt;
    let t_stop = f64::from(n_stop) * dt;
    // Past every participant's checkpoint time (C0's fluid is half a step ahead).
    let t_past = f64::from(n_ckpt + 1) * dt;
    let run = |out: &Path, t_end: f64| {
        let args = sets(overrides, t_end);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        ok(Fsi::run(&scratch, case, out, &args), &format!("fsi run to t = {t_end:e}"));
    };
    run(&full, t_full);
    run(&part, t_stop);
    let stopped: Vec<String> = PROBE_FILES.iter().map(|f| read(&part, f)).collect();
    let id = unique_run_id("restart");
    let mut args = vec!["run".to_string(), case.display().to_string(), "--quiet".into()];
    args.extend(["--restart".into(), part.display().to_string(), "--run-id".into(), id]);
    args.extend(sets(overrides, t_full));
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    ok(Fsi::start(&scratch, &args), "fsi run --restart");
    for (file, before) in PROBE_FILES.iter().zip(&stopped) {
        let (whole, continued) = (read(&full, file), read(&part, file));
        let (t_whole, t_before) = (times(&whole), times(before));
        // The stopped run wrote rows past its last checkpoint, which the restart replaced.
        let last = *t_before.last().unwrap();
        assert!(last > t_past, "{file}: the stopped run's rows end at {last:e}");
        assert!(t_whole.len() > t_before.len(), "{file}: nothing was continued");
        if continued != whole {
            let first = whole.lines().zip(continued.lines()).position(|(a, b)| a != b);
            panic!(
                "{file}: the continued run differs from the uninterrupted one ({} and {} lines), \
                 first at line {first:?}:\n{:?}\n{:?}",
                continued.lines().count(),
                whole.lines().count(),
                first.and_then(|i| whole.lines().nth(i)),
                first.and_then(|i| continued.lines().nth(i)),
            );
        }
    }
    let structure = read(&full, PROBE_FILES[1]);
    let moved = structure.lines().skip(1).flat_map(|l| {
        l.split(',').skip(1).take(3).map(|x| x.parse::<f64>().unwrap().abs()).collect::<Vec<_>>()
    });
    moved.fold(0.0, f64::max)
}

/// The gas piston at Δt = 2^-12 s (the case's is 2e-4 s), checkpoints every 8 steps; stopped
/// after 20 steps (restart from 16), continued to 36.
fn gas_piston_restart(scheme: &str) {
    let dt = 2f64.powi(-12);
    let overrides = [
        format!("coupling.scheme=\"{scheme}\""),
        format!("coupling.dt={dt:e}"),
        "output.checkpoint_every=8".to_string(),
    ];
    let moved = restart_is_bitwise(&gas_piston(), &overrides, dt, (16, 20, 36));
    // u0 = u_s = 0.714 m: the piston's displacement from its reference.
    assert!(moved > 0.7, "the piston's displacement {moved:e}");
}

#[test]
fn gas_piston_c0_restart_continues_bitwise() {
    gas_piston_restart("C0");
}

#[test]
fn gas_piston_css_restart_continues_bitwise() {
    gas_piston_restart("CSS");
}

/// A clamped 0.2 m steel plate (MITC4, 4 x 4, 5 mm) in the plane z = 0, closing a column of air
/// at 1e5 Pa below it (x, y in [0.075, 0.125], z in [-0.305, 0.105], dz = 0.01: the plate half-way
/// between two node layers); no fluid above the plate.
fn plate_case(scheme: &str) -> String {
    let edge = |name: &str, min: [f64; 3], max: [f64; 3]| {
        format!("{name} = {{ min = {min:?}, max = {max:?} }}\n")
    };
    let bc = |set: &str| {
        format!("[[structure.bc]]\nset = \"{set}\"\nfixed = [\"ux\", \"uy\", \"uz\", \"rx\", \"ry\", \"rz\"]\n")
    };
    let (a, b, c, d) = (-1e-9, 1e-9, 0.2 - 1e-9, 0.2 + 1e-9);
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
[structure]
command = ["structure-solver"]
mesh = {{ generator = "rectangle", lx = 0.2, ly = 0.2, nx = 4, ny = 4 }}
material = {{ e = 200e9, nu = 0.3, rho = 7800.0 }}
thickness = 0.005
element = "mitc4"
wet_set = "all"
[[structure.probes]]
name = "centre"
point = [0.1, 0.1, 0.0]
[output]
fields_every = 0
checkpoint_every = 8
[structure.sets]
{}{}{}{}{}{}{}{}"#,
        edge("x0", [a, -1.0, -1.0], [b, 1.0, 1.0]),
        edge("x1", [c, -1.0, -1.0], [d, 1.0, 1.0]),
        edge("y0", [-1.0, a, -1.0], [1.0, b, 1.0]),
        edge("y1", [-1.0, c, -1.0], [1.0, d, 1.0]),
        bc("x0"),
        bc("x1"),
        bc("y0"),
        bc("y1"),
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
    let case = gas_piston();
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
