//! `fluid-solver bench`: node-steps per second per core of RK2 + MUSCL (van Albada) + Roe on a
//! perfect gas, on a box of tets with a non-uniform state, with 1 and 2 threads; memory per
//! node; and the split of one residual into its passes. A node-step is one full RK2 step (two
//! residuals) of one node (DESIGN §8).

use crate::bc::BoundaryCondition;
use crate::eos::Eos;
use crate::mesh::boxmesh::{BoxCells, BoxSpec, FACE_NAMES};
use crate::mesh::Mesh;
use crate::semidiscretization::{Numerics, Semidiscretization};
use crate::state::{State, Workspace};
use crate::time::{rk2_step, TimeStepping};
use serde::Serialize;
use std::time::Instant;

/// One measurement.
#[derive(Debug, Clone, Serialize)]
pub struct Measurement {
    pub threads: usize,
    pub seconds_per_step: f64,
    pub node_steps_per_second: f64,
    pub node_steps_per_second_per_core: f64,
    /// Seconds of one residual spent in each pass (primitives, gradients, edge fluxes + gather +
    /// boundary).
    pub residual_split_seconds: std::collections::BTreeMap<String, f64>,
}

/// The bench report.
#[derive(Debug, Clone, Serialize)]
pub struct BenchReport {
    pub scheme: &'static str,
    pub nodes: usize,
    pub edges: usize,
    pub cells: usize,
    pub steps: usize,
    pub mesh_build_seconds: f64,
    pub bytes_per_node: f64,
    pub measurements: Vec<Measurement>,
}

/// Runs the bench on about `nodes` nodes for `steps` RK2 steps per thread count.
pub fn run(nodes: usize, steps: usize) -> anyhow::Result<BenchReport> {
    let n = ((nodes as f64).cbrt().round() as usize).max(3) - 1;
    let start = Instant::now();
    let mesh = Mesh::build(BoxSpec::uniform([0.0; 3], [1.0; 3], [n, n, n], BoxCells::Tet).raw()?)?;
    let mesh_build_seconds = start.elapsed().as_secs_f64();
    let eos = Eos::PerfectGas { gamma: 1.4 };
    let free = [1.0, 0.3, 0.1, 0.0, 1.0];
    let bcs: Vec<(String, BoundaryCondition)> = FACE_NAMES
        .iter()
        .map(|f| (f.to_string(), BoundaryCondition::FarField { state: free }))
        .collect();
    let semi = Semidiscretization::new(mesh, eos, Numerics::default(), &bcs)?;
    let initial = State {
        cons: semi
            .mesh
            .coords
            .iter()
            .map(|x| {
                let s = (6.0 * x[0]).sin() * (5.0 * x[1]).cos() * (4.0 * x[2] + 1.0).sin();
                eos.prim_to_cons(&[1.0 + 0.2 * s, 0.3 + 0.1 * s, 0.1, 0.05 * s, 1.0 + 0.3 * s])
            })
            .collect(),
    };
    let mut measurements = Vec::new();
    let mut bytes = 0;
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build()?;
        let m = pool.install(|| -> anyhow::Result<Measurement> {
            let mut ws = Workspace::new(semi.mesh.n_nodes(), semi.mesh.n_edges());
            let mut state = initial.clone();
            // Warm up, then time.
            rk2_step(&semi, &mut state, &mut ws, TimeStepping::Global { cfl: 0.9 }, 1.0)?;
            let start = Instant::now();
            for _ in 0..steps {
                rk2_step(&semi, &mut state, &mut ws, TimeStepping::Global { cfl: 0.9 }, 1.0)?;
            }
            let per_step = start.elapsed().as_secs_f64() / steps as f64;
            let mut split = std::collections::BTreeMap::new();
            let reps = 3;
            let t0 = Instant::now();
            for _ in 0..reps {
                semi.primitives(&state.cons, &mut ws)?;
            }
            split.insert("primitives".to_string(), t0.elapsed().as_secs_f64() / reps as f64);
            let t0 = Instant::now();
            for _ in 0..reps {
                semi.gradient.compute(&semi.mesh, &ws.prim, &mut ws.grad);
            }
            split.insert("gradients".to_string(), t0.elapsed().as_secs_f64() / reps as f64);
            let t0 = Instant::now();
            for _ in 0..reps {
                semi.residual_from_primitives(&mut ws)?;
            }
            let full = t0.elapsed().as_secs_f64() / reps as f64;
            split.insert("fluxes_gather_boundary".to_string(), full - split["gradients"]);
            bytes = semi.mesh.memory_bytes()
                + semi.gradient.memory_bytes()
                + ws.memory_bytes()
                + state.cons.len() * 40;
            let rate = semi.mesh.n_nodes() as f64 / per_step;
            Ok(Measurement {
                threads,
                seconds_per_step: per_step,
                node_steps_per_second: rate,
                node_steps_per_second_per_core: rate / threads as f64,
                residual_split_seconds: split,
            })
        })?;
        measurements.push(m);
    }
    Ok(BenchReport {
        scheme: "RK2 (TVD) + MUSCL (van Albada, LSQ gradients) + Roe, perfect gas, tets",
        nodes: semi.mesh.n_nodes(),
        edges: semi.mesh.n_edges(),
        cells: semi.mesh.cells.len(),
        steps,
        mesh_build_seconds,
        bytes_per_node: bytes as f64 / semi.mesh.n_nodes() as f64,
        measurements,
    })
}
