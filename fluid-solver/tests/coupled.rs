//! `fluid-solver run --couple`: the fluid as a protocol participant. Coupled to a structure
//! without a wet surface, it advances the fluid over the coupling steps exactly as the
//! stand-alone stepper does with the same targets; a wet surface it cannot track is answered
//! `Failed` naming the element or node. (`cases/shell-water-air`, `tests/shell_water_air.rs`,
//! couples a wet surface through `fsi`.)
//!
//! `rigid-structure` requires at least one wet node and checks its own states, so the structure
//! here is played by the test itself, which is also the launcher. Build the binaries first:
//! `cargo build --release -p coupler-scripts -p rigid-structure -p fluid-solver --bins`.

mod common;

use common::lines::rows;

use common::ExactTube;
use fluid_solver::eos::Eos;
use fluid_solver::solver::{FluidRun, Mode, RunOptions};
use interface_protocol::case::Case;
use interface_protocol::endpoint::{LauncherLink, StructureEndpoint, Timeouts};
use interface_protocol::handshake::HelloInfo;
use interface_protocol::io::checkpoint::{tag_for_step, Checkpoint};
use interface_protocol::liveness::LAUNCHER_PID_ENV;
use interface_protocol::messages::{
    reply_kind, scheme_phase, Command, NodeLoad, NodeState, Reply, Role, StepHeader, SurfaceElement,
};
use interface_protocol::participant::failure_code;
use std::path::{Path, PathBuf};
use std::process::{Command as Process, Stdio};
use std::time::{Duration, Instant};

/// Sod's tube (`cases/sod-tube`, 50 cells, to t = 0.1) coupled with CSS in four steps.
const FLUID: &str = r#"
[case]
name = "sod-coupled"

[coupling]
scheme = "CSS"
dt = 0.025
t_end = 0.1
timeout_s = 10.0

[fluid]
command = ["fluid-solver"]
eos = { kind = "perfect_gas", gamma = 1.4 }
probes = [
  { name = "left", at = [0.2, 0.0, 0.0] },
  { name = "right", at = [0.8, 0.0, 0.0] },
]
lines = [{ name = "axis", from = [0.0, 0.0, 0.0], to = [1.0, 0.0, 0.0], points = 51, times = [0.05] }]

[fluid.mesh]
box = { lo = [0.0, 0.0, 0.0], hi = [1.0, 0.02, 0.02], cells = [50, 1, 1], shape = "tet" }

