//! A static run alone: load steps, displacement control or arc-length path following.

use anyhow::anyhow;
use interface_protocol::case::{Case, CurveName, CurveSpec, StructureSection};
use interface_protocol::io::report::{bucket, Timers};

use super::alone_output::AloneOutput;
use crate::assembly::FeModel;
use crate::build::{field_error, node_set};
use crate::mesh::Mesh;
use crate::model::Model;
use crate::statics::{
    arc_length, displacement_control, load_steps, ArcLengthSettings, Converged, NewtonSettings,
};

/// A static run: `steps` equal load increments to the load factor `t_end`, displacement
/// control of one dof to `control.value`, or arc-length path following to the load factor
/// `t_end` in at most `steps` steps (the last two scale the loads with the load factor λ).
/// Each converged step writes a probe row at its load factor.
pub(super) fn run_static(
    s: &StructureSection,
    case: &Case,
    mesh: &Mesh,
    model: &mut FeModel,
    t_end: f64,
    output: &mut AloneOutput,
    timers: &mut Timers,
) -> anyhow::Result<Vec<Converged>> {
    let steps = s.steps.unwrap_or(10);
    let defaults = NewtonSettings::default();
    let newton = s.newton.unwrap_or_default();
    let settings = NewtonSettings {
        tol: newton.tol.unwrap_or(defaults.tol),
        max_iter: newton.max_iter.unwrap_or(defaults.max_iter),
        max_cuts: newton.max_cuts.unwrap_or(defaults.max_cuts),
    };
    let zero = vec![0.0; model.n_dof()];
    output.write(&*model, None, &zero, (0, 0.0, 0.0), false)?;
    let mut k = 0u64;
    let mut failure = None;
    // `reached`: the arc length passed `t_end`; load steps and control end after `steps`.
    let mut on_step = |m: &mut dyn Model, c: Converged, reached: bool| {
        k += 1;
        let last = reached || k == steps as u64;
        if failure.is_none() {
            if let Err(e) = output.write(&*m, None, &zero, (k, c.t, c.t), last) {
                failure = Some(e);
            }
        }
    };
    let done = match (&s.control, &s.arc_length) {
        (None, Some(a)) => {
            linear_loads(s, case, "arc-length path following")?;
            let arc = ArcLengthSettings {
                newton: settings,
                initial: a.initial,
                min: a.min(),
                max: a.max(),
                desired_iterations: a.desired_iterations.unwrap_or(4),
                max_steps: steps,
                start: 0.0,
            };
            let mut reached = false;
            let done = timers.time(bucket::STRUCTURE, || {
                arc_length(model, &arc, |m, c| {
                    reached = c.t >= t_end;
                    on_step(m, c, reached);
                    !reached
                })
            })?;
            if !reached {
                return Err(field_error(
                    case,
                    "structure.steps",
                    format!(
                        "the arc length took {steps} steps to the load factor {:.4}, short of \
                         t_end = {t_end}; allow more steps or a longer arc",
                        done.last().map_or(0.0, |c| c.t)
                    ),
                ));
            }
            Ok(done)
        }
        (None, None) => {
            let targets: Vec<f64> = (1..=steps).map(|i| t_end * i as f64 / steps as f64).collect();
            timers.time(bucket::STRUCTURE, || {
                load_steps(model, &targets, &settings, |m, c| on_step(m, c, false))
            })
        }
        (Some(c), _) => {
            let node = match (&c.point, &c.set) {
                (Some(p), _) => mesh.nearest_node(*p),
                (None, Some(name)) => {
                    let nodes = node_set(mesh, name, "structure.control.set", case)?;
                    if nodes.len() != 1 {
                        return Err(field_error(
                            case,
                            "structure.control.set",
                            format!("expected a set of one node, \"{name}\" holds {}", nodes.len()),
                        ));
                    }
                    nodes[0]
                }
                (None, None) => unreachable!("validated: a point or a set"),
            };
            linear_loads(s, case, "displacement control")?;
            let targets: Vec<f64> =
                (1..=steps).map(|i| c.value * i as f64 / steps as f64).collect();
            let dof = 6 * node + c.dof.index();
            timers.time(bucket::STRUCTURE, || {
                displacement_control(model, dof, &targets, &settings, |m, c| on_step(m, c, false))
            })
        }
    };
    if let Some(e) = failure {
        return Err(e);
    }
    done.map_err(|e| anyhow!("{}: static solve: {e}", case.source.path.display()))
}

/// Path following scales the loads with the load factor: their curves must be linear and the
/// constrained dofs fixed.
pub(super) fn linear_loads(s: &StructureSection, case: &Case, what: &str) -> anyhow::Result<()> {
    for (k, l) in s.loads.iter().enumerate() {
        if !matches!(l.curve, None | Some(CurveSpec::Named(CurveName::Linear))) {
            return Err(field_error(
                case,
                &format!("structure.loads[{k}].curve"),
                format!("{what} scales the loads with the load factor; use \"linear\""),
            ));
        }
    }
    if let Some(k) = s.bc.iter().position(|b| b.prescribed.is_some()) {
        return Err(field_error(
            case,
            &format!("structure.bc[{k}].prescribed"),
            format!("{what} holds the constrained dofs fixed; use `fixed`"),
        ));
    }
    Ok(())
}
