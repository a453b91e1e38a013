//! The Python structure participant (`coupler-scripts/python/spring-mass`, PROTOCOL §6) through
//! real processes: the spring-piston case against the closed form of the damped oscillation
//! (the tolerance of `cases.rs`), its probe history against `rigid-structure`'s on the same case
//! (the same formulas of `interface_protocol::coupling`), a SIGKILL of it mid-run, and its
//! coupled restart (`fsi run --restart`) continuing bitwise.
//!
//! Needs the venv of `coupler-scripts/python/install.sh` (`scripts/install-deps.sh` runs it).

use fsi_system_tests::restart;
use fsi_system_tests::{
    alive, python_structure, run_files, signal, Fsi, Oscillator, Probes, Scratch,
};
use interface_protocol::case::Case;
use interface_protocol::io::checkpoint::{tag_for_step, Checkpoint};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

fn spring_piston() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../cases/spring-piston/case.toml")
}

/// Runs the spring-piston case with `scheme`, the Python structure if `python`, into `out`.
fn run(scratch: &Scratch, out: &Path, scheme: &str, python: bool, extra: &[&str]) {
    let scheme_set = format!("coupling.scheme=\"{scheme}\"");
    let command = python_structure();
    let mut args = vec!["--set", scheme_set.as_str()];
    if python {
        args.extend(["--set", command.as_str()]);
    }
    args.extend(extra);
    let done = Fsi::run(scratch, &spring_piston(), out, &args).wait(Duration::from_secs(60));
    assert!(done.status.success(), "fsi run {scheme} (python: {python}) failed:\n{}", done.stderr);
}

/// The Python body follows m u'' + (c + A ρ0 c0) u' + k u = -A p0 over the case's second.
fn closed_form(scheme: &str, extra: &[&str]) {
    let case = Case::load(&spring_piston(), &[]).expect("the case parses");
    let osc = Oscillator::from_case(&case);
    let scratch = Scratch::new();
    let out = scratch.path().join("out");
    run(&scratch, &out, scheme, true, extra);
    let e = osc.max_error(&out, "piston", case.coupling.t_end);
    println!(
        "spring-piston, Python structure, {scheme}: largest error relative to A p0 / k: {e:.3e}"
    );
    // As cases.rs: the radiation damping alone takes the amplitude down by e^2 over the run.
    assert!(e < 2e-2, "{scheme}: relative error {e}");
}

#[test]
fn python_spring_mass_c0_follows_the_damped_oscillation() {
    closed_form("C0", &[]);
}

#[test]
fn python_spring_mass_a6_follows_the_damped_oscillation() {
    closed_form("A6", &[]);
}

/// CSS is first order: at the case's step 1e-3 it is off by 4.4e-2 (as rigid-structure, the
/// next test), so it runs at a quarter of it.
#[test]
fn python_spring_mass_css_follows_the_damped_oscillation() {
    closed_form("CSS", &["--set", "coupling.dt=2.5e-4"]);
}

/// Same case, same scheme: `structure_probes.csv` of the Python body equals rigid-structure's.
fn same_as_rigid(scheme: &str) {
    let scratch = Scratch::new();
    let (rust_out, py_out) = (scratch.path().join("rust"), scratch.path().join("python"));
    run(&scratch, &rust_out, scheme, false, &[]);
    run(&scratch, &py_out, scheme, true, &[]);
    let rust = Probes::read(&rust_out.join("structure_probes.csv"));
    let py = Probes::read(&py_out.join("structure_probes.csv"));
    assert_eq!(rust.columns, py.columns, "probe columns");
    assert_eq!(rust.rows.len(), py.rows.len(), "probe rows");
    let scale = rust.rows.iter().flat_map(|r| r[1..].iter()).fold(0.0f64, |m, x| m.max(x.abs()));
    let mut worst = 0.0f64;
    for (i, (a, b)) in rust.rows.iter().zip(&py.rows).enumerate() {
        assert_eq!(a[0], b[0], "{scheme}: time of row {i}");
        for (x, y) in a[1..].iter().zip(&b[1..]) {
            worst = worst.max((x - y).abs() / scale);
        }
    }
    println!(
        "{scheme}: {} rows, largest difference relative to max |value|: {worst:.3e}",
        py.rows.len()
    );
    assert!(worst <= 1e-12, "{scheme}: Python and Rust probes differ by {worst:e} (relative)");
}

