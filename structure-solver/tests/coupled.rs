//! `structure-solver` coupled through `fsi run` to `piston-fluid`: a clamped MITC4 plate whose
//! faces carry the acoustic-column load F = -A (p0 + ρ0 c0 v̄·n) n / N per wet node (v̄ the mean
//! wet-node velocity). The centre deflection history converges with the coupling step at each
//! scheme's order against a run at a step eight times finer (DESIGN §4).
//!
//! Build the binaries first:
//! `cargo build --release -p coupler-scripts -p fsi-system-tests -p structure-solver --bins`.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::atomic::{AtomicU32, Ordering};
use std::time::{Duration, Instant};

/// Coupled span: about one period of the plate's fundamental mode.
const T_END: f64 = 1e-3;

/// `target/<profile>/<name>`, or a panic naming the build command.
fn bin(name: &str) -> PathBuf {
    let profile = if cfg!(debug_assertions) { "debug" } else { "release" };
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join("target"));
    let p = target.join(profile).join(name);
    assert!(
        p.is_file(),
        "{} is missing: run `cargo build{} -p coupler-scripts -p fsi-system-tests -p structure-solver --bins`",
        p.display(),
        if cfg!(debug_assertions) { "" } else { " --release" }
    );
    p
}

/// The clamped plate (`clamped_plate.toml`, shared with `tests/tests/coupled_restart.rs`).
const PLATE: &str = include_str!("clamped_plate.toml");

/// The plate case: the clamped plate under a water column.
fn case(scheme: &str, dt: f64) -> String {
    format!(
        r#"[case]
name = "plate"
[coupling]
scheme = "{scheme}"
dt = {dt:e}
t_end = {T_END:e}
timeout_s = 10
[fluid]
command = ["piston-fluid"]
[fluid.piston]
area = 0.04
p0 = 1e4
rho0 = 1000.0
c0 = 1500.0
normal = [0.0, 0.0, 1.0]
{PLATE}"#
    )
}

