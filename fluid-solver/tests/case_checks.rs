//! What `run` checks before its first step, and `fluid-solver check` with it (one setup shared
//! by both): probes and lines outside the mesh (a non-convex mesh included), initial regions
//! that hold no node, states the EOS does not admit, line times outside the run, meshes that
//! cannot fit in memory, step counts past the cap and gmsh headers announcing absurd counts.
//! Every error names the case key (or the file and line) and what was expected. Then the `check`
//! binary: a summary and exit 0, or the error and a non-zero exit, for cases run alone and
//! coupled, and never an output folder.

mod common;

use common::msh::to_msh;
use fluid_solver::check;
use fluid_solver::mesh::boxmesh::{BoxCells, BoxSpec};
use fluid_solver::mesh::TaggedFace;
use interface_protocol::case::Case;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

fn case_path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../cases/sod-tube/case.toml")
}

/// The sod-tube case on 50 cells with `extra` overrides.
fn small(extra: &[&str]) -> Vec<String> {
    let mut v = vec!["fluid.mesh.box.cells=[50,1,1]".to_string()];
    v.extend(extra.iter().map(|s| s.to_string()));
    v
}

/// What `check` says of the sod-tube case with `overrides`: its summary followed by its
/// warnings (one `warning: ...` line each), or its error.
fn check_case(path: &Path, overrides: &[String]) -> Result<String, String> {
    Case::load(path, overrides)
        .map_err(anyhow::Error::from)
        .and_then(|case| check::check(&case))
        .map(|c| {
            let warnings: String = c.warnings.iter().map(|w| format!("warning: {w}\n")).collect();
            c.summary + &warnings
        })
        .map_err(|e| format!("{e:#}"))
}

/// The error of the sod-tube case with `extra`, which must contain every one of `expected`.
fn error_of(extra: &[&str], expected: &[&str]) -> String {
    let e = check_case(&case_path(), &small(extra)).expect_err("the case is refused");
    println!("{e}");
    for x in expected {
        assert!(e.contains(x), "`{x}` missing from: {e}");
    }
    e
}

#[test]
fn the_sod_case_checks_with_its_probes_on_the_mesh_boundary() {
    // Its probes and line lie on the edge y = z = 0 of the tube: on the boundary is inside.
    let summary = check_case(&case_path(), &small(&[])).unwrap();
    assert!(
        summary.contains("ok, as the fluid alone") && summary.contains("204 nodes"),
        "{summary}"
    );
    assert!(summary.contains("2 probes, 1 lines (201 points)"), "{summary}");
}

#[test]
fn probes_and_lines_outside_the_mesh_are_named() {
    let probes = "fluid.probes=[{name=\"a\",at=[0.2,0,0]},{name=\"b\",at=[0.5,0.01,0.01]},{name=\"c\",at=[9,0,0]}]";
    error_of(
        &[probes],
        &[
            "field `fluid.probes[2].at`: [9.0, 0.0, 0.0] lies outside the fluid mesh",
            "bounding box",
        ],
    );
    let line = |from: &str, to: &str| {
        format!("fluid.lines=[{{name=\"axis\",from={from},to={to},points=11,times=[0.1]}}]")
    };
    error_of(
        &[&line("[0,0,0]", "[1.5,0,0]")],
        &["field `fluid.lines[0].to`: [1.5, 0.0, 0.0] lies outside"],
    );
    error_of(
        &[&line("[0,-0.1,0]", "[1,0,0]")],
        &["field `fluid.lines[0].from`: [0.0, -0.1, 0.0] lies outside"],
    );
    // Just outside the end, by more than round-off.
    error_of(&[&line("[0,0,0]", "[1.000001,0,0]")], &["fluid.lines[0].to"]);
}

