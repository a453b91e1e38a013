//! Helpers shared by the integration tests: building a problem, marching it to a time, exact
//! shock-tube solutions, error norms and the committed JSON references.
#![allow(dead_code)]

pub mod lines;
pub mod msh;
pub mod plot;

use fluid_solver::bc::BoundaryCondition;
use fluid_solver::eos::Eos;
use fluid_solver::initial::InitialCondition;
use fluid_solver::mesh::boxmesh::{BoxCells, BoxSpec};
use fluid_solver::mesh::Mesh;
use fluid_solver::riemann::{RiemannSolution, State1d};
use fluid_solver::semidiscretization::{Numerics, Semidiscretization};
use fluid_solver::state::{State, Workspace};
use fluid_solver::time::{rk2_step, TimeStepping};
use interface_protocol::case::Region;
use std::path::PathBuf;

/// Marches `state` to `t_end` with RK2 at the given CFL; returns the number of steps.
pub fn march(semi: &Semidiscretization, state: &mut State, t_end: f64, cfl: f64) -> usize {
    let mut ws = Workspace::new(semi.mesh.n_nodes());
    let mut t = 0.0;
    let mut steps = 0;
    while t < t_end * (1.0 - 1e-12) {
        let dt = rk2_step(semi, state, &mut ws, TimeStepping::Global { cfl }, t_end - t)
            .unwrap_or_else(|e| panic!("step {steps} at t = {t}: {e}"));
        t += dt;
        steps += 1;
        assert!(steps < 1_000_000);
    }
    steps
}

/// Every face of a box a symmetry plane except the two ends along x, which are far fields with
/// the given states.
pub fn tube_conditions(left: [f64; 5], right: [f64; 5]) -> Vec<(String, BoundaryCondition)> {
    let mut v: Vec<(String, BoundaryCondition)> = ["ymin", "ymax", "zmin", "zmax"]
        .iter()
        .map(|n| (n.to_string(), BoundaryCondition::Symmetry))
        .collect();
    v.push(("xmin".into(), BoundaryCondition::FarField { state: left }));
    v.push(("xmax".into(), BoundaryCondition::FarField { state: right }));
    v
}

/// A shock tube on `[0, 1]` with `n` cells, one cell thick (a square section 4 cells wide, so
/// the lateral facets, which carry no waves, limit the time step little), diaphragm at `x0`.
pub fn shock_tube(
    n: usize,
    shape: BoxCells,
    eos: Eos,
    left: [f64; 5],
    right: [f64; 5],
    x0: f64,
    numerics: Numerics,
) -> (Semidiscretization, State) {
    let mesh =
        Mesh::build(BoxSpec::tube(0.0, 1.0, n, 4.0 / n as f64, shape).raw().unwrap()).unwrap();
    let ic = InitialCondition::single(
        left,
        &[(Region::HalfSpace { point: [x0, 0.0, 0.0], normal: [1.0, 0.0, 0.0] }, right)],
    );
    let state = ic.state(&mesh, &[eos]).unwrap();
    let semi = Semidiscretization::new(mesh, eos, numerics, &tube_conditions(left, right)).unwrap();
    (semi, state)
}

/// The exact solution of a 1D Riemann problem along x.
pub struct ExactTube {
    pub solution: RiemannSolution,
    pub x0: f64,
    pub t: f64,
}

impl ExactTube {
    pub fn new(eos: Eos, left: [f64; 5], right: [f64; 5], x0: f64, t: f64) -> ExactTube {
        let s = |w: [f64; 5]| State1d { rho: w[0], u: w[1], p: w[4] };
        let solution = RiemannSolution::new(&eos, s(left), &eos, s(right)).expect("exact solution");
        ExactTube { solution, x0, t }
    }

    /// `(ρ, u, p)` at `x`.
    pub fn at(&self, x: f64) -> [f64; 3] {
        let s = self.solution.sample((x - self.x0) / self.t);
        [s.rho, s.u, s.p]
    }

    /// Widths of the left and right star plateaus.
    pub fn plateau_widths(&self) -> (f64, f64) {
        let u = self.solution.star.u;
        (self.t * (u - self.solution.left_wave().1), self.t * (self.solution.right_wave().1 - u))
    }

    /// Middles of the left and right star plateaus.
    pub fn plateau_middles(&self) -> (f64, f64) {
        let u = self.solution.star.u;
        let left_tail = self.solution.left_wave().1;
        let right_tail = self.solution.right_wave().1;
        (self.x0 + self.t * 0.5 * (left_tail + u), self.x0 + self.t * 0.5 * (u + right_tail))
    }
}

