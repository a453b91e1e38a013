//! `run.json` of a fluid-alone run (DESIGN §7): the case echo, versions, counts, the wall-time
//! buckets and, with an embedded surface, its `surface` section ([`SurfaceReport`]).

use crate::embedded::advance::{active_mass, EmbeddedRun};
use crate::embedded::status::NodeStatus;
use crate::semidiscretization::Semidiscretization;
use crate::state::State;
use interface_protocol::case::Case;
use interface_protocol::io::outdir::OutputDir;
use interface_protocol::io::report::{self, RunReport, SurfaceReport, Timers};
use std::time::Instant;

/// `run.json`'s `surface` section of the embedded surface `e` ([`SurfaceReport`]) with the run's
/// state `state` (the masses of a run that took no step are the current one).
pub(crate) fn surface_report(
    e: &EmbeddedRun,
    semi: &Semidiscretization,
    state: &State,
) -> SurfaceReport {
    let t = &e.tracker;
    let count = |s: NodeStatus| t.sides.status.iter().filter(|&&x| x == s).count() as u64;
    let now = active_mass(semi, &state.cons, &t.active);
    SurfaceReport {
        tracking_seconds: e.tracking_s,
        wall_flux_seconds: e.wall_flux_s,
        loads_seconds: e.loads_s,
        cut_edges: t.cuts.cuts.len() as u64,
        active_nodes: count(NodeStatus::Active),
        occluded_nodes: count(NodeStatus::Occluded),
        inactive_nodes: count(NodeStatus::Inactive),
        mass_start: e.mass.start.unwrap_or(now),
        mass_end: now,
        boundary_outflow: e.mass.outflow,
        mass_change: e.mass.change,
    }
}

#[allow(clippy::too_many_arguments)]
pub(crate) fn write_report(
    case: &Case,
    case_text: &str,
    out: &OutputDir,
    semi: &Semidiscretization,
    status: &Result<(), String>,
    steps: u64,
    time: f64,
    timers: &Timers,
    wall: Instant,
    cavitation_clips: u64,
    surface: Option<SurfaceReport>,
) -> anyhow::Result<()> {
    let mut versions = report::versions();
    versions.insert("fluid-solver".into(), env!("CARGO_PKG_VERSION").into());
    let report = RunReport {
        case_file: case.source.path.display().to_string(),
        case: report::case_echo(case_text).unwrap_or(serde_json::Value::Null),
        versions,
        status: match status {
            Ok(()) => "completed".into(),
            Err(e) => e.clone(),
        },
        steps,
        final_time: time,
        counts: [
            ("nodes".to_string(), semi.mesh.n_nodes() as u64),
            ("edges".to_string(), semi.mesh.n_edges() as u64),
            ("cells".to_string(), semi.mesh.cells.len() as u64),
            ("cavitation_clips".to_string(), cavitation_clips),
        ]
        .into(),
        wall_seconds: wall.elapsed().as_secs_f64(),
        timings: [("fluid".to_string(), timers.seconds())].into(),
        surface,
    };
    report.write(&out.run_json())?;
    Ok(())
}
