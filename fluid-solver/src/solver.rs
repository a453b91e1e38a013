//! The stand-alone run loop (DESIGN §7): march a case to its end time with RK2, writing probes,
//! lines, the field time series, checkpoints and `run.json`; restart from a checkpoint; stop at
//! the first invalid or non-finite state naming node, time and values, keeping the last good
//! checkpoint.
//!
//! A restarted run is bitwise identical to an uninterrupted one: the state is the conserved
//! array plus `(step, t)`, and the time step depends only on them and on `t_end`.

use crate::output;
use crate::probes::{nearest_node, Line};
use crate::semidiscretization::Semidiscretization;
use crate::setup::{self, Problem};
use crate::state::{State, Workspace};
use crate::time::rk2_step;
use anyhow::Context;
use interface_protocol::case::Case;
use interface_protocol::io::checkpoint::{self, Checkpoint};
use interface_protocol::io::finite::{check_finite, Entity};
use interface_protocol::io::outdir::{OutputDir, Policy};
use interface_protocol::io::probes::{write_line_sample, ProbeWriter};
use interface_protocol::io::progress::Progress;
use interface_protocol::io::report::{self, bucket, RunReport, Timers};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Checkpoint part name of the fluid.
pub const CHECKPOINT_PART: &str = "fluid";

/// Command-line options of `fluid-solver run`.
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    pub out: PathBuf,
    pub quiet: bool,
    /// A previous run's output folder to continue from (its newest complete checkpoint).
    pub restart: Option<PathBuf>,
    /// Overwrite a previous run's files in `out`.
    pub force: bool,
}

/// How a run ended.
#[derive(Debug, Clone, PartialEq)]
pub struct RunSummary {
    pub steps: u64,
    pub time: f64,
    pub nodes: usize,
}

/// Reads the conserved state of the newest checkpoint under `run_dir/checkpoints`.
pub fn read_checkpoint(run_dir: &Path, n_nodes: usize) -> anyhow::Result<(State, u64, f64)> {
    let dir = run_dir.join("checkpoints");
    let found = checkpoint::latest(&dir, &[CHECKPOINT_PART])?
        .with_context(|| format!("no complete fluid checkpoint in {}", dir.display()))?;
    let ck = Checkpoint::read(&dir, &found.tag, CHECKPOINT_PART)?;
    let cons = ck.f64_n::<5>("cons")?;
    anyhow::ensure!(
        cons.len() == n_nodes,
        "checkpoint {} holds {} nodes, but the case's mesh has {n_nodes}",
        found.dir.display(),
        cons.len()
    );
    Ok((State { cons }, ck.step, ck.time))
}

fn write_checkpoint(out: &OutputDir, state: &State, step: u64, time: f64) -> anyhow::Result<()> {
    let mut ck = Checkpoint::new(step, time);
    ck.put_f64_n("cons", &state.cons)?;
    ck.write(&out.checkpoints()?, &checkpoint::tag_for_step(step), CHECKPOINT_PART)?;
    Ok(())
}

