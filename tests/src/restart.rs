//! `fsi run CASE --restart DIR` checked through the real binaries: a run stopped early and
//! continued from its newest common checkpoint must write probe files equal byte for byte to an
//! uninterrupted run's (`tests/coupled_restart.rs`, `tests/python_peer.rs`).

use crate::{unique_run_id, Fsi, Scratch};
use std::path::{Path, PathBuf};
use std::time::Duration;

/// The probe files both participants write.
pub const PROBE_FILES: [&str; 2] = ["probes.csv", "structure_probes.csv"];

/// `--set` pairs for the overrides and `coupling.t_end = n dt`.
pub fn sets(overrides: &[String], t_end: f64) -> Vec<String> {
    let mut v = Vec::new();
    for o in overrides.iter().cloned().chain([format!("coupling.t_end={t_end:e}")]) {
        v.push("--set".to_string());
        v.push(o);
    }
    v
}

/// Waits up to 60 s for `fsi`; panics with its stderr unless it succeeded.
pub fn ok(fsi: Fsi, what: &str) {
    let done = fsi.wait(Duration::from_secs(60));
    assert!(done.status.success(), "{what} failed:\n{}", done.stderr);
}

/// The text of `dir/file`.
pub fn read(dir: &Path, file: &str) -> String {
    std::fs::read_to_string(dir.join(file)).unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
}

/// The times of a probe file's rows.
pub fn times(text: &str) -> Vec<f64> {
    text.lines().skip(1).map(|l| l.split(',').next().unwrap().parse().unwrap()).collect()
}

/// Runs `case` to step `n_full` uninterrupted, to step `n_stop` (past its last checkpoint, at
/// step `n_ckpt`), then restarts the stopped run to `n_full`; both probe files must equal the
/// uninterrupted run's. Returns the largest displacement component the structure probe saw
/// (the test means something only if the structure moves).
///
/// The stopped run ends at an earlier `coupling.t_end` that is not a checkpoint step, so it
/// writes rows past its last checkpoint; `dt` should be a power of two so that t^n = n Δt of
/// the shorter run is the longer run's to the bit.
pub fn restart_is_bitwise(
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

/// `cases/gas-piston`.
pub fn gas_piston_case() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../cases/gas-piston/case.toml")
}

/// [`restart_is_bitwise`] on the gas piston with `scheme` (and the `--set` overrides `extra`) at
/// Δt = 2^-12 s (the case's is 2e-4 s), checkpoints every 8 steps; stopped after 20 steps
/// (restart from 16), continued to 36. Returns the piston's largest displacement, checked to
/// move (u0 = u_s = 0.714 m from its reference).
pub fn gas_piston(scheme: &str, extra: &[String]) -> f64 {
    let dt = 2f64.powi(-12);
    let mut overrides = vec![
        format!("coupling.scheme=\"{scheme}\""),
        format!("coupling.dt={dt:e}"),
        "output.checkpoint_every=8".to_string(),
    ];
    overrides.extend_from_slice(extra);
    let moved = restart_is_bitwise(&gas_piston_case(), &overrides, dt, (16, 20, 36));
    assert!(moved > 0.7, "{scheme}: the piston's displacement {moved:e}");
    moved
}
