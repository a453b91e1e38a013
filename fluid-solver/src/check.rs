//! `fluid-solver check CASE [--set KEY=VALUE]...`: everything `run` does before its first step
//! ([`setup::problem`]: the mesh and its checks, boundary names, EOS, initial and boundary states,
//! probes and lines, the CFL step and the caps on memory and steps), then a short summary. No
//! output folder is created or touched.
//!
//! A case with a `[structure]` section is checked as the fluid of a coupled run (it runs to
//! `coupling.t_end`, `[fluid.time]` unused), any other as a run alone.

use crate::setup::{self, Mode};
use crate::time::TimeStepping;
use interface_protocol::case::Case;
use std::fmt::Write;

/// The mode `check` checks a case for.
pub fn mode_of(case: &Case) -> Mode {
    if case.structure.is_some() {
        Mode::Coupled
    } else {
        Mode::Alone
    }
}

/// What `check` found: the summary (stdout) and the warnings a run would print (stderr).
#[derive(Debug, Clone)]
pub struct Checked {
    pub summary: String,
    pub warnings: Vec<String>,
}

/// Sets the case up as `run` would and returns its summary and warnings, or the first error.
pub fn check(case: &Case) -> anyhow::Result<Checked> {
    let mode = mode_of(case);
    let p = setup::problem(case, mode)?;
    let mesh = &p.semi.mesh;
    let mut out = String::new();
    let w = &mut out;
    let role = match mode {
        Mode::Alone => "the fluid alone",
        Mode::Coupled => "the fluid of a coupled run",
    };
    writeln!(w, "{}: ok, as {role}", case.source.path.display())?;
    writeln!(
        w,
        "  mesh      {} nodes, {} cells, {} edges; boundaries {}",
        mesh.n_nodes(),
        mesh.cells.len(),
        mesh.n_edges(),
        mesh.boundary_names().join(", ")
    )?;
    match &p.semi.eos[..] {
        [eos] => writeln!(w, "  eos       {eos:?}")?,
        table => {
            let n_of = |m: usize| p.initial.material.iter().filter(|&&k| k as usize == m).count();
            for (m, eos) in table.iter().enumerate() {
                let lead = if m == 0 { "fluids" } else { "" };
                writeln!(
                    w,
                    "  {lead:<9} material {m} = `{}` ({} nodes): {eos:?}",
                    p.fluid_names[m],
                    n_of(m)
                )?;
            }
        }
    }
    let (kind, cfl) = match p.stepping {
        TimeStepping::Global { cfl } => ("global", cfl),
        TimeStepping::Local { cfl } => ("local", cfl),
    };
    writeln!(
        w,
        "  time      to t = {:e}: first step {:.3e} ({kind} CFL {cfl}), about {:.0} steps",
        p.t_end,
        p.dt_initial,
        (p.t_end / p.dt_initial).ceil()
    )?;
    let samples: usize = p.placed.lines.iter().map(|l| l.points.len()).sum();
    writeln!(
        w,
        "  sampling  {} probes, {} lines ({samples} points), all inside the mesh",
        p.probes.len(),
        p.placed.lines.len()
    )?;
    writeln!(
        w,
        "  memory    about {}",
        interface_protocol::resources::human_bytes(crate::memory::estimate(
            mesh.n_nodes() as f64,
            mesh.cells.len() as f64
        ))
    )?;
    Ok(Checked { summary: out, warnings: p.warnings })
}
