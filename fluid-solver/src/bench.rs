//! `fluid-solver bench`: node-steps per second per core of RK2 + MUSCL (van Albada) + Roe on a
//! perfect gas, on a box of tets with a non-uniform state, with 1 and 2 threads; memory per
//! node (everything the solver holds: mesh, dual, gradient operator, state, scratch and stage
//! arrays); the split of one step into its passes; and the cost of the edge loop alone per edge.
//! Then the same for two materials on the same box (`two_material`: water | air at rest, the
//! edge loop over the gaps between the interface edges with per-node EOS, the two-phase flux on
//! them, gradients masked at the interface).
//! A node-step is one full RK2 step (two residuals) of one node (DESIGN §8).
//!
//! `--dump-edges FILE` also writes the arrays of the edge loop in the raw format read by the C
//! reference loop `fluid-solver/bench/edge_loop.c` (see `fluid-solver/bench/run-c-reference.sh`):
//! all little-endian, in this order
//! - header: 8 bytes magic `FIVEREDG`, `u64` nodes `N`, `u64` edges `E`, `f64` γ;
//! - `E x [u32; 2]` edges `(i, j)`; `E x [f64; 3]` area normals `ν_ij`;
//! - `N x [f64; 3]` coordinates; `N x [f64; 5]` primitives `[ρ, u, v, w, p]`;
//! - `N x [[f64; 3]; 5]` primitive gradients;
//! - `N x [f64; 5]` the edge residual `Σ_j ±F_ij` this solver computes from them (no boundary
//!   fluxes), for checking the C loop.

use crate::bc::BoundaryCondition;
use crate::eos::Eos;
use crate::mesh::boxmesh::{BoxCells, BoxSpec, FACE_NAMES};
use crate::mesh::Mesh;
use crate::semidiscretization::{Numerics, Semidiscretization};
use crate::state::{MaterialId, State, Workspace};
use crate::time::{rk2_step, TimeStepping};
use serde::Serialize;
use std::collections::BTreeMap;
use std::io::Write;
use std::path::Path;
use std::time::Instant;

/// One measurement.
#[derive(Debug, Clone, Serialize)]
pub struct Measurement {
    pub threads: usize,
    /// Median over the timed steps.
    pub seconds_per_step: f64,
    /// Mean over the timed steps.
    pub seconds_per_step_mean: f64,
    /// From the median step.
    pub node_steps_per_second: f64,
    pub node_steps_per_second_per_core: f64,
    /// Seconds of each pass of one residual evaluation (medians): primitives, time steps (once
    /// per RK2 step), gradients, edge fluxes + boundary fluxes (one pass).
    pub residual_split_seconds: BTreeMap<String, f64>,
    /// The edge flux loop alone (MUSCL + limiter + Roe + adding to both nodes), per edge.
    pub edge_loop_ns_per_edge: f64,
}

/// The bench report.
#[derive(Debug, Clone, Serialize)]
pub struct BenchReport {
    pub scheme: &'static str,
    pub nodes: usize,
    pub edges: usize,
    pub cells: usize,
    pub edge_blocks: usize,
    pub steps: usize,
    pub mesh_build_seconds: f64,
    pub bytes_per_node: f64,
    /// Bytes per node of each part.
    pub bytes_per_node_split: BTreeMap<String, f64>,
    pub measurements: Vec<Measurement>,
    /// Node-steps per second with 2 threads over 1 thread (when both were measured).
    pub speedup_2_threads: Option<f64>,
    /// The same box with two fluids.
    pub two_material: TwoMaterial,
}

/// The two-material row of the bench.
#[derive(Debug, Clone, Serialize)]
pub struct TwoMaterial {
    pub scheme: &'static str,
    /// Edges between the two fluids (special edges of the blocks).
    pub special_edges: usize,
    pub bytes_per_node: f64,
    pub bytes_per_node_split: BTreeMap<String, f64>,
    pub measurements: Vec<Measurement>,
}

/// Median of a non-empty list.
pub(crate) fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// Median seconds of `reps` calls of `f`.
fn time_median(reps: usize, mut f: impl FnMut() -> anyhow::Result<()>) -> anyhow::Result<f64> {
    let mut t = Vec::with_capacity(reps);
    for _ in 0..reps {
        let start = Instant::now();
        f()?;
        t.push(start.elapsed().as_secs_f64());
    }
    Ok(median(t))
}

