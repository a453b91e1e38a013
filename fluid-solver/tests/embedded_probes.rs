//! Probes and lines with an embedded surface read only active nodes on their own side of it
//! ([`fluid_solver::embedded::sample`]): beside a plate with a different state on each side
//! each probe reads its side's state, also where its nearest node is across the plate; inside a
//! closed body a probe reads NaN and a line sample NaN with the material `NO_FLUID`.

use fluid_solver::probes::NO_FLUID;
use fluid_solver::solver::{self, RunOptions};
use interface_protocol::case::Case;
use std::collections::HashMap;
use std::path::Path;

/// Runs `text` alone in `dir` and returns its output folder.
fn run(dir: &Path, name: &str, text: &str) -> std::path::PathBuf {
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(&path, text).unwrap();
    let case = Case::load(&path, &[]).unwrap();
    let out = dir.join(name);
    let opts = RunOptions { out: out.clone(), quiet: true, restart: None, force: false };
    solver::run(&case, text, &opts).unwrap();
    out
}

/// Columns of a CSV file by name (`NaN` parsed as NaN).
fn columns(path: &Path) -> HashMap<String, Vec<f64>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let names: Vec<String> = lines.next().unwrap().split(',').map(str::to_string).collect();
    let mut cols: Vec<Vec<f64>> = vec![Vec::new(); names.len()];
    for l in lines {
        for (c, v) in cols.iter_mut().zip(l.split(',')) {
            c.push(v.parse().unwrap());
        }
    }
    names.into_iter().zip(cols).collect()
}

const MESH: &str = r#"
[fluid.mesh]
box = { lo = [0, 0, 0], hi = [1, 0.5, 0.5], cells = [10, 5, 5], shape = "tet" }
[fluid.boundary]
xmin = { kind = "slip_wall" }
xmax = { kind = "slip_wall" }
ymin = { kind = "symmetry" }
ymax = { kind = "symmetry" }
zmin = { kind = "symmetry" }
zmax = { kind = "symmetry" }
[fluid.time]
t_end = 2e-4
[output]
fields_every = 0
checkpoint_every = 0
"#;

/// A static plate at x = 0.52 across the box, air at rest at (1.0, 1e5) on its left and
/// (2.0, 2e5) on its right: at rest against a wall at rest, each side keeps its state exactly.
/// The probe at x = 0.53 has its nearest node at x = 0.5, across the plate: it reads the right
/// side's state, as the one at x = 0.51 reads the left's.
#[test]
fn probes_beside_a_plate_read_their_own_side() {
    let dir = tempfile::tempdir().unwrap();
    let text = format!(
        r#"
[fluid]
eos = {{ kind = "perfect_gas", gamma = 1.4 }}
probes = [{{ name = "left", at = [0.51, 0.21, 0.19] }}, {{ name = "right", at = [0.53, 0.21, 0.19] }}, {{ name = "far", at = [0.8, 0.2, 0.2] }}]
lines = [{{ name = "across", from = [0.05, 0.2, 0.2], to = [0.95, 0.2, 0.2], points = 46 }}]
[fluid.initial]
state = [1.0, 0.0, 0.0, 0.0, 1e5]
regions = [{{ region = {{ shape = "half_space", point = [0.52, 0, 0], normal = [1, 0, 0] }}, state = [2.0, 0.0, 0.0, 0.0, 2e5] }}]
[fluid.embedded]
surface = {{ generator = "plate", corner = [0.52, -0.1, -0.1], edge_u = [0, 0.7, 0], edge_v = [0, 0, 0.7], cells = [2, 2] }}
tracking = "collision"
seeds = [{{ at = [0.2, 0.25, 0.25], active = true }}, {{ at = [0.8, 0.25, 0.25], active = true }}]
{MESH}"#
    );
    let out = run(dir.path(), "plate", &text);
    let probes = columns(&out.join("probes.csv"));
    let rows = probes["time"].len();
    assert!(rows > 3, "{rows} rows");
    for k in 0..rows {
        for (name, rho, p) in [("left", 1.0, 1e5), ("right", 2.0, 2e5), ("far", 2.0, 2e5)] {
            let (r, q) = (probes[&format!("{name}.rho")][k], probes[&format!("{name}.p")][k]);
            assert!(
                (r - rho).abs() < 1e-12 && (q - p).abs() < 1e-12 * p,
                "row {k}: probe {name} reads ({r}, {q}), its side is ({rho}, {p})"
            );
        }
    }
    let line = columns(&out.join("lines/across.csv"));
    for (k, x) in line["x"].iter().enumerate() {
        let rho = if *x < 0.52 { 1.0 } else { 2.0 };
        assert_eq!(line["rho"][k], rho, "line sample at x = {x}");
        assert_eq!(line["material"][k], 0.0);
    }
}

/// A closed box around a block of nodes (Alg. 4.1): a probe at its centre and one just inside
/// its wall (whose nearest node is a fluid node outside) read NaN; a line through it reads NaN
/// with the material `NO_FLUID` exactly at the points inside, the uniform state elsewhere.
#[test]
fn probes_inside_a_closed_body_read_nan() {
    let dir = tempfile::tempdir().unwrap();
    let text = format!(
        r#"
[fluid]
eos = {{ kind = "perfect_gas", gamma = 1.4 }}
probes = [{{ name = "centre", at = [0.25, 0.25, 0.25] }}, {{ name = "wall", at = [0.13, 0.21, 0.19] }}, {{ name = "out", at = [0.11, 0.21, 0.19] }}]
lines = [{{ name = "through", from = [0.02, 0.25, 0.25], to = [0.98, 0.25, 0.25], points = 48 }}]
[fluid.initial]
state = [1.3, 0.0, 0.0, 0.0, 1e5]
[fluid.embedded]
surface = {{ generator = "box", lo = [0.12, 0.12, 0.12], hi = [0.38, 0.38, 0.38], cells = [2, 2, 2] }}
seeds = [{{ at = [0.8, 0.05, 0.05], active = true }}, {{ at = [0.25, 0.25, 0.25], active = false }}]
{MESH}"#
    );
    let out = run(dir.path(), "body", &text);
    let probes = columns(&out.join("probes.csv"));
    for k in 0..probes["time"].len() {
        for field in ["rho", "vx", "vy", "vz", "p"] {
            assert!(probes[&format!("centre.{field}")][k].is_nan(), "row {k}: centre.{field}");
            assert!(probes[&format!("wall.{field}")][k].is_nan(), "row {k}: wall.{field}");
        }
        assert!((probes["out.rho"][k] - 1.3).abs() < 1e-12, "row {k}: out.rho");
    }
    let line = columns(&out.join("lines/through.csv"));
    let mut inside = 0;
    for (k, x) in line["x"].iter().enumerate() {
        if *x > 0.12 && *x < 0.38 {
            inside += 1;
            assert!(line["rho"][k].is_nan() && line["p"][k].is_nan(), "x = {x}");
            assert_eq!(line["material"][k], f64::from(NO_FLUID), "x = {x}");
        } else {
            assert!((line["rho"][k] - 1.3).abs() < 1e-12, "x = {x}: rho {}", line["rho"][k]);
            assert_eq!(line["material"][k], 0.0);
        }
    }
    assert!(inside >= 10, "{inside} samples inside");
}