/// An L-shaped gmsh mesh: the box [0, 2] x [0, 2] x [0, 1] without its quarter x, y > 1. A probe
/// in the missing quarter is inside the bounding box but in no cell, and a line across it has
/// both ends inside.
#[test]
fn points_in_the_notch_of_a_non_convex_mesh_are_outside() {
    let dir = tempfile::tempdir().unwrap();
    let spec = BoxSpec::uniform([0.0; 3], [2.0, 2.0, 1.0], [4, 4, 2], BoxCells::Tet);
    let mut raw = spec.raw().unwrap();
    let coords = raw.coords.clone();
    let in_notch = |nodes: &[u32]| {
        let x = |v: u32| coords[v as usize];
        nodes.iter().all(|&v| x(v)[0] >= 1.0 && x(v)[1] >= 1.0)
    };
    let removed: Vec<_> = raw.cells.iter().filter(|c| in_notch(c.nodes())).cloned().collect();
    raw.cells.retain(|c| !in_notch(c.nodes()));
    raw.faces.retain(|f| !in_notch(&f.nodes));
    // The faces between the notch and the rest become the walls of the notch (`xmax`).
    for c in &removed {
        for lf in c.kind.faces() {
            let nodes: Vec<u32> = lf.iter().rev().map(|&l| c.nodes[l]).collect();
            let on = |d: usize| nodes.iter().all(|&v| coords[v as usize][d] == 1.0);
            if on(0) || on(1) {
                raw.faces.push(TaggedFace { patch: 1, nodes });
            }
        }
    }
    std::fs::write(dir.path().join("l.msh"), to_msh(&raw)).unwrap();
    let case = dir.path().join("case.toml");
    std::fs::copy(case_path(), &case).unwrap();
    let on_l = |extra: &str| {
        check_case(
            &case,
            &[
                "fluid.mesh={file=\"l.msh\"}".to_string(),
                "fluid.initial.regions=[]".to_string(),
                "fluid.lines=[]".to_string(),
                extra.to_string(),
            ],
        )
    };
    let summary = on_l("fluid.probes=[{name=\"in\",at=[0.5,1.5,0.5]}]").unwrap();
    assert!(summary.contains("1 probes"), "{summary}");
    let e = on_l("fluid.probes=[{name=\"in\",at=[0.5,1.5,0.5]},{name=\"notch\",at=[1.5,1.5,0.5]}]")
        .unwrap_err();
    println!("{e}");
    assert!(
        e.contains("field `fluid.probes[1].at`: [1.5, 1.5, 0.5] lies outside the fluid mesh"),
        "{e}"
    );
    let e = on_l(
        "fluid.lines=[{name=\"across\",from=[0.9,1.9,0.5],to=[1.9,0.9,0.5],points=21,times=[]}]",
    )
    .unwrap_err();
    println!("{e}");
    assert!(
        e.contains("field `fluid.lines[0]`: sample point 3 of 21 of line `across`, at [1.05, 1.75"),
        "{e}"
    );
}

#[test]
fn initial_regions_that_hold_no_node_are_named() {
    let region =
        |r: &str| format!("fluid.initial.regions=[{{region={r},state=[0.125,0,0,0,0.1]}}]");
    error_of(
        &[&region("{shape=\"box\",lo=[2,0,0],hi=[3,1,1]}")],
        &["field `fluid.initial.regions[0]`: the box from [2.0, 0.0, 0.0] to [3.0, 1.0, 1.0] holds no mesh node"],
    );
    // Inside the tube, but smaller than its cells and between their nodes.
    error_of(
        &[&region("{shape=\"sphere\",center=[0.51,0.01,0.01],radius=0.001}")],
        &["field `fluid.initial.regions[0]`: the sphere of radius 0.001", "holds no mesh node"],
    );
}