/// Runs the bench on about `nodes` nodes for `steps` RK2 steps with each thread count of
/// `threads`; with `dump_edges`, also writes the edge-loop arrays there (see the module docs).
pub fn run(
    nodes: usize,
    steps: usize,
    threads: &[usize],
    dump_edges: Option<&Path>,
) -> anyhow::Result<BenchReport> {
    anyhow::ensure!(steps > 0, "--steps must be at least 1");
    anyhow::ensure!(
        !threads.is_empty() && threads.iter().all(|&t| t > 0),
        "--threads must list thread counts of at least 1, e.g. 1,2"
    );
    let n = ((nodes as f64).cbrt().round() as usize).max(3) - 1;
    let start = Instant::now();
    let mesh = Mesh::build(BoxSpec::uniform([0.0; 3], [1.0; 3], [n, n, n], BoxCells::Tet).raw()?)?;
    let mesh_build_seconds = start.elapsed().as_secs_f64();
    let two_mesh = mesh.clone();
    let (semi, initial) = single_material(mesh)?;
    let single = measure(&semi, &initial, steps, threads, |ws| match dump_edges {
        Some(path) => dump(path, &semi, ws, GAMMA),
        None => Ok(()),
    })?;
    let n_nodes = semi.mesh.n_nodes();
    let rate_with =
        |t: usize| single.0.iter().find(|m| m.threads == t).map(|m| m.node_steps_per_second);
    let speedup_2_threads = rate_with(1).zip(rate_with(2)).map(|(one, two)| two / one);
    let edges = semi.mesh.n_edges();
    let (cells, edge_blocks) = (semi.mesh.cells.len(), semi.mesh.blocks.len());
    drop(semi);
    let two_material = two_material_row(two_mesh, steps, threads)?;
    Ok(BenchReport {
        scheme: "RK2 (TVD) + MUSCL (van Albada, LSQ gradients) + Roe, perfect gas, tets",
        nodes: n_nodes,
        edges,
        cells,
        edge_blocks,
        steps,
        mesh_build_seconds,
        bytes_per_node: single.1.values().sum::<f64>(),
        bytes_per_node_split: single.1,
        measurements: single.0,
        speedup_2_threads,
        two_material,
    })
}

/// γ of the single-material row's perfect gas.
const GAMMA: f64 = 1.4;
/// The far-field state `[ρ, u, v, w, p]` of the single-material box.
pub(crate) const FREE_STREAM: [f64; 5] = [1.0, 0.3, 0.1, 0.0, 1.0];

/// The single-material row's scheme and state on `mesh`: a perfect gas between far-field
/// boundaries, `[ρ, u, v, w, p] = [1 + 0.2s, 0.3 + 0.1s, 0.1, 0.05s, 1 + 0.3s]` with
/// `s = sin 6x cos 5y sin(4z + 1)`.
pub(crate) fn single_material(mesh: Mesh) -> anyhow::Result<(Semidiscretization, State)> {
    let eos = Eos::PerfectGas { gamma: GAMMA };
    let free = FREE_STREAM;
    let bcs: Vec<(String, BoundaryCondition)> = FACE_NAMES
        .iter()
        .map(|f| (f.to_string(), BoundaryCondition::FarField { state: free }))
        .collect();
    let semi = Semidiscretization::new(mesh, eos, Numerics::default(), &bcs)?;
    let initial = State::new(
        semi.mesh
            .coords
            .iter()
            .map(|x| {
                let s = (6.0 * x[0]).sin() * (5.0 * x[1]).cos() * (4.0 * x[2] + 1.0).sin();
                eos.prim_to_cons(&[1.0 + 0.2 * s, 0.3 + 0.1 * s, 0.1, 0.05 * s, 1.0 + 0.3 * s])
            })
            .collect(),
    );
    Ok((semi, initial))
}

/// The two-material row: the same box, water (stiffened gas, γ 4.4, p_c 6e8) for `x < 0.5` and
/// air (perfect gas, γ 1.4) beyond, at rest at equal pressure (1e5) between slip walls, so the
/// state stays exact and every step does the full work (MUSCL on the gaps with each edge's EOS
/// from the table, the two-phase flux on the interface edges).
fn two_material_row(mesh: Mesh, steps: usize, threads: &[usize]) -> anyhow::Result<TwoMaterial> {
    let table = vec![Eos::StiffenedGas { gamma: 4.4, p_c: 6e8 }, Eos::PerfectGas { gamma: 1.4 }];
    let material: Vec<MaterialId> = mesh.coords.iter().map(|x| u8::from(x[0] >= 0.5)).collect();
    let walls: Vec<(String, BoundaryCondition)> =
        FACE_NAMES.iter().map(|f| (f.to_string(), BoundaryCondition::SlipWall)).collect();
    let semi =
        Semidiscretization::with_materials(mesh, table, material, Numerics::default(), &walls)?;
    let rest = [[1000.0, 0.0, 0.0, 0.0, 1e5], [1.2, 0.0, 0.0, 0.0, 1e5]];
    let state = State {
        cons: semi
            .material()
            .iter()
            .map(|&m| semi.eos[m as usize].prim_to_cons(&rest[m as usize]))
            .collect(),
        material: semi.material().to_vec(),
        phi: Vec::new(),
    };
    let (measurements, mut split) = measure(&semi, &state, steps, threads, |_| Ok(()))?;
    let per_node = 1.0 / semi.mesh.n_nodes() as f64;
    split.insert("special_edges".into(), semi.special_edges().memory_bytes() as f64 * per_node);
    Ok(TwoMaterial {
        scheme: "as above, stiffened-gas water | perfect-gas air at rest, two-phase flux at the \
                 interface",
        special_edges: semi.special_edges().len(),
        bytes_per_node: split.values().sum(),
        bytes_per_node_split: split,
        measurements,
    })
}

