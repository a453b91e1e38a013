//! `structure-solver run CASE`: a structure alone, from the `[structure]` section of a case
//! (DESIGN §7; the schema is documented in `interface_protocol::case::structure`): mesh and
//! sets, materials and parts, boundary conditions, loads with time curves, initial velocity,
//! and the analysis: central differences, Newmark, the implicit midpoint rule, or statics
//! (load steps or displacement control). Probes go to `structure_probes.csv` (static runs: the
//! time column holds the load factor), fields to `structure.xdmf`, the final cell fields to
//! `structure_cells.csv`.
//!
//! Every structure is one `assembly::FeModel`; BT4 and BLT3 shells are its explicit-only part
//! (`bt4` parts: BT4 on quadrilaterals, BLT3 on triangles). Central
//! differences scale the shells' rotary inertia (`RotaryInertia::Scaled`), implicit and static
//! runs keep the physical one. What happens before the first step is [`crate::prepare`]'s,
//! shared with `check`.
//!
//! Files by job: `alone_output` (probes, fields and progress per step), `checkpoint` (restart
//! state in and out), `dynamic` (the time loop of central differences and the implicit
//! schemes), `statics_driver` (load steps, displacement control, arc length).

mod alone_output;
mod checkpoint;
mod dynamic;
mod statics_driver;

use std::path::PathBuf;
use std::time::{Instant, SystemTime};

use anyhow::bail;
use interface_protocol::case::{Case, Integrator};
use interface_protocol::io::outdir::{default_run_dir, OutputDir, Policy};
use interface_protocol::io::probes::ProbeWriter;
use interface_protocol::io::progress::Progress;
use interface_protocol::io::report::{case_echo, versions, RunReport, Timers};

use crate::build::{section, Structure};
use crate::output::{write_cell_table, FieldOutput};
use crate::prepare::{prepare_alone, Alone};
use alone_output::AloneOutput;
use checkpoint::read_checkpoint;
use dynamic::Dynamic;
use statics_driver::run_static;

/// Options of `run`.
#[derive(Debug, Clone)]
pub struct RunOptions {
    pub case: PathBuf,
    pub out: Option<PathBuf>,
    pub set: Vec<String>,
    pub quiet: bool,
    /// Reuse an output folder that holds a previous run (`--force`).
    pub force: bool,
    /// Resume from the newest checkpoint in this run folder.
    pub restart: Option<PathBuf>,
}

/// What a run did.
#[derive(Debug, Clone)]
pub struct RunSummary {
    pub steps: u64,
    pub t: f64,
    pub dt: f64,
    pub out: PathBuf,
}

/// Where a run has got to: steps completed and the time (load factor) of the last good state.
#[derive(Debug, Clone, Copy)]
struct Reached {
    steps: u64,
    t: f64,
}

/// Runs a case alone. The output folder follows the one rule of every binary: a folder that
/// holds a run is refused unless `--force`; a restart from the same folder under `--force`
/// continues that run in place (its checkpoints stay, [`Policy::alone`]). Every step is checked finite before anything is written;
/// `run.json` records how the run ended, failed runs included.
pub fn run(opts: &RunOptions) -> anyhow::Result<RunSummary> {
    let case = Case::load(&opts.case, &opts.set)?;
    let file = case.source.path.clone();
    let s = section(&case)?;
    let alone = prepare_alone(&case)?;
    let statics = alone.integrator == Integrator::Static;
    if statics && opts.restart.is_some() {
        bail!("--restart applies to dynamic runs; a static run starts from its unloaded state");
    }
    let Alone { structure, integrator, t_end, stable, adaptive, probe_nodes, .. } = alone;
    let Structure { mesh, mut model, v0, cells, .. } = structure;
    let n = mesh.nodes.len();

    let out = opts.out.clone().unwrap_or_else(|| default_run_dir(&opts.case, SystemTime::now()));
    // Read the checkpoint before the output folder is made: it may be the same folder.
    let resume = match &opts.restart {
        Some(from) => Some(read_checkpoint(from, &mut model)?),
        None => None,
    };
    let policy = Policy::alone(opts.force, opts.restart.as_deref(), &out);
    let dir = OutputDir::create(&out, policy)?;
    let names: Vec<&str> = s.probes.iter().map(|p| p.name.as_str()).collect();
    let started = Instant::now();
    // Static steps see the model through `dyn Model` only: nodal fields.
    let field_cells = if statics { None } else { Some(cells.clone()) };
    let mut output = AloneOutput {
        probe_nodes,
        probes: ProbeWriter::structure(dir.path(), &names)?,
        probes_every: s.output_every.unwrap_or(1).max(1),
        fields: FieldOutput::create(dir.path(), &mesh, field_cells)?,
        fields_every: case.output.fields_every,
        disp: vec![[0.0; 3]; n],
        vel: vec![[0.0; 3]; n],
        bar: Progress::new(t_end, opts.quiet),
    };
    let mut timers = Timers::new();
    let start = resume
        .as_ref()
        .map_or(Reached { steps: 0, t: 0.0 }, |r| Reached { steps: r.step, t: r.dynamics.t });
    let mut reached = start;
    let dt = resume.as_ref().map_or(alone.dt, |r| r.dt);
    let result = match integrator {
        Integrator::Static => {
            run_static(s, &case, &mesh, &mut model, t_end, &mut output, &mut timers).map(|done| {
                reached = Reached { steps: done.len() as u64, t: done.last().map_or(0.0, |c| c.t) };
            })
        }
        _ => {
            let mut run = Dynamic {
                mesh: &mesh,
                dir: &dir,
                checkpoint_every: case.output.checkpoint_every,
                t_end,
                dt,
                stable,
                adaptive,
                output: &mut output,
                timers: &mut timers,
                reached: &mut reached,
            };
            run.integrate(&mut model, integrator, v0, resume)
        }
    };
    output.probes.flush()?;
    output.fields.finish()?;
    output.bar.finish();
    if result.is_ok() {
        write_cell_table(&dir.path().join("structure_cells.csv"), &mesh, &model, &cells)?;
    }
    let report = RunReport {
        case_file: file.display().to_string(),
        case: std::fs::read_to_string(&file)
            .ok()
            .and_then(|text| case_echo(&text).ok())
            .unwrap_or_default(),
        versions: {
            let mut v = versions();
            v.insert("structure-solver".into(), env!("CARGO_PKG_VERSION").into());
            v
        },
        status: match &result {
            Ok(()) => "completed".into(),
            Err(e) => format!("{e:#}"),
        },
        steps: reached.steps,
        final_time: reached.t,
        counts: [("nodes", n as u64), ("cells", mesh.cells.len() as u64)]
            .into_iter()
            .map(|(k, v)| (k.to_string(), v))
            .collect(),
        wall_seconds: started.elapsed().as_secs_f64(),
        timings: [("structure".to_string(), timers.seconds())].into_iter().collect(),
        surface: None,
    };
    report.write(&dir.run_json())?;
    result?;
    let steps = reached.steps;
    let dt = if statics { t_end / steps.max(1) as f64 } else { dt };
    if !opts.quiet {
        let what = if statics { "load steps to load factor" } else { "steps to t =" };
        eprintln!(
            "structure-solver: {steps} {what} {t_end} (step {dt:.3e}); outputs in {}",
            out.display()
        );
    }
    Ok(RunSummary { steps, t: t_end, dt, out })
}