#[test]
fn states_the_eos_does_not_admit_are_named() {
    error_of(&["fluid.initial.state=[1.0,0,0,0,-1]"], &["fluid.initial.state", "pressure -1"]);
    error_of(
        &["fluid.boundary.xmin={kind=\"far_field\",state=[1,0,0,0,0]}"],
        &["fluid.boundary.xmin.state", "at or below the EOS limit 0"],
    );
    error_of(
        &["fluid.boundary.xmax={kind=\"outflow\",pressure=-5.0}"],
        &["fluid.boundary.xmax.pressure", "-5 is at or below the lowest pressure 0"],
    );
    error_of(
        &["fluid.initial.regions=[{region={shape=\"half_space\",point=[0.3,0,0],normal=[1,0,0]},state=[1,1e200,0,0,1]}]"],
        &["fluid.initial.regions[0].state", "overflow"],
    );
    // Tait water: the pressure follows from the density and a different one is refused.
    let tait = "fluid.eos={kind=\"tait\",k1=2.07e9,k2=7.15,rho0=1000.0,p0=1e5}";
    let water = [
        tait,
        "fluid.initial.state=[1000.0,0,0,0,1e5]",
        "fluid.initial.regions=[]",
        "fluid.boundary.xmin={kind=\"slip_wall\"}",
        "fluid.boundary.xmax={kind=\"slip_wall\"}",
    ];
    check_case(&case_path(), &small(&water)).unwrap();
    let mut wrong = water.to_vec();
    wrong[1] = "fluid.initial.state=[1000.0,0,0,0,5e5]";
    error_of(&wrong, &["fluid.initial.state", "ρ = 1000 gives p = 1e5, not 5e5"]);
}

#[test]
fn line_times_outside_the_run_are_named() {
    // After the end (a run shortened with --set): a warning, not a refusal.
    let lines = "fluid.lines=[{name=\"axis\",from=[0,0,0],to=[1,0,0],times=[0.1,0.3]}]";
    let summary = check_case(&case_path(), &small(&[lines])).unwrap();
    assert!(
        summary.contains("field `fluid.lines[0].times[1]`: 0.3 is after the end of the run (fluid.time.t_end = 0.2)"),
        "{summary}"
    );
    assert!(!summary.contains("times[0]"), "{summary}");
    error_of(
        &["fluid.lines=[{name=\"axis\",from=[0,0,0],to=[1,0,0],times=[-0.1]}]"],
        &["fluid.lines[0].times[0]", "expected a finite time >= 0"],
    );
}

#[test]
fn runs_that_cannot_fit_or_end_are_refused_at_once() {
    let start = Instant::now();
    // 10^14 cells: refused before anything is allocated.
    let e = error_of(
        &["fluid.mesh.box.cells=[100000,100000,10000]"],
        &["fluid.mesh.box.cells", "[100000, 100000, 10000]", "needs about", "available"],
    );
    assert!(e.contains("B per node") && e.contains("PiB"), "{e}");
    error_of(
        &["fluid.time.max_steps=100000000000"],
        &["fluid.time.max_steps", "at most 1000000000"],
    );
    error_of(
        &["fluid.time.t_end=1e300"],
        &["fluid.time.t_end = 1e300 over the initial CFL step", "steps, more than the 1000000000"],
    );
    // With max_steps the run ends, however far t_end.
    check_case(&case_path(), &small(&["fluid.time.t_end=1e300", "fluid.time.max_steps=10"]))
        .unwrap();
    assert!(start.elapsed() < Duration::from_secs(5), "took {:?}", start.elapsed());
}

#[test]
fn gmsh_headers_announcing_absurd_counts_are_refused_naming_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let fixture = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/tet_box.msh");
    let text = std::fs::read_to_string(fixture).unwrap();
    let case = dir.path().join("case.toml");
    std::fs::copy(case_path(), &case).unwrap();
    for section in ["$Nodes\n", "$Elements\n"] {
        let at = text.find(section).unwrap() + section.len();
        let header_end = at + text[at..].find('\n').unwrap();
        let mut fields: Vec<String> =
            text[at..header_end].split_whitespace().map(str::to_string).collect();
        fields[1] = "100000000000000".into();
        fields[3] = "100000000000000".into();
        let bad = format!("{}{}{}", &text[..at], fields.join(" "), &text[header_end..]);
        std::fs::write(dir.path().join("huge.msh"), bad).unwrap();
        let line = text[..at].lines().count() + 1;
        let e = check_case(&case, &["fluid.mesh={file=\"huge.msh\"}".to_string()]).unwrap_err();
        println!("{e}");
        assert!(e.contains("fluid.mesh.file") && e.contains(&format!("huge.msh:{line}")), "{e}");
        assert!(e.contains("100000000000000"), "{e}");
    }
}