/// Runs `fsi run` on the plate (with `extra` arguments) and returns its output folder and the
/// centre deflection `(t, uz)` rows.
fn run_with(dir: &Path, scheme: &str, dt: f64, extra: &[&str]) -> (PathBuf, Vec<(f64, f64)>) {
    static NEXT: AtomicU32 = AtomicU32::new(0);
    let n = NEXT.fetch_add(1, Ordering::SeqCst);
    let tag = format!("{scheme}-{n}");
    let case_path = dir.join(format!("{tag}.toml"));
    std::fs::write(&case_path, case(scheme, dt)).unwrap();
    let out = dir.join(format!("out-{tag}"));
    let run_id = format!("t{:x}-plate-{tag}", std::process::id());
    let mut child = Command::new(bin("fsi"))
        .args(["run", case_path.to_str().unwrap(), "--out", out.to_str().unwrap(), "--quiet"])
        .args(["--run-id", &run_id])
        .args(extra)
        .stdout(std::process::Stdio::null())
        .stderr(std::fs::File::create(dir.join(format!("{tag}.err"))).unwrap())
        .spawn()
        .expect("start fsi");
    let deadline = Instant::now() + Duration::from_secs(30);
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if Instant::now() > deadline {
            let _ = child.kill();
            let _ = child.wait();
            panic!("fsi run {scheme} dt {dt} did not finish in 30 s");
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let err = std::fs::read_to_string(dir.join(format!("{tag}.err"))).unwrap_or_default();
    assert!(status.success(), "fsi run {scheme} dt {dt} failed:\n{err}");
    let text = std::fs::read_to_string(out.join("structure_probes.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = header.iter().position(|c| *c == "centre.uz").expect("a centre.uz column");
    let rows: Vec<(f64, f64)> = lines
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            (v[0], v[col])
        })
        .collect();
    let last = rows.last().unwrap().0;
    assert!((last - T_END).abs() < 1e-12, "{scheme} dt {dt}: the run ended at {last}");
    assert_eq!(rows.len(), (T_END / dt).round() as usize + 1, "{scheme} dt {dt}: probe rows");
    (out, rows)
}

/// The centre deflection history of a plain run.
fn run(dir: &Path, scheme: &str, dt: f64) -> Vec<(f64, f64)> {
    run_with(dir, scheme, dt, &[]).1
}

/// Largest deflection difference at the coarse run's times, relative to the largest reference
/// deflection.
fn error(coarse: &[(f64, f64)], fine: &[(f64, f64)], ratio: usize) -> f64 {
    let scale = fine.iter().map(|r| r.1.abs()).fold(0.0, f64::max);
    coarse
        .iter()
        .enumerate()
        .map(|(i, &(t, u))| {
            let (tf, uf) = fine[i * ratio];
            assert!((t - tf).abs() < 1e-12, "times {t} and {tf} differ");
            (u - uf).abs()
        })
        .fold(0.0, f64::max)
        / scale
}

/// Errors at `dts` (each half the previous) against a run at `dts[2] / 8`; returns the orders.
fn orders(scheme: &str, dts: [f64; 3]) -> (Vec<f64>, Vec<f64>) {
    orders_with(scheme, dts, &[])
}

/// [`orders`] with `extra` arguments to every run.
fn orders_with(scheme: &str, dts: [f64; 3], extra: &[&str]) -> (Vec<f64>, Vec<f64>) {
    let dir = tempfile::tempdir().unwrap();
    let run = |dt: f64| run_with(dir.path(), scheme, dt, extra).1;
    let reference = run(dts[2] / 8.0);
    let e: Vec<f64> =
        dts.iter().enumerate().map(|(k, &dt)| error(&run(dt), &reference, 8 << (2 - k))).collect();
    let p: Vec<f64> = e.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
    println!("{scheme} {extra:?}: dt {dts:?} relative errors {e:?} observed orders {p:.3?}");
    (e, p)
}

#[test]
fn c0_plate_converges_at_second_order() {
    let (e, p) = orders("C0", [4e-6, 2e-6, 1e-6]);
    assert!(p.iter().all(|&p| (1.8..2.6).contains(&p)), "C0 errors {e:?}, orders {p:?}");
}

/// Four structure substeps in every coupling step (the first three and the last drift at
/// PREDICT, with the load extrapolated from F^{n-1/2} and F^{n+1/2}; `coupling::Staggered`)
/// keep C0 second order, and CSS first order.
#[test]
fn subcycled_plate_keeps_the_scheme_orders() {
    let four = ["--set", "structure.substeps=4"];
    let (e, p) = orders_with("C0", [4e-6, 2e-6, 1e-6], &four);
    assert!(p.iter().all(|&p| (1.8..2.6).contains(&p)), "C0 errors {e:?}, orders {p:?}");
    let (e, p) = orders_with("CSS", [4e-6, 2e-6, 1e-6], &four);
    assert!(p.iter().all(|&p| (0.7..1.4).contains(&p)), "CSS errors {e:?}, orders {p:?}");
}

#[test]
fn a6_plate_converges_at_second_order() {
    let (e, p) = orders("A6", [4e-6, 2e-6, 1e-6]);
    assert!(p.iter().all(|&p| (1.8..2.6).contains(&p)), "A6 errors {e:?}, orders {p:?}");
}

#[test]
fn css_plate_converges_at_first_order() {
    let (e, p) = orders("CSS", [4e-6, 2e-6, 1e-6]);
    assert!(p.iter().all(|&p| (0.7..1.4).contains(&p)), "CSS errors {e:?}, orders {p:?}");
}

/// Reads `structure.xdmf` with meshio: points, cell counts per type, and per step the time and
/// the displacement and velocity of node `node`.
const MESHIO: &str = r#"
import json, sys, meshio
out = {"steps": []}
with meshio.xdmf.TimeSeriesReader(sys.argv[1]) as r:
    points, cells = r.read_points_cells()
    out["n_points"] = len(points)
    out["cells"] = {c.type: len(c.data) for c in cells}
    for k in range(r.num_steps):
        t, pd, _ = r.read_data(k)
        n = int(sys.argv[2])
        out["steps"].append([float(t)] + [float(x) for x in pd["displacement"][n]] + [float(x) for x in pd["velocity"][n]])
print(json.dumps(out))
"#;

#[test]
fn field_series_opens_in_meshio_and_matches_the_probes() {
    let probe = Command::new("python3").args(["-c", "import meshio, h5py"]).output();
    assert!(
        probe.is_ok_and(|o| o.status.success()),
        "python3 with meshio and h5py is needed to read structure.xdmf: run scripts/install-deps.sh"
    );
    let dir = tempfile::tempdir().unwrap();
    let (out, rows) = run_with(dir.path(), "C0", 4e-6, &["--set", "output.fields_every=50"]);
    // Node 12 is the centre of the 5 x 5 grid.
    let o = Command::new("python3")
        .args(["-c", MESHIO, out.join("structure.xdmf").to_str().unwrap(), "12"])
        .output()
        .unwrap();
    assert!(o.status.success(), "meshio failed:\n{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["n_points"], 25);
    assert_eq!(v["cells"]["quad"], 16);
    let steps = v["steps"].as_array().unwrap();
    assert_eq!(steps.len(), 6, "t = 0 and every 50 of 250 steps");
    for (k, s) in steps.iter().enumerate() {
        let s: Vec<f64> = s.as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
        let (t, uz) = rows[50 * k];
        assert!((s[0] - t).abs() < 1e-15, "step {k}: time {} vs probe {t}", s[0]);
        assert_eq!(s[3], uz, "step {k}: centre uz in structure.xdmf vs structure_probes.csv");
    }
    assert!(rows[250].1 < -1e-6, "the plate must deflect away from the water");
}

/// The largest cell values of the last step of `structure.xdmf`, read by meshio.
const CELL_FIELDS: &str = r#"
import json, sys, meshio
with meshio.xdmf.TimeSeriesReader(sys.argv[1]) as r:
    r.read_points_cells()
    t, _, cd = r.read_data(r.num_steps - 1)
print(json.dumps({k: float(max(v[0])) for k, v in cd.items()}))
"#;

/// The cantilever plate alone: BT4 with J2 (yields under the tip load) by central differences,
/// elastic MITC4 or J2 MITC4 (`shell`, yields too) by the implicit midpoint rule; a checkpoint
/// every 300 steps.
fn cantilever(element: &str) -> String {
    let (material, integrator) = match element {
        "bt4" => ("sigma_y = 20e6, hardening = 1e9", "central_difference"),
        "shell" => ("sigma_y = 20e6, hardening = 1e9", "midpoint"),
        _ => ("nu = 0.3", "midpoint"),
    };
    let nu = if element == "mitc4" { "" } else { "nu = 0.3, " };
    format!(
        r#"[case]
name = "cantilever"
[structure]
mesh = {{ generator = "rectangle", lx = 1.0, ly = 0.1, nx = 8, ny = 2 }}
material = {{ e = 200e9, {nu}rho = 7800.0, {material} }}
thickness = 0.02
element = "{element}"
integrator = "{integrator}"
dt = 2e-6
t_end = 2e-3
[structure.sets]
clamp = {{ min = [-1e-9, -1.0, -1.0], max = [1e-9, 1.0, 1.0] }}
tip = {{ min = [0.999999, -1.0, -1.0], max = [1.000001, 1.0, 1.0] }}
[[structure.bc]]
set = "clamp"
fixed = ["ux", "uy", "uz", "rx", "ry", "rz"]
[[structure.loads]]
set = "tip"
dof = "uz"
value = 2000.0
[[structure.probes]]
name = "tip"
point = [1.0, 0.0, 0.0]
[output]
checkpoint_every = 300
"#
    )
}

/// `structure-solver run` with `args`; panics with its stderr on failure.
fn structure_solver(args: &[&str]) {
    let o = Command::new(bin("structure-solver")).arg("run").args(args).output().unwrap();
    assert!(
        o.status.success(),
        "structure-solver {args:?}:\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
}

#[test]
fn restart_from_the_newest_checkpoint_reproduces_the_run_exactly() {
    use interface_protocol::io::checkpoint::Checkpoint;
    for element in ["bt4", "mitc4", "shell"] {
        let dir = tempfile::tempdir().unwrap();
        let case = dir.path().join("cantilever.toml");
        std::fs::write(&case, cantilever(element)).unwrap();
        let (a, b) = (dir.path().join("a"), dir.path().join("b"));
        let c = case.to_str().unwrap();
        structure_solver(&[c, "--out", a.to_str().unwrap(), "--quiet"]);
        structure_solver(&[
            c,
            "--out",
            b.to_str().unwrap(),
            "--restart",
            a.to_str().unwrap(),
            "--quiet",
        ]);
        let read = |p: &Path| std::fs::read_to_string(p.join("structure_probes.csv")).unwrap();
        let (full, resumed) = (read(&a), read(&b));
        let full: Vec<&str> = full.lines().collect();
        let resumed: Vec<&str> = resumed.lines().collect();
        // 1000 steps, the newest checkpoint at step 900: header + rows 900..=1000.
        assert_eq!(resumed.len(), 1 + 101, "{element}: rows after the restart");
        assert_eq!(resumed[1..], full[full.len() - 101..], "{element}: restarted history");
        let tag = interface_protocol::io::checkpoint::tag_for_step(900);
        let ck = Checkpoint::read(&a.join("checkpoints"), &tag, "structure").unwrap();
        assert_eq!(ck.step, 900);
        assert!((ck.time - 900.0 * 2e-6).abs() < 1e-15, "{element}: time {}", ck.time);
        if element == "bt4" {
            let ep = ck.f64("bt4.plastic_strain").unwrap();
            assert!(ep.iter().cloned().fold(0.0, f64::max) > 0.0, "the plate must have yielded");
            // The cell fields as meshio reads them: yielded shells sit on the hardening line
            // σ_vm = σy + H εp (σy = 20 MPa, H = 1 GPa).
            let o = Command::new("python3")
                .args(["-c", CELL_FIELDS, a.join("structure.xdmf").to_str().unwrap()])
                .output()
                .unwrap();
            assert!(o.status.success(), "meshio failed:\n{}", String::from_utf8_lossy(&o.stderr));
            let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
            let (vm, ep) =
                (v["von_mises"].as_f64().unwrap(), v["plastic_strain"].as_f64().unwrap());
            assert!(ep > 0.0, "plastic strain in structure.xdmf: {ep}");
            assert!(vm >= 0.999 * 20e6 && vm <= 1.001 * (20e6 + 1e9 * ep), "σ_vm {vm}, εp {ep}");
        } else {
            assert_eq!(ck.f64("rotations").unwrap().len(), 9 * 27);
            let ep = ck.f64("material").unwrap();
            let yielded = ep.iter().any(|&v| v != 0.0);
            assert_eq!(yielded, element == "shell", "{element}: J2 state {}", ep.len());
        }
    }
}

#[test]
fn coupled_run_writes_checkpoints_and_stops_on_unstable_steps() {
    let dir = tempfile::tempdir().unwrap();
    let (out, rows) = run_with(dir.path(), "A6", 4e-6, &["--set", "output.checkpoint_every=100"]);
    let ck = checkpoint_at(&out.join("checkpoints"), 200);
    assert!((ck.time - 200.0 * 4e-6).abs() < 1e-15);
    // The centre (0.1, 0.1) is at z = 0 unloaded: its checkpointed z is the probed deflection.
    // Checkpoints hold the model's storage order (the renumbered mesh): find it by position.
    let x = ck.f64("x").unwrap();
    let d = |p: &[f64]| (p[0] - 0.1).hypot(p[1] - 0.1);
    let centre = x.chunks_exact(3).min_by(|a, b| d(a).total_cmp(&d(b))).unwrap();
    assert!(d(centre) < 1e-6, "the centre moves in its plane by {:e}", d(centre));
    let uz = centre[2];
    assert_eq!(uz, rows[200].1);
    // C0 integrates with central differences: with one substep fixed, a step past their
    // stability limit is refused; by default the structure subcycles within it.
    let one = case("C0", 1e-4).replace("[structure]\n", "[structure]\nsubsteps = 1\n");
    let (o, err) = fsi_fails(dir.path(), "big", &one);
    assert!(!o.status.success());
    assert!(err.contains("exceeds the stable step"), "{err}");
    let fine = run(dir.path(), "C0", 1e-6);
    let subcycled = run(dir.path(), "C0", 2e-5);
    let e = error(&subcycled, &fine, 20);
    assert!(e < 0.05, "C0 at 2e-5 s, subcycled: relative error {e:e}");
    // A column 1e5 times stiffer than water makes the explicit coupling diverge: the run stops
    // at the first non-finite value, naming the field, node and time.
    let (o, err) =
        fsi_fails(dir.path(), "stiff", &case("C0", 2e-6).replace("rho0 = 1000.0", "rho0 = 1e8"));
    println!("{err}");
    assert!(!o.status.success());
    assert!(
        err.contains("non-finite value") && err.contains("at node") && err.contains("t = "),
        "{err}"
    );
    // the structure's own every-step check names the node and dof
    assert!(err.contains(" dof ") && err.contains("the structure diverged"), "{err}");
}

/// The structure's checkpoint at `step` among the tag folders of `dir` (the launcher names
/// them; the name is not assumed here).
fn checkpoint_at(dir: &Path, step: u64) -> interface_protocol::io::checkpoint::Checkpoint {
    use interface_protocol::io::checkpoint::Checkpoint;
    std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| Checkpoint::read_file(&e.unwrap().path().join("structure.ckpt")).ok())
        .find(|ck| ck.step == step)
        .unwrap_or_else(|| panic!("no structure checkpoint at step {step} in {}", dir.display()))
}

/// Runs `fsi run` on case text that must fail; returns the output and its stderr.
fn fsi_fails(dir: &Path, tag: &str, text: &str) -> (std::process::Output, String) {
    let case_path = dir.join(format!("{tag}.toml"));
    std::fs::write(&case_path, text).unwrap();
    let o = Command::new(bin("fsi"))
        .args(["run", case_path.to_str().unwrap(), "--quiet", "--out"])
        .arg(dir.join(tag))
        .args(["--run-id", &format!("t{:x}-plate-{tag}", std::process::id())])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    (o, err)
}
