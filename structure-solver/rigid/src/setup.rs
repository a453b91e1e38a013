//! Everything `run` does before the first step, shared with `check`: the body of the case's
//! `[structure.rigid]`, the scheme's settings, the probe name and the stable step. Touches no
//! file.

use crate::model::Body;
use interface_protocol::case::{Case, Scheme};
use interface_protocol::io::probes::check_probe_name;

/// A case made ready to run.
#[derive(Debug, Clone)]
pub struct Setup {
    pub body: Body,
    pub scheme: Scheme,
    /// Coupling step Δt [s].
    pub dt: f64,
    pub t_end: f64,
    pub n_steps: u64,
    pub probes_every: u64,
}

impl Setup {
    /// The setup of `case`, or an error naming the file and the field.
    pub fn new(case: &Case) -> Result<Setup, String> {
        let file = case.source.path.display();
        let rigid =
            case.structure.as_ref().and_then(|s| s.rigid.as_ref()).ok_or_else(|| {
                format!("{file}: rigid-structure needs a [structure.rigid] section")
            })?;
        let body = Body::new(rigid);
        check_probe_name(&body.probe)
            .map_err(|e| format!("{file}: field `structure.rigid.probe`: {e}"))?;
        let c = &case.coupling;
        Ok(Setup {
            body,
            scheme: c.scheme,
            dt: c.dt,
            t_end: c.t_end,
            n_steps: c.n_steps(),
            probes_every: case.output.probes_every,
        })
    }

    /// The stable coupling step of the scheme's structure integrator: 2/ω_max for the central
    /// differences of CSS and C0, unlimited for A6's implicit midpoint.
    pub fn dt_stable(&self) -> f64 {
        dt_stable(self.scheme, &self.body)
    }

    /// `coupling.dt` above the stable step, said so (`None` when it is stable).
    pub fn unstable_step_warning(&self) -> Option<String> {
        above_stable_step(self.dt, self.dt_stable(), &self.body)
            .map(|why| format!("coupling.dt = {} s: {why}", crate::finite::short(self.dt)))
    }

    /// The one-line summary of `check`.
    pub fn summary(&self, case: &Case) -> String {
        let b = &self.body;
        let dofs: Vec<&str> = (0..b.dofs.len()).map(|i| b.dof_name(i)).collect();
        let stable = self.dt_stable();
        let stable = if stable.is_finite() { format!("{stable:e} s") } else { "unlimited".into() };
        format!(
            "{}: ok: rigid body `{}`, {} DOF ({}), {} wet nodes, {} wet elements; {} dt {:e} s \
             (stable step {stable}), {} steps to t_end {:e} s",
            case.source.path.display(),
            b.probe,
            dofs.len(),
            dofs.join(", "),
            b.wet_nodes.len(),
            b.elements.len(),
            scheme_name(self.scheme),
            self.dt,
            self.n_steps,
            self.t_end
        )
    }
}

/// The scheme as the case file spells it.
fn scheme_name(scheme: Scheme) -> &'static str {
    match scheme {
        Scheme::Css => "CSS",
        Scheme::C0 => "C0",
        Scheme::A6 => "A6",
    }
}

/// The stable step of `scheme`'s structure integrator for `body`.
pub fn dt_stable(scheme: Scheme, body: &Body) -> f64 {
    match scheme {
        Scheme::A6 => f64::INFINITY,
        Scheme::Css | Scheme::C0 => body.dt_stable_explicit(),
    }
}

/// Why a step `dt` is unstable when it is above `dt_stable`, `None` otherwise.
pub fn above_stable_step(dt: f64, dt_stable: f64, body: &Body) -> Option<String> {
    (dt > dt_stable).then(|| {
        format!(
            "the step is above the stable step {} s of the rigid model (central differences: \
             dt <= 2/ω_max, ω_max = {} rad/s); lower coupling.dt",
            crate::finite::short(dt_stable),
            crate::finite::short(body.omega_max())
        )
    })
}