/// Runs a case alone. `case_text` is echoed into `run.json`.
pub fn run(case: &Case, case_text: &str, opts: &RunOptions) -> anyhow::Result<RunSummary> {
    let wall = Instant::now();
    let problem = setup::problem(case)?;
    let out = OutputDir::create(&opts.out, Policy::from_force(opts.force))?;
    let mut timers = Timers::new();
    let Problem { semi, initial, stepping, t_end, max_steps, probes, lines } = problem;
    let (mut state, mut step, mut t) = match &opts.restart {
        Some(dir) => read_checkpoint(dir, semi.mesh.n_nodes())?,
        None => (initial, 0, 0.0),
    };
    let every = &case.output;
    let mut ws = Workspace::new(semi.mesh.n_nodes(), semi.mesh.n_edges());
    semi.primitives(&state.cons, &mut ws)?;

    let mut fields = output::create_writer(out.path(), &semi.mesh)?;
    let names: Vec<&str> = probes.iter().map(|p| p.name.as_str()).collect();
    let probe_nodes: Vec<usize> = probes.iter().map(|p| nearest_node(&semi.mesh, p.at)).collect();
    let mut probe_csv = ProbeWriter::fluid(out.path(), &names)?;
    let mut lines: Vec<Line> = lines
        .iter()
        .map(|l| Line::new(&semi.mesh, &l.name, l.from, l.to, l.points, &l.times))
        .collect();
    let write_probes = |csv: &mut ProbeWriter, t: f64, prim: &[[f64; 5]]| {
        let row: Vec<f64> = probe_nodes.iter().flat_map(|&i| prim[i]).collect();
        csv.write_row(t, &row)
    };
    write_probes(&mut probe_csv, t, &ws.prim)?;
    output::write_fields(&mut fields, &semi.eos, t, &ws.prim)?;

    let mut bar = Progress::new(t_end, opts.quiet);
    let mut status = Ok(());
    let mut last_fields_step = step;
    while t < t_end * (1.0 - 1e-12) && max_steps.is_none_or(|m| step < m) {
        let start = Instant::now();
        let result = rk2_step(&semi, &mut state, &mut ws, stepping, t_end - t);
        timers.add_since(bucket::RESIDUAL, start);
        let dt = match result {
            Ok(dt) => dt,
            Err(e) => {
                // The state is unchanged by a failed step: keep it as the last good checkpoint.
                write_checkpoint(&out, &state, step, t)?;
                status = Err(format!("stopped at step {}, t = {t:e}: {e}", step + 1));
                break;
            }
        };
        if let Err(e) =
            check_finite("conserved [ρ, ρu, ρv, ρw, E]", Entity::Node, t + dt, &state.cons[..])
        {
            let node = e.index;
            status = Err(format!(
                "stopped at step {}: {e} (x = {:?}, conserved = {:?}); the last good checkpoint is kept",
                step + 1,
                semi.mesh.coords[node],
                state.cons[node]
            ));
            break;
        }
        t += dt;
        step += 1;
        let start = Instant::now();
        let want_fields = every.fields_every > 0 && step % every.fields_every == 0;
        let want_lines = lines.iter().any(|l| l.pending.first().is_some_and(|&lt| t >= lt));
        if step % every.probes_every == 0 || want_fields || want_lines {
            semi.primitives(&state.cons, &mut ws)?;
        }
        if step % every.probes_every == 0 {
            write_probes(&mut probe_csv, t, &ws.prim)?;
        }
        if want_fields {
            output::write_fields(&mut fields, &semi.eos, t, &ws.prim)?;
            last_fields_step = step;
        }
        for line in &mut lines {
            if line.pending.first().is_some_and(|&lt| t >= lt) {
                while line.pending.first().is_some_and(|&lt| t >= lt) {
                    line.pending.remove(0);
                }
                let name = format!("{}_t{t:.6e}", line.name);
                write_line_sample(&out.lines()?, &name, &line.sample(&ws.prim))?;
            }
        }
        if every.checkpoint_every > 0 && step % every.checkpoint_every == 0 {
            write_checkpoint(&out, &state, step, t)?;
        }
        timers.add_since(bucket::OUTPUT, start);
        bar.update(step, t, dt);
    }
    bar.finish();
    if status.is_ok() {
        let start = Instant::now();
        semi.primitives(&state.cons, &mut ws)?;
        if last_fields_step != step {
            output::write_fields(&mut fields, &semi.eos, t, &ws.prim)?;
        }
        for line in &lines {
            write_line_sample(&out.lines()?, &line.name, &line.sample(&ws.prim))?;
        }
        write_checkpoint(&out, &state, step, t)?;
        timers.add_since(bucket::OUTPUT, start);
    }
    probe_csv.flush()?;
    fields.finish()?;
    write_report(case, case_text, &out, &semi, &status, step, t, &timers, wall)?;
    match status {
        Ok(()) => Ok(RunSummary { steps: step, time: t, nodes: semi.mesh.n_nodes() }),
        Err(e) => Err(anyhow::anyhow!(e)),
    }
}

fn write_report(
    case: &Case,
    case_text: &str,
    out: &OutputDir,
    semi: &Semidiscretization,
    status: &Result<(), String>,
    steps: u64,
    time: f64,
    timers: &Timers,
    wall: Instant,
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
        ]
        .into(),
        wall_seconds: wall.elapsed().as_secs_f64(),
        timings: [("fluid".to_string(), timers.seconds())].into(),
    };
    report.write(&out.run_json())?;
    Ok(())
}
