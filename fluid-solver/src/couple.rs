//! The fluid as a coupling participant (DESIGN §1, §3; coupling-sequence): `fluid-solver run CASE
//! --couple RUN_ID --out DIR` joins the run, answers the launcher's commands through
//! `participant::serve` and advances [`FluidRun`] over each `Advance` interval in its own CFL
//! steps, the last one clipped to land on `t_to`.
//!
//! The embedded boundary (thesis Ch. 4-5) that turns a wet surface into fluid loads is not in this
//! build: the fluid accepts only a structure without a wet surface, for which the loads are the
//! empty slice, and refuses any other with `Failed { UNSUPPORTED }` at `Init`.

use crate::solver::{FluidRun, Mode, RunOptions};
use interface_protocol::case::Case;
use interface_protocol::endpoint::{FluidEndpoint, Timeouts};
use interface_protocol::handshake::HelloInfo;
use interface_protocol::messages::{Command, StepHeader};
use interface_protocol::participant::{failure_code, serve, Failure, Handler, Progress};

/// Relative tolerance between the fluid's time and a command's `t_from`.
const TIME_TOLERANCE: f64 = 1e-9;

/// The refusal of a structure whose wet surface has `n_nodes` nodes.
pub fn no_embedded_boundary(n_nodes: usize) -> String {
    format!(
        "fluid-solver: this build has no embedded boundary (thesis Ch. 4-5), so it cannot load a \
         wet surface of {n_nodes} nodes; couple a structure without a wet surface or use [fluid] \
         command = [\"piston-fluid\"]"
    )
}

/// The participant: the fluid run, opened at `Init` once the wet surface is known to be empty.
pub struct CoupledFluid<'a> {
    case: &'a Case,
    case_text: &'a str,
    opts: RunOptions,
    run: Option<FluidRun<'a>>,
    /// Topology version of the (empty) wet surface, echoed in the loads' headers.
    topology_version: u64,
}

impl<'a> CoupledFluid<'a> {
    pub fn new(case: &'a Case, case_text: &'a str, opts: RunOptions) -> CoupledFluid<'a> {
        CoupledFluid { case, case_text, opts, run: None, topology_version: 0 }
    }

    fn run(&mut self) -> Result<&mut FluidRun<'a>, Failure> {
        self.run.as_mut().ok_or_else(|| {
            Failure::new(failure_code::PROTOCOL, "fluid-solver: a command arrived before Init")
        })
    }
}

/// Refuses a non-empty wet surface.
fn require_no_wet_surface(n_nodes: usize, n_elements: usize) -> Result<(), Failure> {
    if n_nodes > 0 || n_elements > 0 {
        return Err(Failure::new(failure_code::UNSUPPORTED, no_embedded_boundary(n_nodes)));
    }
    Ok(())
}

fn solver_failure(e: anyhow::Error) -> Failure {
    Failure::new(failure_code::SOLVER, format!("fluid-solver: {e:#}"))
}

impl Handler<FluidEndpoint> for CoupledFluid<'_> {
    fn init(&mut self, ep: &mut FluidEndpoint) -> Result<f64, Failure> {
        let (version, n_elements) =
            ep.read_topology(|h: &StepHeader, elements| (h.topology_version, elements.len()))?;
        let n_nodes = ep.read_kinematics(|_, nodes| nodes.len())?;
        require_no_wet_surface(n_nodes, n_elements)?;
        self.topology_version = version;
        let run = FluidRun::open(self.case, self.case_text, &self.opts, Mode::Coupled)
            .map_err(solver_failure)?;
        let header = StepHeader {
            step: 0,
            time: run.reached().t,
            dt: 0.0,
            topology_version: version,
            count: 0,
        };
        self.run = Some(run);
        // The load at the start on no wet node.
        ep.publish_loads(header, 0, |_| ())?;
        // The fluid subcycles in its own CFL steps: it puts no limit on the coupling step.
        Ok(f64::INFINITY)
    }

    fn advance(&mut self, ep: &mut FluidEndpoint, c: &Command) -> Result<Progress, Failure> {
        if let Some((version, n_elements)) =
            ep.try_read_topology(|h: &StepHeader, elements| (h.topology_version, elements.len()))?
        {
            require_no_wet_surface(0, n_elements)?;
            self.topology_version = version;
        }
        // The target kinematics at t_to: consumed (lockstep), and there is no wet node to move.
        let n_nodes = ep.read_kinematics(|_, nodes| nodes.len())?;
        require_no_wet_surface(n_nodes, 0)?;
        let run = self.run()?;
        let t = run.reached().t;
        if (c.t_from - t).abs() > TIME_TOLERANCE * c.t_from.abs().max(c.t_to - c.t_from) {
            return Err(Failure::new(
                failure_code::PROTOCOL,
                format!(
                    "fluid-solver: `{}` starts at t = {:e}, but the fluid is at t = {t:e}",
                    c.describe(),
                    c.t_from
                ),
            ));
        }
        run.advance_to(c.t_to).map_err(|e| {
            let code = if run.failed() { failure_code::SOLVER } else { failure_code::IO };
            Failure::new(code, format!("fluid-solver: {e:#}"))
        })?;
        let header = StepHeader {
            step: c.step,
            time: c.t_to,
            dt: c.t_to - c.t_from,
            topology_version: self.topology_version,
            count: 0,
        };
        ep.publish_loads(header, 0, |_| ())?;
        Ok(Progress { step: c.step, t: c.t_to, dt_stable: f64::INFINITY })
    }

    fn checkpoint(&mut self, _ep: &mut FluidEndpoint, tag: &str) -> Result<(), Failure> {
        self.run()?.write_checkpoint(tag).map_err(|e| {
            Failure::new(failure_code::IO, format!("fluid-solver: checkpoint {tag}: {e:#}"))
        })
    }

    fn finish(&mut self, _ep: &mut FluidEndpoint) -> Result<(), Failure> {
        match self.run.take() {
            Some(run) => run.finish().map(|_| ()).map_err(solver_failure),
            None => Ok(()),
        }
    }
}

/// Joins run `run_id` as the fluid (a `Hello` accepting any wet-surface size) and answers its
/// commands until `Finish`.
pub fn run(case: &Case, case_text: &str, opts: RunOptions, run_id: &str) -> anyhow::Result<()> {
    let info = HelloInfo { n_surface_nodes: 0, n_surface_elements: 0, case_hash: case.hash() };
    let mut endpoint =
        FluidEndpoint::open(run_id, info, Timeouts::from_secs(case.coupling.timeout_s))
            .map_err(|e| anyhow::anyhow!("cannot join run {run_id}: {e}"))?;
    let mut participant = CoupledFluid::new(case, case_text, opts);
    let result = serve(&mut endpoint, &mut participant);
    drop(endpoint);
    result.map_err(|e| anyhow::anyhow!("run {run_id} stopped: {e}"))
}
