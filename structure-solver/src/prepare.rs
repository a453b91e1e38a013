//! Everything a run alone does before its first step, in one function that `run` and `check`
//! both call so they cannot drift: the case's structure built and checked ([`build`]: mesh,
//! sets, materials, parts, BCs, loads), the analysis settings, the stable step of central
//! differences, the step count (capped at `resources::MAX_STEPS`) and the probe nodes.

use anyhow::bail;
use interface_protocol::case::{Case, Integrator};
use interface_protocol::resources::step_count;

use crate::assembly::RotaryInertia;
use crate::build::{build, field_error, need, section, Structure};
use crate::model::Model;
use crate::time::{critical_dt, StableStep};

/// A case ready to run alone.
pub struct Alone {
    pub structure: Structure,
    pub integrator: Integrator,
    /// End time (static: the final load factor).
    pub t_end: f64,
    /// The time step (static: the load factor of one step).
    pub dt: f64,
    /// The stable step of central differences (the smaller of the element bound and the power
    /// iteration of `time::critical`); `None` for the other integrators.
    pub stable: Option<f64>,
    /// Central differences without `structure.dt`: the step recomputed every step from the
    /// element bound at the current configuration (`safety` stated in the case, 0.8 else).
    pub adaptive: Option<StableStep>,
    /// Steps to `t_end`.
    pub steps: u64,
    /// The node of each `[[structure.probes]]`.
    pub probe_nodes: Vec<usize>,
}

/// `"; dt = X is above the stable step Y ..."` when the step `dt` exceeds the stable one.
pub fn unstable_note(stable: Option<f64>, dt: f64) -> String {
    match stable {
        Some(stable) if dt > stable => format!(
            "; dt = {dt:.3e} s is above the stable step {stable:.3e} s of central differences: \
             lower `structure.dt`, or leave it out to take `safety` x the stable step"
        ),
        _ => String::new(),
    }
}

/// Builds and checks `case` for a run alone.
pub fn prepare_alone(case: &Case) -> anyhow::Result<Alone> {
    let file = case.source.path.clone();
    let s = section(case)?;
    let integrator = s.integrator();
    let rotary = if integrator == Integrator::CentralDifference {
        RotaryInertia::Scaled
    } else {
        RotaryInertia::Physical
    };
    let mut structure = build(case, rotary)?;
    let statics = integrator == Integrator::Static;
    let t_end = match (statics, s.t_end) {
        (true, t) => t.unwrap_or(1.0),
        (false, _) => *need(&s.t_end, "t_end", case)?,
    };
    if !structure.model.has_tangent() && integrator != Integrator::CentralDifference {
        return Err(field_error(
            case,
            "structure.integrator",
            format!(
                "bt4 shells are explicit; use integrator = \"central_difference\", or mitc4/dkt \
                 shells with \"{}\"",
                integrator.name()
            ),
        ));
    }
    let mut adaptive = None;
    let (dt, stable) = match integrator {
        Integrator::CentralDifference => {
            let probe = 1e-9 * structure.length;
            let estimate = critical_dt(&mut structure.model, 0.0, 100, probe);
            let stable = estimate.stable(1.0);
            let safety = s.safety.unwrap_or(0.8);
            if s.dt.is_none() {
                adaptive = Some(StableStep::new(&estimate, safety));
            }
            let dt = s.dt.unwrap_or(safety * stable);
            if !(dt.is_finite() && dt > 0.0) {
                bail!("{}: no stable step could be estimated; give `structure.dt`", file.display());
            }
            if s.dt.is_some() && dt > stable {
                let note = unstable_note(Some(stable), dt);
                let warning = case.field_error("structure.dt", note.trim_start_matches("; "));
                eprintln!("structure-solver: warning: {warning}");
            }
            (dt, Some(stable))
        }
        Integrator::Newmark | Integrator::Midpoint => (*need(&s.dt, "dt", case)?, None),
        Integrator::Static => (t_end / s.steps.unwrap_or(10) as f64, None),
    };
    let steps = if statics {
        s.steps.unwrap_or(10) as u64
    } else {
        let keys = if s.dt.is_some() {
            "structure.t_end / structure.dt"
        } else {
            "structure.t_end / (structure.safety x the stable step)"
        };
        step_count(keys, t_end, dt).map_err(|e| field_error(case, "structure.t_end", e))?
    };
    let mesh = &structure.mesh;
    let probe_nodes = s.probes.iter().map(|p| mesh.nearest_node(p.point)).collect();
    Ok(Alone { structure, integrator, t_end, dt, stable, adaptive, steps, probe_nodes })
}