/// Times `steps` RK2 steps of `initial` and the passes of one residual for each thread count;
/// `after` sees the workspace after the first count's passes. Returns the measurements and the
/// bytes per node of each part the solver holds.
fn measure(
    semi: &Semidiscretization,
    initial: &State,
    steps: usize,
    threads: &[usize],
    mut after: impl FnMut(&Workspace) -> anyhow::Result<()> + Send,
) -> anyhow::Result<(Vec<Measurement>, BTreeMap<String, f64>)> {
    let n_nodes = semi.mesh.n_nodes();
    let mut measurements = Vec::new();
    let mut split_bytes = BTreeMap::new();
    let mut first = true;
    for &threads in threads {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build()?;
        let m = pool.install(|| -> anyhow::Result<Measurement> {
            let mut ws = Workspace::new(n_nodes);
            let mut state = initial.clone();
            let stepping = TimeStepping::Global { cfl: 0.9 };
            // Warm up, then time each step.
            rk2_step(semi, &mut state, &mut ws, stepping, 1.0)?;
            let mut per_step = Vec::with_capacity(steps);
            for _ in 0..steps {
                let start = Instant::now();
                rk2_step(semi, &mut state, &mut ws, stepping, 1.0)?;
                per_step.push(start.elapsed().as_secs_f64());
            }
            let mean = per_step.iter().sum::<f64>() / steps as f64;
            let step = median(per_step);
            let reps = 5;
            let mut split = BTreeMap::new();
            let t = time_median(reps, || Ok(semi.primitives(&state.cons, &mut ws)?))?;
            split.insert("primitives".to_string(), t);
            let t = time_median(reps, || {
                semi.node_time_steps(&mut ws);
                Ok(())
            })?;
            split.insert("time_steps".to_string(), t);
            let t = time_median(reps, || {
                semi.gradient.compute(&semi.mesh, &ws.prim, &mut ws.grad);
                Ok(())
            })?;
            split.insert("gradients".to_string(), t);
            let full = time_median(reps, || Ok(semi.residual_from_primitives(&mut ws)?))?;
            split.insert("fluxes_and_boundary".to_string(), full - split["gradients"]);
            let edge_loop = time_median(reps, || Ok(semi.edge_residual(&mut ws)?))?;
            if first {
                after(&ws)?;
                first = false;
            }
            let per_node = 1.0 / n_nodes as f64;
            let mut bytes = |k: &str, b: usize| split_bytes.insert(k.into(), b as f64 * per_node);
            bytes("mesh", semi.mesh.memory_bytes());
            bytes("gradient_operator", semi.gradient.memory_bytes());
            bytes("workspace", ws.memory_bytes());
            bytes("state", state.memory_bytes());
            let rate = n_nodes as f64 / step;
            Ok(Measurement {
                threads,
                seconds_per_step: step,
                seconds_per_step_mean: mean,
                node_steps_per_second: rate,
                node_steps_per_second_per_core: rate / threads as f64,
                residual_split_seconds: split,
                edge_loop_ns_per_edge: edge_loop / semi.mesh.n_edges() as f64 * 1e9,
            })
        })?;
        measurements.push(m);
    }
    Ok((measurements, split_bytes))
}

/// Writes the edge-loop arrays and the edge residual in `ws` (see the module docs).
fn dump(path: &Path, semi: &Semidiscretization, ws: &Workspace, gamma: f64) -> anyhow::Result<()> {
    let mesh = &semi.mesh;
    let mut out = std::io::BufWriter::new(std::fs::File::create(path)?);
    out.write_all(b"FIVEREDG")?;
    out.write_all(&(mesh.n_nodes() as u64).to_le_bytes())?;
    out.write_all(&(mesh.n_edges() as u64).to_le_bytes())?;
    out.write_all(&gamma.to_le_bytes())?;
    for e in &mesh.edges {
        for v in e {
            out.write_all(&v.to_le_bytes())?;
        }
    }
    let mut put = |values: &mut dyn Iterator<Item = f64>| -> std::io::Result<()> {
        for v in values {
            out.write_all(&v.to_le_bytes())?;
        }
        Ok(())
    };
    put(&mut mesh.edge_normals.iter().flatten().copied())?;
    put(&mut mesh.coords.iter().flatten().copied())?;
    put(&mut ws.prim.iter().flatten().copied())?;
    put(&mut ws.grad.iter().flatten().flatten().copied())?;
    put(&mut ws.residual.iter().flatten().copied())?;
    out.flush()?;
    Ok(())
}