fn fluid_solver() -> Command {
    Command::new(env!("CARGO_BIN_EXE_fluid-solver"))
}

/// The files and folders in `dir`.
fn listing(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn the_check_command_summarises_or_names_the_error_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let case = dir.path().join("case.toml");
    let text = std::fs::read_to_string(case_path()).unwrap();
    std::fs::write(&case, format!("{text}dir = \"out\"\n")).unwrap();
    let run = |extra: &[&str]| {
        let mut cmd = fluid_solver();
        cmd.arg("check").arg(&case).current_dir(dir.path());
        for s in small(extra) {
            cmd.arg("--set").arg(s);
        }
        cmd.output().unwrap()
    };
    let ok = run(&[]);
    let stdout = String::from_utf8_lossy(&ok.stdout);
    assert!(ok.status.success(), "{}", String::from_utf8_lossy(&ok.stderr));
    assert!(stdout.contains("ok, as the fluid alone") && stdout.contains("first step"), "{stdout}");
    let bad = run(&["fluid.probes=[{name=\"far\",at=[0,0,5]}]"]);
    let stderr = String::from_utf8_lossy(&bad.stderr);
    assert!(!bad.status.success() && bad.stdout.is_empty(), "{stderr}");
    assert!(stderr.contains("case.toml") && stderr.contains("fluid.probes[0].at"), "{stderr}");
    let bad = run(&["fluid.boundary.inlet={kind=\"slip_wall\"}"]);
    let stderr = String::from_utf8_lossy(&bad.stderr);
    assert!(!bad.status.success() && stderr.contains("fluid.boundary.inlet"), "{stderr}");
    // Neither `[output] dir` nor a default run folder was made.
    assert_eq!(listing(dir.path()), ["case.toml"]);
}

#[test]
fn a_coupled_case_checks_the_fluid_of_the_coupled_run() {
    let dir = tempfile::tempdir().unwrap();
    let case = dir.path().join("case.toml");
    let text = std::fs::read_to_string(case_path()).unwrap();
    // A coupled case needs no [fluid.time]: the coupling drives the fluid to coupling.t_end.
    let fluid_only = text.replace("[fluid.time]\nt_end = 0.2\n", "");
    assert_ne!(fluid_only, text);
    let coupled = format!(
        "{fluid_only}\n[coupling]\nscheme = \"CSS\"\ndt = 0.025\nt_end = 0.1\n\n[structure]\n\
         command = [\"rigid-structure\"]\n\n[structure.rigid]\nmass = 1.0\nstiffness = 1.0e4\n\
         wet_nodes = [[0.0, -0.1, -0.1], [0.0, 0.1, -0.1], [0.0, 0.1, 0.1], [0.0, -0.1, 0.1]]\n\
         wet_elements = [[0, 1, 2, 3]]\n"
    );
    std::fs::write(&case, coupled).unwrap();
    let r = fluid_solver()
        .arg("check")
        .arg(&case)
        .args(["--set", "fluid.mesh.box.cells=[50,1,1]"])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&r.stdout);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    assert!(
        stdout.contains("as the fluid of a coupled run") && stdout.contains("to t = 1e-1"),
        "{stdout}"
    );
    // Its line time is checked against coupling.t_end, and the fluid steps against the cap.
    let s = check_case(&case, &small(&["coupling.t_end=0.05"])).unwrap();
    assert!(
        s.contains(
            "field `fluid.lines[0].times[0]`: 0.1 is after the end of the run (coupling.t_end = 0.05)"
        ),
        "{s}"
    );
    let e = check_case(&case, &small(&["coupling.t_end=1e7", "coupling.dt=1e4", "fluid.lines=[]"]))
        .unwrap_err();
    assert!(e.contains("coupling.t_end") && e.contains("more than the 1000000000"), "{e}");
}
