//! The level-set row of `fluid-solver bench`: `cases/underwater-bubble` (a gas sphere in water,
//! octant of a ball meshed by [`crate::mesh::octant`], two materials, the level set advected and reinitialised every 10
//! steps, the ghost-fluid fluxes at the interface) set up by [`crate::setup::problem`] from the
//! case file itself, resized to about `nodes` nodes; node-steps per second per core of
//! [`crate::levelset::LevelSet::step`] (flow, `φ`, new materials and their ghost states, the layout rebuilt when a
//! node changes fluid, the reinitialisations) from the start of the run, and the bytes per node
//! of everything the run holds.

use crate::bench::median;
use crate::levelset::LevelSetWorkspace;
use crate::mesh::octant::OctantSpec;
use crate::setup::{self, Mode};
use crate::state::Workspace;
use interface_protocol::case::Case;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;

/// The case file, compiled in so the bench runs from any folder.
const CASE: &str = include_str!("../../cases/underwater-bubble/case.toml");

/// One thread count's measurement.
#[derive(Debug, Clone, Serialize)]
pub struct BubbleMeasurement {
    pub threads: usize,
    /// Median over the timed steps.
    pub seconds_per_step: f64,
    pub seconds_per_step_mean: f64,
    pub node_steps_per_second: f64,
    pub node_steps_per_second_per_core: f64,
    /// Nodes that changed fluid over the timed steps.
    pub material_changes: usize,
}

/// The level-set row.
#[derive(Debug, Clone, Serialize)]
pub struct BubbleRow {
    pub scheme: &'static str,
    pub nodes: usize,
    pub edges: usize,
    /// Edges between the two fluids at the start.
    pub interface_edges: usize,
    pub setup_seconds: f64,
    pub steps: usize,
    pub bytes_per_node: f64,
    pub bytes_per_node_split: BTreeMap<String, f64>,
    pub measurements: Vec<BubbleMeasurement>,
}

/// Runs the row on at least `nodes` nodes (the case's octant mesh with the fewest core cells per
/// edge, an even count, that give them) for `steps` steps after one warm-up step, from the
/// initial state, with each count of `threads`.
pub fn run(nodes: usize, steps: usize, threads: &[usize]) -> anyhow::Result<BubbleRow> {
    let path = Path::new("cases/underwater-bubble/case.toml");
    let case = Case::parse(CASE, path, &[])?;
    let o = case.fluid.as_ref().and_then(|f| f.mesh.as_ref()).and_then(|m| m.octant.clone());
    let o = o.ok_or_else(|| anyhow::anyhow!("{}: expected an octant mesh", path.display()))?;
    let spec = |cells: usize| OctantSpec { cells, ..OctantSpec::from(&o) };
    let mut cells = 2;
    while spec(cells).size().0 < nodes {
        cells += 2;
    }
    let overrides = [format!("fluid.mesh.octant.cells={cells}")];
    let case = Case::parse(CASE, path, &overrides)?;
    let start = Instant::now();
    let problem = setup::problem(&case, Mode::Alone)?;
    let setup_seconds = start.elapsed().as_secs_f64();
    let ls = problem.level_set.as_ref().expect("the case has a level set");
    let n_nodes = problem.semi.mesh.n_nodes();
    let interface_edges = problem.semi.special_edges().len();
    let mut measurements = Vec::new();
    let mut split = BTreeMap::new();
    for &t in threads {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(t).build()?;
        let m = pool.install(|| -> anyhow::Result<BubbleMeasurement> {
            let mut semi = problem.semi.clone();
            let mut state = problem.initial.clone();
            let mut ws = Workspace::new(n_nodes);
            let mut lws = LevelSetWorkspace::new(n_nodes);
            let mut step = |k: u64| {
                ls.step(&mut semi, &mut state, &mut ws, &mut lws, problem.stepping, 1.0, k)
            };
            step(1)?;
            let mut per_step = Vec::with_capacity(steps);
            let mut changes = 0;
            for k in 0..steps {
                let start = Instant::now();
                changes += step(k as u64 + 2)?.changed;
                per_step.push(start.elapsed().as_secs_f64());
            }
            let per_node = 1.0 / n_nodes as f64;
            let mut bytes = |k: &str, b: usize| split.insert(k.into(), b as f64 * per_node);
            bytes("mesh", semi.mesh.memory_bytes());
            bytes("gradient_operator", semi.gradient.memory_bytes());
            bytes("special_edges", semi.special_edges().memory_bytes());
            bytes("workspace", ws.memory_bytes());
            bytes("state", state.memory_bytes());
            bytes("level_set_gradient", ls.gradient.memory_bytes());
            bytes("level_set_adjacency", ls.adjacency.memory_bytes());
            bytes("level_set_workspace", lws.memory_bytes() + ls.open.len());
            let mean = per_step.iter().sum::<f64>() / steps as f64;
            let step = median(per_step);
            let rate = n_nodes as f64 / step;
            Ok(BubbleMeasurement {
                threads: t,
                seconds_per_step: step,
                seconds_per_step_mean: mean,
                node_steps_per_second: rate,
                node_steps_per_second_per_core: rate / t as f64,
                material_changes: changes,
            })
        })?;
        measurements.push(m);
    }
    Ok(BubbleRow {
        scheme: "cases/underwater-bubble: RK2 + MUSCL (van Albada) + Roe, stiffened-gas water | \
                 perfect-gas bubble, level set (advection, ghost states, reinit every 10), graded \
                 hexes",
        nodes: n_nodes,
        edges: problem.semi.mesh.n_edges(),
        interface_edges,
        setup_seconds,
        steps,
        bytes_per_node: split.values().sum(),
        bytes_per_node_split: split,
        measurements,
    })
}