#[test]
fn python_spring_mass_c0_matches_rigid_structure() {
    same_as_rigid("C0");
}

#[test]
fn python_spring_mass_a6_matches_rigid_structure() {
    same_as_rigid("A6");
}

#[test]
fn python_spring_mass_css_matches_rigid_structure() {
    same_as_rigid("CSS");
}

/// SIGKILL of the Python structure mid-run: fsi fails within 2 s naming the structure, the fluid
/// is gone and no file of the run remains.
#[test]
fn killing_the_python_structure_stops_the_run() {
    let scratch = Scratch::new();
    let out = scratch.path().join("out");
    let command = python_structure();
    let set = [
        "--set",
        "coupling.t_end=1e3",
        "--set",
        "coupling.dt=1e-5",
        "--set",
        "coupling.timeout_s=2",
        "--set",
        command.as_str(),
    ];
    let fsi = Fsi::run(&scratch, &spring_piston(), &out, &set);
    let run_id = fsi.run_id.clone();
    let deadline = Instant::now() + Duration::from_secs(20);
    let probes = out.join("structure_probes.csv");
    while std::fs::read_to_string(&probes).map_or(0, |t| t.lines().count()) < 3 {
        assert!(Instant::now() < deadline, "the run did not start stepping within 20 s");
        std::thread::sleep(Duration::from_millis(10));
    }
    let kids = fsi.participants(Duration::from_secs(2));
    assert_eq!(kids.len(), 2, "participants of fsi: {kids:?}");
    let fluid = kids.iter().find(|k| k.1.starts_with("piston-fluid")).expect("the fluid").0;
    let python = kids.iter().find(|k| k.0 != fluid).expect("the Python structure").0;
    let killed = Instant::now();
    signal(python, libc::SIGKILL);
    let done = fsi.wait(Duration::from_secs(10));
    let after = killed.elapsed();
    println!("Python structure killed: fsi exited {after:?} later: {}", done.stderr.trim());
    assert!(!done.status.success(), "fsi succeeded:\n{}", done.stderr);
    assert!(after < Duration::from_secs(2), "fsi took {after:?} to exit after the kill");
    for w in ["structure", "SIGKILL"] {
        assert!(done.stderr.contains(w), "the error does not name `{w}`:\n{}", done.stderr);
    }
    assert!(!alive(fluid), "piston-fluid (pid {fluid}) is still running");
    let left = run_files(&run_id);
    assert!(left.is_empty(), "files of run {run_id} remain: {left:?}");
}

/// The gas piston (`cases/gas-piston`, `fluid-solver`) with the Python structure, stopped and
/// restarted as `coupled_restart.rs` does with `rigid-structure` (`restart::gas_piston`): both
/// probe files equal the uninterrupted run's byte for byte. The spring-piston case cannot restart: its `piston-fluid` does not
/// announce the capability.
fn python_restart(scheme: &str) {
    let moved = restart::gas_piston(scheme, &[python_structure()]);
    println!("gas piston, Python structure, {scheme}: restart bitwise, |u| up to {moved:e} m");
}

#[test]
fn python_spring_mass_c0_restart_continues_bitwise() {
    python_restart("C0");
}

#[test]
fn python_spring_mass_a6_restart_continues_bitwise() {
    python_restart("A6");
}

#[test]
fn python_spring_mass_css_restart_continues_bitwise() {
    python_restart("CSS");
}