/// Volume-weighted mean of `|f_i - g(x_i)|`.
pub fn l1_error(mesh: &Mesh, values: &[f64], exact: impl Fn([f64; 3]) -> f64) -> f64 {
    let mut s = 0.0;
    for i in 0..mesh.n_nodes() {
        s += mesh.volumes[i] * (values[i] - exact(mesh.coords[i])).abs();
    }
    s / mesh.total_volume()
}

/// Root of the volume-weighted mean of `(f_i - g(x_i))²`.
pub fn l2_error(mesh: &Mesh, values: &[f64], exact: impl Fn([f64; 3]) -> f64) -> f64 {
    let mut s = 0.0;
    for i in 0..mesh.n_nodes() {
        s += mesh.volumes[i] * (values[i] - exact(mesh.coords[i])).powi(2);
    }
    (s / mesh.total_volume()).sqrt()
}

/// A primitive variable of a tube at `x`: the average over the nodes of the two stations
/// around `x`, interpolated linearly.
pub fn tube_value(mesh: &Mesh, prim: &[[f64; 5]], k: usize, x: f64) -> f64 {
    let mut stations: Vec<(f64, f64, usize)> = Vec::new();
    for (i, c) in mesh.coords.iter().enumerate() {
        match stations.iter_mut().find(|s| (s.0 - c[0]).abs() < 1e-12) {
            Some(s) => {
                s.1 += prim[i][k];
                s.2 += 1;
            }
            None => stations.push((c[0], prim[i][k], 1)),
        }
    }
    stations.sort_by(|a, b| a.0.total_cmp(&b.0));
    let at = |s: &(f64, f64, usize)| s.1 / s.2 as f64;
    let k = stations.partition_point(|s| s.0 <= x).clamp(1, stations.len() - 1);
    let (a, b) = (&stations[k - 1], &stations[k]);
    let t = (x - a.0) / (b.0 - a.0);
    (1.0 - t) * at(a) + t * at(b)
}

/// Primitive variables of a state.
pub fn primitives(eos: &Eos, state: &State) -> Vec<[f64; 5]> {
    state.cons.iter().map(|q| eos.cons_to_prim(q)).collect()
}

/// Observed order between successive errors of meshes refined by 2.
pub fn orders(errors: &[f64]) -> Vec<f64> {
    errors.windows(2).map(|w| (w[0] / w[1]).log2()).collect()
}

/// Path of a committed reference file.
pub fn reference_path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/reference").join(name)
}

/// Compares a table of errors with its committed JSON reference (relative tolerance `rel`);
/// with `FIVER_BLESS=1` in the environment, writes the reference instead.
pub fn compare_with_reference(name: &str, table: &serde_json::Value, rel: f64) {
    let path = reference_path(name);
    if std::env::var("FIVER_BLESS").is_ok_and(|v| v == "1") {
        std::fs::write(&path, serde_json::to_string_pretty(table).unwrap() + "\n").unwrap();
        return;
    }
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| {
        panic!("{}: {e} (run with FIVER_BLESS=1 to create it)", path.display())
    });
    let reference: serde_json::Value = serde_json::from_str(&text).unwrap();
    compare_values(&reference, table, rel, name);
}

fn compare_values(reference: &serde_json::Value, value: &serde_json::Value, rel: f64, at: &str) {
    use serde_json::Value;
    match (reference, value) {
        (Value::Object(a), Value::Object(b)) => {
            for (k, va) in a {
                let vb = b.get(k).unwrap_or_else(|| panic!("{at}.{k}: missing"));
                compare_values(va, vb, rel, &format!("{at}.{k}"));
            }
        }
        (Value::Array(a), Value::Array(b)) => {
            assert_eq!(a.len(), b.len(), "{at}: length");
            for (k, (va, vb)) in a.iter().zip(b).enumerate() {
                compare_values(va, vb, rel, &format!("{at}[{k}]"));
            }
        }
        (Value::Number(a), Value::Number(b)) => {
            let (a, b) = (a.as_f64().unwrap(), b.as_f64().unwrap());
            assert!(
                (a - b).abs() <= rel * a.abs().max(1e-300),
                "{at}: {b} differs from the reference {a}"
            );
        }
        (a, b) => assert_eq!(a, b, "{at}"),
    }
}
