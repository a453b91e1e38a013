//! The field output of an embedded surface, read back with real readers (h5py, meshio): the
//! node `status` and `p_wall` in `fluid.xdmf`, and the surface's own time series
//! (`surface.xdmf`) with its moving geometry and the pressure on each side.

use fluid_solver::embedded::advance::Kinematics;
use fluid_solver::embedded::status::NodeStatus;
use fluid_solver::eos::Eos;
use fluid_solver::riemann::{RiemannSolution, State1d};
use fluid_solver::solver::{FluidRun, Mode, RunOptions};
use interface_protocol::case::Case;
use interface_protocol::io::report::{RunReport, SurfaceReport};
use std::path::Path;
use std::process::Command;

/// Runs `script` with `args` in python3 (with h5py, meshio, numpy) and parses its JSON output.
fn python(script: &str, args: &[&Path]) -> serde_json::Value {
    let probe = Command::new("python3").args(["-c", "import meshio, h5py, numpy"]).output();
    assert!(
        probe.is_ok_and(|o| o.status.success()),
        "python3 with meshio, h5py and numpy is needed to read the output back: run \
         scripts/install-deps.sh"
    );
    let out = Command::new("python3").arg("-c").arg(script).args(args).output().unwrap();
    assert!(out.status.success(), "python failed:\n{}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).unwrap()
}

/// Every step of `fluid.xdmf` through meshio, with the `status` and `p_wall` fields (NaN as
/// null), and every step of `surface.xdmf` with its own geometry (meshio's series reader pointed
/// at each grid of the temporal collection in turn).
const READER: &str = r#"
import json, sys, math
import meshio
def clean(v):
    return [None if isinstance(x, float) and math.isnan(x) else x for x in v]
out = {"fluid": [], "surface": []}
with meshio.xdmf.TimeSeriesReader(sys.argv[1]) as r:
    r.read_points_cells()
    for k in range(r.num_steps):
        t, pd, _ = r.read_data(k)
        out["fluid"].append({"t": t, "status": pd["status"].tolist(), "p_wall": clean(pd["p_wall"].tolist()), "p": pd["p"].tolist()})
with meshio.xdmf.TimeSeriesReader(sys.argv[2]) as r:
    grids = list(r.collection)
    for k in range(r.num_steps):
        r.mesh_grid = grids[k]
        points, cells = r.read_points_cells()
        t, pd, _ = r.read_data(k)
        out["surface"].append({
            "t": t, "points": points.tolist(), "cells": [[c.type, len(c.data)] for c in cells],
            "velocity": pd["velocity"].tolist(),
            "p_plus": clean(pd["p_plus"].tolist()), "p_minus": clean(pd["p_minus"].tolist()),
        })
print(json.dumps(out))
"#;

/// A closed box carried by a uniform flow at its own velocity, on a coarse tet mesh, fields every
/// 40 steps.
fn carried_box(loads: &str) -> String {
    let w = [1.3, 10.0, 0.0, 0.0, 1e5];
    format!(
        r#"
[fluid]
eos = {{ kind = "perfect_gas", gamma = 1.4 }}
[fluid.mesh]
box = {{ lo = [0, 0, 0], hi = [1, 0.5, 0.5], cells = [16, 8, 8], shape = "tet" }}
[fluid.initial]
state = {w:?}
[fluid.boundary]
xmin = {{ kind = "far_field", state = {w:?} }}
xmax = {{ kind = "far_field", state = {w:?} }}
ymin = {{ kind = "symmetry" }}
ymax = {{ kind = "symmetry" }}
zmin = {{ kind = "symmetry" }}
zmax = {{ kind = "symmetry" }}
[fluid.embedded]
surface = {{ generator = "box", lo = [0.21, 0.13, 0.12], hi = [0.46, 0.38, 0.37], cells = [2, 2, 2] }}
motion = {{ kind = "translation", velocity = [10, 0, 0] }}
loads = "{loads}"
seeds = [{{ at = [0.9, 0.05, 0.05], active = true }}, {{ at = [0.33, 0.25, 0.25], active = false }}]
[fluid.time]
t_end = 4e-3
[output]
fields_every = 40
checkpoint_every = 0
"#
    )
}

fn f64s(v: &serde_json::Value) -> Vec<Option<f64>> {
    v.as_array().unwrap().iter().map(|x| x.as_f64()).collect()
}

/// `status` in `fluid.xdmf` has the run's counts of active, occluded and inactive nodes, node by
/// node; `p_wall` is finite exactly at the active nodes with a cut edge and there equals the
/// uniform pressure (Alg. 5.1 with the wall moving with the flow gives `p* = p`). The surface
/// series carries the box at `x_0 + v t` at every output time (the motion law), its velocity,
/// `p* = p` on the fluid side and no pressure on the side inside the box.
#[test]
fn status_p_wall_and_the_moving_surface_read_back() {
    let dir = tempfile::tempdir().unwrap();
    let text = carried_box("facets");
    let path = dir.path().join("case.toml");
    std::fs::write(&path, &text).unwrap();
    let case = Case::load(&path, &[]).unwrap();
    let out = dir.path().join("out");
    let opts = RunOptions { out: out.clone(), quiet: true, restart: None, force: false };
    let mut run = FluidRun::open(&case, &text, &opts, Mode::Alone).unwrap();
    run.advance_to(run.t_end()).unwrap();
    let steps = run.reached().step;
    let e = run.embedded().unwrap();
    let tracker = e.tracker.clone();
    let Kinematics::Law { reference, .. } = e.kinematics.clone() else { panic!("a law") };
    let mesh = run.semidiscretization().mesh.clone();
    run.finish().unwrap();

    let got = python(READER, &[&out.join("fluid.xdmf"), &out.join("surface.xdmf")]);
    let fluid = got["fluid"].as_array().unwrap();
    // t = 0, every 40 steps, and the end if it falls between.
    assert_eq!(fluid.len() as u64, 1 + steps / 40 + u64::from(steps % 40 != 0));
    let last = fluid.last().unwrap();
    assert_eq!(last["t"].as_f64().unwrap(), 4e-3);

    let status: Vec<f64> = f64s(&last["status"]).into_iter().map(Option::unwrap).collect();
    let count = |s: NodeStatus| tracker.sides.status.iter().filter(|&&x| x == s).count();
    let written = |v: f64| status.iter().filter(|&&x| x == v).count();
    let counts = [NodeStatus::Active, NodeStatus::Occluded, NodeStatus::Inactive].map(count);
    println!("{steps} steps; active, occluded, inactive nodes: {counts:?}");
    assert_eq!([written(0.0), written(1.0), written(2.0)], counts);
    assert!(counts[0] > 0 && counts[2] > 0);
    for (i, s) in tracker.sides.status.iter().enumerate() {
        assert_eq!(status[i], f64::from(*s as u8), "node {i}");
    }

    let mut at_cut = vec![false; mesh.n_nodes()];
    for c in &tracker.cuts.cuts {
        for n in mesh.edges[c.edge as usize] {
            at_cut[n as usize] |= tracker.active[n as usize];
        }
    }
    let p_wall = f64s(&last["p_wall"]);
    let mut worst = 0.0f64;
    for (i, p) in p_wall.iter().enumerate() {
        assert_eq!(p.is_some(), at_cut[i], "node {i}: p_wall {p:?}, at a cut edge {}", at_cut[i]);
        if let Some(p) = p {
            worst = worst.max((p - 1e5).abs() / 1e5);
        }
    }
    println!(
        "{} nodes with p_wall, largest |p_wall - p| / p = {worst:.2e}",
        at_cut.iter().filter(|&&a| a).count()
    );
    assert!(at_cut.iter().filter(|&&a| a).count() > 20);
    assert!(worst < 1e-10, "p_wall off the uniform pressure by {worst:e}");

    // The surface: the box at x_0 + v t at each output time, quads merged back.
    let surface = got["surface"].as_array().unwrap();
    assert_eq!(surface.len(), fluid.len());
    let times: Vec<f64> = surface.iter().map(|s| s["t"].as_f64().unwrap()).collect();
    assert!(times.len() >= 3 && times[0] == 0.0);
    for s in surface {
        let t = s["t"].as_f64().unwrap();
        let points: Vec<f64> =
            s["points"].as_array().unwrap().iter().flat_map(f64s).map(Option::unwrap).collect();
        let exact: Vec<f64> =
            reference.iter().flat_map(|x| [x[0] + 10.0 * t, x[1], x[2]]).collect();
        assert_eq!(points.len(), exact.len());
        let err = points.iter().zip(&exact).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        assert!(err < 1e-14, "t = {t}: positions off the motion law by {err:e}");
        assert_eq!(s["cells"], serde_json::json!([["quad", 24]]), "t = {t}");
        let v: Vec<f64> =
            s["velocity"].as_array().unwrap().iter().flat_map(f64s).map(Option::unwrap).collect();
        assert!(v.chunks(3).all(|c| c == [10.0, 0.0, 0.0]), "t = {t}: velocity");
        let (plus, minus) = (f64s(&s["p_plus"]), f64s(&s["p_minus"]));
        // One side is the fluid, the other the inside of the box.
        let (fluid_side, inside) = match plus.iter().any(Option::is_some) {
            true => (plus, minus),
            false => (minus, plus),
        };
        assert!(inside.iter().all(Option::is_none), "t = {t}: pressure inside the box");
        let reached = fluid_side.iter().flatten().count();
        assert!(reached > fluid_side.len() / 2, "t = {t}: {reached} of {} nodes", fluid_side.len());
        for p in fluid_side.iter().flatten() {
            assert!((p - 1e5).abs() < 1e-10 * 1e5, "t = {t}: p* = {p}");
        }
    }
}

/// Runs the case file `path` (with `overrides`) alone into `out` through [`FluidRun`]: returns the
/// active volume `Σ |C_i|` over the active nodes at the start and at the end, and `run.json`'s
/// surface section.
fn run_with_volumes(path: &Path, overrides: &[String], out: &Path) -> (f64, f64, SurfaceReport) {
    let case = Case::load(path, overrides).unwrap();
    let text = std::fs::read_to_string(path).unwrap();
    let opts = RunOptions { out: out.to_path_buf(), quiet: true, restart: None, force: false };
    let mut run = FluidRun::open(&case, &text, &opts, Mode::Alone).unwrap();
    let volume = |run: &FluidRun| {
        let (mesh, active) =
            (&run.semidiscretization().mesh, &run.embedded().unwrap().tracker.active);
        (0..mesh.n_nodes()).filter(|&i| active[i]).map(|i| mesh.volumes[i]).sum::<f64>()
    };
    let v0 = volume(&run);
    run.advance_to(run.t_end()).unwrap();
    let v1 = volume(&run);
    run.finish().unwrap();
    let report = RunReport::read(&out.join("run.json")).unwrap();
    (v0, v1, report.surface.expect("an embedded run reports its surface"))
}

/// `run.json`'s `surface` section. A closed box carried by a uniform flow over exactly one cell
/// of a mesh that repeats itself cell by cell: the box then covers as much dual volume as at the
/// start, the flow stays uniform and what enters at `xmin` leaves at `xmax`, so the mass the
/// surface creates is zero to round-off. The piston (`cases/piston-air`, 130 cells): the wall
/// creates no mass, so the exact solution puts in the discrete active region of volume `V_A(t)`
/// the mass `M_0 + ρ* (V_A(t) - V_f(t))` (`V_f = (0.6 - x_wall) A`, the fluid region, `M_0 = ρ_0
/// V_f(0)`, `ρ*` the exact density behind the shock) and the mass change is that minus `ρ_0
/// V_A(0)`; no wave reaches the far field, so no mass crosses the boundary.
#[test]
fn run_json_reports_the_mass_the_surface_creates() {
    let dir = tempfile::tempdir().unwrap();
    // One cell of 1/16 at 10 m/s.
    let text = carried_box("reconstructed").replace("t_end = 4e-3", "t_end = 6.25e-3");
    let path = dir.path().join("box.toml");
    std::fs::write(&path, &text).unwrap();
    let (v0, v1, s) = run_with_volumes(&path, &[], &dir.path().join("box"));
    println!("closed box: {s:?}, active volume {v0} -> {v1}");
    assert!(s.cut_edges > 100 && s.active_nodes > 1000 && s.inactive_nodes > 0);
    assert!(s.tracking_seconds > 0.0 && s.wall_flux_seconds > 0.0 && s.loads_seconds > 0.0);
    assert!((v1 - v0).abs() < 1e-12 * v0, "the covered volume changed: {v0} -> {v1}");
    assert!((s.mass_start - 1.3 * v0).abs() < 1e-12 * s.mass_start);
    assert!(s.boundary_outflow.abs() < 1e-12 * s.mass_start, "outflow {:e}", s.boundary_outflow);
    let rel = s.mass_change.abs() / s.mass_start;
    println!("closed box: mass change {:e} kg, {rel:.2e} of the mass", s.mass_change);
    assert!(rel < 1e-12, "the closed box creates {:e} kg", s.mass_change);
    let balance = s.mass_end - s.mass_start + s.boundary_outflow;
    assert!((balance - s.mass_change).abs() < 1e-12 * s.mass_start);

    let piston = Path::new(env!("CARGO_MANIFEST_DIR")).join("../cases/piston-air/case.toml");
    let cells = 130;
    let overrides =
        vec![format!("fluid.mesh.box.cells=[{cells},1,1]"), "output.fields_every=0".to_string()];
    let (v0, v1, s) = run_with_volumes(&piston, &overrides, &dir.path().join("piston"));
    let eos = Eos::PerfectGas { gamma: 1.4 };
    let star = RiemannSolution::wall(&eos, State1d { rho: 1.3, u: 0.0, p: 1e5 }, -10.0).unwrap();
    let rho_star = star.star.rho_l;
    let area = 0.01 * 0.01;
    let fluid_volume = |t: f64| (0.6 - (0.001 + 10.0 * t)) * area;
    let m0 = 1.3 * fluid_volume(0.0);
    let exact = m0 + rho_star * (v1 - fluid_volume(1.2e-3)) - 1.3 * v0;
    let cell_mass = 1.3 * 0.65 / cells as f64 * area;
    println!(
        "piston: {s:?}; ρ* = {rho_star}, active volume {v0:e} -> {v1:e}; mass change {:e} kg, \
         exact {exact:e} kg, difference {:.3} of one cell's mass ({cell_mass:e} kg)",
        s.mass_change,
        (s.mass_change - exact) / cell_mass
    );
    assert!((s.mass_start - 1.3 * v0).abs() < 1e-12 * s.mass_start);
    assert!(s.boundary_outflow.abs() < 1e-10 * s.mass_start, "outflow {:e}", s.boundary_outflow);
    assert!(
        (s.mass_change - exact).abs() < 0.01 * cell_mass,
        "piston: mass change {:e} kg against {exact:e} kg",
        s.mass_change
    );
}