/// The Python structure's part is an `io::checkpoint` file with `rigid-structure`'s content, and
/// one it cannot continue from is refused before the run, naming the file and the array.
#[test]
fn the_python_checkpoint_is_a_checkpoint_part_and_a_bad_one_is_named() {
    let scratch = Scratch::new();
    let out = scratch.path().join("out");
    let command = python_structure();
    let set = ["--set", "coupling.t_end=8e-3", "--set", "output.checkpoint_every=4"];
    let done =
        Fsi::run(&scratch, &spring_piston(), &out, &[&set[..], &["--set", &command]].concat())
            .wait(Duration::from_secs(60));
    assert!(done.status.success(), "fsi run failed:\n{}", done.stderr);
    let tag = out.join("checkpoints").join(tag_for_step(8));
    let ck = Checkpoint::read_file(&tag.join("structure.ckpt")).expect("a checkpoint part");
    assert_eq!(ck.step, 8);
    assert!((ck.time - 8e-3).abs() < 1e-15, "checkpoint time {:e}", ck.time);
    let dofs: Vec<String> = ck.meta().expect("the DOF names");
    assert_eq!(dofs, ["x"]);
    let mut names: Vec<&str> = ck.names().collect();
    names.sort_unstable();
    let history = ["a_hat", "f_applied", "f_half", "f_prev", "times", "v_half_prev", "work"];
    let mut want: Vec<String> = ["a", "u", "v", "v_half"].map(String::from).to_vec();
    want.extend(history.map(|h| format!("coupling.{h}")));
    want.sort_unstable();
    assert_eq!(names, want);
    // The same part without the ledger's work.
    let bad = scratch.path().join("bad");
    let mut broken = Checkpoint::new(ck.step, ck.time);
    broken.set_meta(&dofs).unwrap();
    for name in ck.names().filter(|n| *n != "coupling.work") {
        broken.put(name, ck.f64(name).unwrap().to_vec()).unwrap();
    }
    broken
        .write_file(&{
            std::fs::create_dir_all(&bad).unwrap();
            bad.join("structure.ckpt")
        })
        .unwrap();
    let wrapper = command.split('"').nth(1).unwrap().to_string();
    let run = std::process::Command::new(wrapper)
        .args(["run", spring_piston().to_str().unwrap(), "--couple", "nobody"])
        .args(["--out", out.to_str().unwrap(), "--restart", bad.to_str().unwrap()])
        .output()
        .expect("spring-mass runs");
    let e = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success(), "a restart from {} succeeded", bad.display());
    assert!(e.contains("bad/structure.ckpt") && e.contains("`coupling.work`"), "{e}");
}

/// The energy ledger (`Staggered::interface_work`, reported in every reply): on the gas piston
/// the structure's work in `run.json` of the Python body equals `rigid-structure`'s to the bit,
/// for the three schemes (the fluid's work too: the same kinematics reached it).
#[test]
fn python_interface_work_equals_rigid_structures() {
    let scratch = Scratch::new();
    let case = restart::gas_piston_case();
    let command = python_structure();
    for scheme in ["C0", "A6", "CSS"] {
        let energy = |python: bool| {
            let out = scratch.path().join(format!("{scheme}-{python}"));
            let scheme_set = format!("coupling.scheme=\"{scheme}\"");
            let mut args = vec!["--set", scheme_set.as_str(), "--set", "coupling.t_end=4e-3"];
            if python {
                args.extend(["--set", command.as_str()]);
            }
            let done = Fsi::run(&scratch, &case, &out, &args).wait(Duration::from_secs(60));
            assert!(done.status.success(), "fsi run {scheme} failed:\n{}", done.stderr);
            let run: serde_json::Value =
                serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).unwrap())
                    .unwrap();
            let e = &run["interface_energy"];
            let work = |k: &str| e[k].as_f64().unwrap_or_else(|| panic!("{scheme}: {k} in {e}"));
            (work("structure_work"), work("fluid_work"))
        };
        let (rust, python) = (energy(false), energy(true));
        println!("{scheme}: structure work {:e} J (rigid-structure {:e} J)", python.0, rust.0);
        assert!(rust.0 > 0.0, "{scheme}: the structure's work {:e}", rust.0);
        assert_eq!(python.0.to_bits(), rust.0.to_bits(), "{scheme}: structure work");
        assert_eq!(python.1.to_bits(), rust.1.to_bits(), "{scheme}: fluid work");
    }
}