[fluid.initial]
state = [1.0, 0.0, 0.0, 0.0, 1.0]
regions = [
  { region = { shape = "half_space", point = [0.3, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }, state = [0.125, 0.0, 0.0, 0.0, 0.1] },
]

[fluid.boundary]
xmin = { kind = "far_field", state = [1.0, 0.0, 0.0, 0.0, 1.0] }
xmax = { kind = "far_field", state = [0.125, 0.0, 0.0, 0.0, 0.1] }
ymin = { kind = "symmetry" }
ymax = { kind = "symmetry" }
zmin = { kind = "symmetry" }
zmax = { kind = "symmetry" }

[fluid.numerics]
flux = "roe"
limiter = "van_albada"
cfl = 0.9

[fluid.time]
t_end = 0.1

[output]
fields_every = 10
probes_every = 1
"#;

/// The coupling times t^n of `FLUID`.
const TIMES: [f64; 5] = [0.0, 0.025, 0.05, 0.075, 0.1];

fn write_case(dir: &Path, text: &str) -> PathBuf {
    let path = dir.join("case.toml");
    std::fs::write(&path, text).unwrap();
    path
}

/// A run id no other test uses.
fn run_id(tag: &str) -> String {
    format!("fs{:x}-{tag}", std::process::id())
}

/// The workspace binary `name`, next to `fluid-solver` in `target/<profile>`.
fn bin(name: &str) -> PathBuf {
    let p = Path::new(env!("CARGO_BIN_EXE_fluid-solver")).with_file_name(name);
    assert!(
        p.is_file(),
        "{} is missing: build first with `cargo build{} -p coupler-scripts -p rigid-structure -p \
         fluid-solver --bins`",
        p.display(),
        if cfg!(debug_assertions) { "" } else { " --release" }
    );
    p
}

fn expect_reply(link: &mut LauncherLink, command: &Command, kind: u32) -> Reply {
    link.send(Role::Fluid, command).unwrap();
    let reply = link.wait_reply(Role::Fluid, Instant::now() + Duration::from_secs(10)).unwrap();
    assert_eq!(
        reply.kind,
        kind,
        "{} answered with kind {} (code {}): {}",
        command.describe(),
        reply.kind,
        reply.code,
        reply.message_str()
    );
    reply
}

fn header(step: u64, time: f64) -> StepHeader {
    StepHeader { step, time, dt: 0.025, topology_version: 1, count: 0 }
}

fn assert_same_rows(a: &Path, b: &Path) {
    let (ra, rb) = (rows(a), rows(b));
    assert_eq!(ra.len(), rb.len(), "{} vs {}", a.display(), b.display());
    for (x, y) in ra.iter().flatten().zip(rb.iter().flatten()) {
        // A line's `phi` column is NaN in a run without a level set.
        let same = (x - y).abs() <= 1e-12 * x.abs().max(y.abs()) || (x.is_nan() && y.is_nan());
        assert!(same, "{}: {x} vs {y}", a.display());
    }
}

/// `fluid-solver run --couple` on `case_path`, writing into `out`, with the launcher and a
/// structure without a wet surface played here, after the handshake.
fn start_coupled(
    case_path: &Path,
    case: &Case,
    out: &Path,
    tag: &str,
) -> (LauncherLink, std::process::Child, StructureEndpoint) {
    let id = run_id(tag);
    let timeouts = Timeouts::from_secs(10.0);
    let mut link = LauncherLink::open(&id, timeouts).unwrap();
    let fluid = Process::new(bin("fluid-solver"))
        .arg("run")
        .arg(case_path)
        .args(["--couple", &id, "--quiet", "--out"])
        .arg(out)
        .env(LAUNCHER_PID_ENV, std::process::id().to_string())
        .stdin(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let info = HelloInfo {
        n_surface_nodes: 0,
        n_surface_elements: 0,
        case_hash: case.hash(),
        capabilities: 0,
    };
    let structure = StructureEndpoint::open(&id, info, timeouts).unwrap();
    let soon = Instant::now() + Duration::from_secs(10);
    let f = link.wait_hello(Role::Fluid, soon).unwrap();
    let s = link.wait_hello(Role::Structure, soon).unwrap();
    assert_eq!((f.n_surface_nodes, f.n_surface_elements), (0, 0), "the fluid accepts any count");
    LauncherLink::check(&f, &s, case.hash()).unwrap();
    (link, fluid, structure)
}

#[test]
fn a_coupled_run_without_wet_surface_steps_like_the_fluid_alone() {
    let dir = tempfile::tempdir().unwrap();
    let case_path = write_case(dir.path(), FLUID);
    let case = Case::load(&case_path, &[]).unwrap();
    let coupled = dir.path().join("coupled");
    std::fs::create_dir(&coupled).unwrap();
    let (mut link, fluid, mut structure) = start_coupled(&case_path, &case, &coupled, "empty");

    structure.publish_topology(header(0, 0.0), 0, |_| ()).unwrap();
    structure.publish_kinematics(header(0, 0.0), 0, |_| ()).unwrap();
    let ready = expect_reply(&mut link, &Command::init(), reply_kind::READY);
    assert_eq!(ready.dt_stable, f64::INFINITY);
    let (t0, n0) = structure.read_loads(|h, loads| (h.time, loads.len())).unwrap();
    assert_eq!((t0, n0), (0.0, 0));
    for (n, w) in TIMES.windows(2).enumerate() {
        let n = n as u64;
        structure.publish_kinematics(header(n, w[1]), 0, |_| ()).unwrap();
        let command = Command::advance(n, w[0], w[1], scheme_phase::NONE);
        let done = expect_reply(&mut link, &command, reply_kind::DONE);
        assert_eq!((done.step, done.t), (n, w[1]));
        let (t, count) = structure.read_loads(|h, loads| (h.time, loads.len())).unwrap();
        assert_eq!((t, count), (w[1], 0), "the loads at t_to on no wet node");
        if n == 1 {
            expect_reply(&mut link, &Command::checkpoint(&tag_for_step(2)), reply_kind::DONE);
        }
    }
    // A command that does not start where the fluid stands is refused; the fluid carries on.
    structure.publish_kinematics(header(4, 0.2), 0, |_| ()).unwrap();
    let command = Command::advance(4, 0.15, 0.2, scheme_phase::NONE);
    let failed = expect_reply(&mut link, &command, reply_kind::FAILED);
    assert_eq!(failed.code, failure_code::PROTOCOL);
    assert!(
        failed.message_str().contains("starts at t = 1.5e-1, but the fluid is at t = "),
        "{}",
        failed.message_str()
    );
    expect_reply(&mut link, &Command::finish(), reply_kind::DONE);
    let out = fluid.wait_with_output().unwrap();
    assert!(out.status.success(), "fluid-solver: {}", String::from_utf8_lossy(&out.stderr));
    drop(structure);
    link.remove_resources().unwrap();

    // The checkpoint the launcher asked for holds the fluid at t^2.
    let ck = Checkpoint::read(&coupled.join("checkpoints"), &tag_for_step(2), "fluid").unwrap();
    assert_eq!(ck.time, TIMES[2]);
    for f in ["fluid.h5", "fluid.xdmf", "probes.csv", "lines/axis.csv"] {
        assert!(coupled.join(f).is_file(), "{f} missing");
    }
    // The line at t = 0.05 and the final one.
    assert_eq!(std::fs::read_dir(coupled.join("lines")).unwrap().count(), 2);
    assert!(!coupled.join("run.json").exists(), "run.json is the launcher's");

    // The stand-alone stepper driven to the same targets gives the same probes and lines.
    let alone = dir.path().join("alone");
    let text = std::fs::read_to_string(&case_path).unwrap();
    let opts = RunOptions { out: alone.clone(), quiet: true, restart: None, force: false };
    let mut run = FluidRun::open(&case, &text, &opts, Mode::Alone).unwrap();
    for &t in &TIMES[1..] {
        let reached = run.advance_to(t).unwrap().t;
        assert!((reached - t).abs() <= 1e-12 * t, "{reached} for {t}");
    }
    let summary = run.finish().unwrap();
    assert!(summary.steps > 4 * 4, "subcycling: {} fluid steps", summary.steps);
    assert_same_rows(&coupled.join("probes.csv"), &alone.join("probes.csv"));
    assert_eq!(rows(&coupled.join("probes.csv")).len() as u64, summary.steps + 1);
    assert_same_rows(&coupled.join("lines/axis.csv"), &alone.join("lines/axis.csv"));

    // And it is Sod's solution at t = 0.1.
    let exact = ExactTube::new(
        Eos::PerfectGas { gamma: 1.4 },
        [1.0, 0.0, 0.0, 0.0, 1.0],
        [0.125, 0.0, 0.0, 0.0, 0.1],
        0.3,
        0.1,
    );
    let line = rows(&coupled.join("lines/axis.csv"));
    let err =
        line.iter().map(|v| (v[4] - exact.at(v[0])[0]).abs()).sum::<f64>() / line.len() as f64;
    assert!(err < 0.02, "mean density error along the line {err}");
}

/// A wet surface the fluid cannot track is answered `Failed` naming what is wrong, never a panic:
/// wet nodes without elements and a degenerate element at `Init`; and, after a good step with a
/// plate across the tube (its loads one per wet node, finite) and one with a new topology that adds
/// a node (loads one per node of the new topology), a non-finite position, naming the node.
#[test]
fn an_untrackable_wet_surface_is_answered_failed_naming_element_or_node() {
    let dir = tempfile::tempdir().unwrap();
    let case_path = write_case(dir.path(), FLUID);
    let case = Case::load(&case_path, &[]).unwrap();
    let plate = |x: f64| {
        [[x, -0.1, -0.1], [x, 0.1, -0.1], [x, 0.1, 0.1], [x, -0.1, 0.1]]
            .map(|x| NodeState { x, v: [0.0; 3] })
    };
    let quad =
        SurfaceElement { nodes: [0, 1, 2, 3], n_nodes: 4, phi: [1.0; 4], ..Default::default() };
    let init_failure = |tag: &str, elements: Vec<SurfaceElement>, nodes: Vec<NodeState>| {
        let out = dir.path().join(tag);
        std::fs::create_dir(&out).unwrap();
        let (mut link, fluid, mut structure) = start_coupled(&case_path, &case, &out, tag);
        structure
            .publish_topology(header(0, 0.0), elements.len(), |o| o.copy_from_slice(&elements))
            .unwrap();
        structure
            .publish_kinematics(header(0, 0.0), nodes.len(), |o| o.copy_from_slice(&nodes))
            .unwrap();
        let failed = expect_reply(&mut link, &Command::init(), reply_kind::FAILED);
        expect_reply(&mut link, &Command::finish(), reply_kind::DONE);
        fluid.wait_with_output().unwrap();
        drop(structure);
        link.remove_resources().unwrap();
        (failed.code, failed.message_str().to_string())
    };
    let (code, message) = init_failure("nodes-only", Vec::new(), plate(0.55).to_vec());
    assert_eq!(code, failure_code::UNSUPPORTED);
    assert!(message.contains("4 wet nodes and 0 wet elements"), "{message}");
    let mut flat = plate(0.55);
    flat[2].x = flat[1].x;
    let sliver =
        SurfaceElement { nodes: [0, 1, 2, 0], n_nodes: 3, phi: [1.0; 4], ..Default::default() };
    let (code, message) = init_failure("degenerate", vec![quad, sliver], flat.to_vec());
    assert_eq!(code, failure_code::PROTOCOL);
    assert!(
        message.contains("surface element 0 (its triangle [0, 1, 2]) is degenerate"),
        "{message}"
    );

    let out = dir.path().join("nan");
    std::fs::create_dir(&out).unwrap();
    let (mut link, fluid, mut structure) = start_coupled(&case_path, &case, &out, "nan");
    structure.publish_topology(header(0, 0.0), 1, |o| o[0] = quad).unwrap();
    let at = plate(0.55);
    structure.publish_kinematics(header(0, 0.0), 4, |o| o.copy_from_slice(&at)).unwrap();
    expect_reply(&mut link, &Command::init(), reply_kind::READY);
    let n0 = structure.read_loads(|_, loads| loads.len()).unwrap();
    assert_eq!(n0, 4, "one load per wet node at the start");
    structure.publish_kinematics(header(0, TIMES[1]), 4, |o| o.copy_from_slice(&at)).unwrap();
    let command = Command::advance(0, TIMES[0], TIMES[1], scheme_phase::NONE);
    expect_reply(&mut link, &command, reply_kind::DONE);
    let (t, loads) = structure.read_loads(|h, loads| (h.time, loads.to_vec())).unwrap();
    assert_eq!((t, loads.len()), (TIMES[1], 4));
    assert!(loads.iter().all(|l| l.f.iter().all(|c| c.is_finite())), "{loads:?}");
    // The plate holds the gas of the left side (the default seed, the first probe): pushed +x.
    assert!(loads.iter().map(|l| l.f[0]).sum::<f64>() > 0.0, "{loads:?}");
    // A new topology (version 2): the quad as two triangles and a fifth node with a triangle
    // outside the tube, appended after the others. Read before the kinematics that carry it.
    let v2 = |step, time| StepHeader { topology_version: 2, ..header(step, time) };
    let tri = |nodes: [u32; 3]| SurfaceElement {
        nodes: [nodes[0], nodes[1], nodes[2], 0],
        n_nodes: 3,
        phi: [1.0; 4],
        ..Default::default()
    };
    let elements = [tri([0, 1, 2]), tri([0, 2, 3]), tri([1, 4, 2])];
    structure.publish_topology(v2(1, TIMES[1]), 3, |o| o.copy_from_slice(&elements)).unwrap();
    let mut at5 = at.to_vec();
    at5.push(NodeState { x: [0.55, 0.15, 0.0], v: [0.0; 3] });
    structure.publish_kinematics(v2(1, TIMES[2]), 5, |o| o.copy_from_slice(&at5)).unwrap();
    let command = Command::advance(1, TIMES[1], TIMES[2], scheme_phase::NONE);
    expect_reply(&mut link, &command, reply_kind::DONE);
    let (version, loads2) =
        structure.read_loads(|h, loads| (h.topology_version, loads.to_vec())).unwrap();
    assert_eq!((version, loads2.len()), (2, 5));
    assert_eq!(loads2[4].f, [0.0; 3], "the new node's triangle lies outside the tube");
    let fx = |l: &[NodeLoad]| l.iter().map(|l| l.f[0]).sum::<f64>();
    assert!(fx(&loads2) > 0.0, "{loads2:?}");
    let mut bad = at5;
    bad[2].x[1] = f64::NAN;
    structure.publish_kinematics(v2(2, TIMES[3]), 5, |o| o.copy_from_slice(&bad)).unwrap();
    let command = Command::advance(2, TIMES[2], TIMES[3], scheme_phase::NONE);
    let failed = expect_reply(&mut link, &command, reply_kind::FAILED);
    assert_eq!(failed.code, failure_code::PROTOCOL);
    assert!(
        failed.message_str().contains("surface node 2 has a non-finite position [0.55, NaN, 0.1]"),
        "{}",
        failed.message_str()
    );
    expect_reply(&mut link, &Command::finish(), reply_kind::DONE);
    let out = fluid.wait_with_output().unwrap();
    assert!(out.status.success(), "fluid-solver: {}", String::from_utf8_lossy(&out.stderr));
    drop(structure);
    link.remove_resources().unwrap();
}

/// A coupled fluid checks its state every step as the fluid alone does: two streams leaving each
/// other at Mach 6.7 pull the pressure negative a few steps in, and the `Advance` that meets it
/// is answered `Failed` (a solver failure) naming the step, the node, the field and its values.
#[test]
fn a_coupled_step_that_goes_bad_is_answered_failed_naming_node_and_field() {
    let dir = tempfile::tempdir().unwrap();
    let state = |u: f64| format!("[1.0, {u}, 0.0, 0.0, 0.1]");
    let separating = FLUID
        .replace(
            "state = [1.0, 0.0, 0.0, 0.0, 1.0]\nregions = [\n  { region = { shape = \"half_space\", point = [0.3, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }, state = [0.125, 0.0, 0.0, 0.0, 0.1] },",
            &format!(
                "state = {}\nregions = [\n  {{ region = {{ shape = \"half_space\", point = [0.5, 0.0, 0.0], normal = [1.0, 0.0, 0.0] }}, state = {} }},",
                state(-2.5),
                state(2.5)
            ),
        )
        .replace("xmin = { kind = \"far_field\", state = [1.0, 0.0, 0.0, 0.0, 1.0] }", &format!("xmin = {{ kind = \"far_field\", state = {} }}", state(-2.5)))
        .replace("xmax = { kind = \"far_field\", state = [0.125, 0.0, 0.0, 0.0, 0.1] }", &format!("xmax = {{ kind = \"far_field\", state = {} }}", state(2.5)))
        .replace("cfl = 0.9", "cfl = 0.3");
    assert_eq!(separating.matches("2.5").count(), 4, "{separating}");
    let case_path = write_case(dir.path(), &separating);
    let case = Case::load(&case_path, &[]).unwrap();
    let coupled = dir.path().join("coupled");
    std::fs::create_dir(&coupled).unwrap();
    let (mut link, fluid, mut structure) = start_coupled(&case_path, &case, &coupled, "bad");
    structure.publish_topology(header(0, 0.0), 0, |_| ()).unwrap();
    structure.publish_kinematics(header(0, 0.0), 0, |_| ()).unwrap();
    expect_reply(&mut link, &Command::init(), reply_kind::READY);
    structure.read_loads(|_, _| ()).unwrap();
    let mut failed = None;
    for (n, w) in TIMES.windows(2).enumerate() {
        let n = n as u64;
        structure.publish_kinematics(header(n, w[1]), 0, |_| ()).unwrap();
        link.send(Role::Fluid, &Command::advance(n, w[0], w[1], scheme_phase::NONE)).unwrap();
        let reply = link.wait_reply(Role::Fluid, Instant::now() + Duration::from_secs(10)).unwrap();
        if reply.kind == reply_kind::FAILED {
            failed = Some(reply);
            break;
        }
        assert_eq!(reply.kind, reply_kind::DONE, "{}", reply.message_str());
        structure.read_loads(|_, _| ()).unwrap();
    }
    let failed = failed.expect("a step of the separating streams fails");
    let msg = failed.message_str();
    println!("{msg}");
    assert_eq!(failed.code, failure_code::SOLVER, "{msg}");
    assert!(
        msg.contains("stopped at step ") && msg.contains("invalid fluid state at node "),
        "{msg}"
    );
    assert!(msg.contains("pressure ") && msg.contains("primitive [ρ, u, v, w, p] = ["), "{msg}");
    link.send(Role::Fluid, &Command::finish()).unwrap();
    let _ = link.wait_reply(Role::Fluid, Instant::now() + Duration::from_secs(10));
    let out = fluid.wait_with_output().unwrap();
    drop(structure);
    link.remove_resources().unwrap();
    assert!(!coupled.join("run.json").exists(), "run.json is the launcher's");
    // Coupled, checkpoints are the launcher's to name: the failing fluid writes none of its own.
    assert!(!coupled.join("checkpoints").exists(), "{}", String::from_utf8_lossy(&out.stderr));
}
