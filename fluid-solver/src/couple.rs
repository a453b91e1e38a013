//! The fluid as a coupling participant (DESIGN §1, §3, §4; PROTOCOL.md): `fluid-solver run CASE
//! --couple RUN_ID --out DIR` joins the run, answers the launcher's commands through
//! `participant::serve` and advances [`FluidRun`] over each `Advance` interval in its own CFL
//! steps, the last one clipped to land on `t_to` (or in exactly `fluid.time.substeps` equal
//! steps, [`crate::time::FixedSteps`]).
//!
//! This module only converts protocol samples to the embedded boundary's [`Surface`] and loads
//! back (DESIGN §5.1):
//! - `Init`: the topology (triangles and quads, phi per element node, its version) and the
//!   kinematics become the one [`Surface`] type the prescribed motion uses too, tracked with the
//!   case's `[fluid.embedded]` tracking, loads, seeds and cut-off ([`case::from_structure`]); the
//!   load at the start is published for it.
//! - `Advance [t_from, t_to]`: a newer topology is applied first (triangles and hierarchy rebuilt,
//!   node sides kept); the kinematics published for `t_to` are checked (one per node, finite, no
//!   degenerate triangle) and the surface moves on the Hermite path from the fluid's own copy of
//!   `(x, v)` at `t_from` to them while the fluid subcycles; the loads at `t_to` (point values
//!   at the end of the interval, both sides of a shell summed) are written straight into the
//!   loads buffer in protocol node order.
//! - A structure without a wet surface (no node, no element) gets the empty slice of loads.
//!
//! Every failure is a `Failed` reply naming what failed (the element, the node, the field).

use crate::embedded::advance::{EmbeddedRun, Kinematics};
use crate::embedded::case;
use crate::embedded::surface::HermitePath;
use crate::embedded::Surface;
use crate::solver::{FluidRun, Mode, RunOptions};
use interface_protocol::case::Case;
use interface_protocol::endpoint::{FluidEndpoint, Timeouts};
use interface_protocol::handshake::HelloInfo;
use interface_protocol::messages::{
    capability, Command, NodeLoad, NodeState, StepHeader, SurfaceElement,
};
use interface_protocol::participant::{failure_code, serve, Failure, Handler, Progress};

/// Relative tolerance between the fluid's time and a command's `t_from`.
const TIME_TOLERANCE: f64 = 1e-9;

/// The participant: the fluid run, opened at `Init`.
pub struct CoupledFluid<'a> {
    case: &'a Case,
    case_text: &'a str,
    opts: RunOptions,
    run: Option<FluidRun<'a>>,
    /// Topology version of the wet surface the fluid holds, echoed in the loads' headers.
    topology_version: u64,
    /// Wet nodes of the structure (0 without a wet surface).
    n_nodes: usize,
}

impl<'a> CoupledFluid<'a> {
    pub fn new(case: &'a Case, case_text: &'a str, opts: RunOptions) -> CoupledFluid<'a> {
        CoupledFluid { case, case_text, opts, run: None, topology_version: 0, n_nodes: 0 }
    }

    fn run(&mut self) -> Result<&mut FluidRun<'a>, Failure> {
        self.run.as_mut().ok_or_else(|| {
            Failure::new(failure_code::PROTOCOL, "fluid-solver: a command arrived before Init")
        })
    }
}

fn solver_failure(e: anyhow::Error) -> Failure {
    Failure::new(failure_code::SOLVER, format!("fluid-solver: {e:#}"))
}

fn protocol_failure(message: impl std::fmt::Display) -> Failure {
    Failure::new(failure_code::PROTOCOL, format!("fluid-solver: {message}"))
}

/// Positions and velocities of a kinematics sample, copied (the fluid keeps the pair).
fn states(nodes: &[NodeState]) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
    nodes.iter().map(|n| (n.x, n.v)).unzip()
}

/// The loads buffer as the nodal force vectors the loads algorithms write.
fn as_vectors(loads: &mut [NodeLoad]) -> &mut [[f64; 3]] {
    // SAFETY: `NodeLoad` is `#[repr(C)]` with the single field `f: [f64; 3]`, so it has the size
    // and alignment of `[f64; 3]` (24 and 8, asserted in `messages.rs`) and every bit pattern of
    // either is valid for the other; the new slice covers exactly the borrowed memory and
    // borrows it mutably for the same lifetime.
    unsafe { std::slice::from_raw_parts_mut(loads.as_mut_ptr().cast::<[f64; 3]>(), loads.len()) }
}

/// Publishes the loads of `run` at `header.time` in place (none without a wet surface).
fn publish_loads(
    ep: &mut FluidEndpoint,
    run: &FluidRun,
    header: StepHeader,
    n_nodes: usize,
) -> Result<(), Failure> {
    let result = ep.publish_loads(header, n_nodes, |out| match run.embedded() {
        Some(e) => e.write_loads(run.semidiscretization(), as_vectors(out)),
        None => Ok(()),
    })?;
    result.map_err(solver_failure)
}

/// A coupled restart: the surface state of the checkpoint `--restart from` names (node status
/// and sides, `(x, v)` at both ends of the last step, the Hermite path, `p*`, loads), checked
/// against the surface the structure published at `Init`; the kinematics published then (the
/// structure's state at t^k) are not the fluid's own copy (C0 and A6 run the fluid off t^k).
fn restore_surface(
    e: &mut EmbeddedRun,
    from: &std::path::Path,
    semi: &crate::semidiscretization::Semidiscretization,
) -> Result<(), Failure> {
    use crate::embedded::checkpoint::EmbeddedCheckpoint;
    use interface_protocol::io::checkpoint;
    let found = checkpoint::restart_point(from, crate::solver::CHECKPOINT_PART)
        .map_err(|err| solver_failure(err.into()))?
        .ok_or_else(|| {
            protocol_failure(format!("--restart {}: no fluid checkpoint", from.display()))
        })?;
    let ck = EmbeddedCheckpoint::read(found).map_err(solver_failure)?;
    let decoded = ck.decode(&e.tracker, &e.kinematics, &semi.mesh).map_err(solver_failure)?;
    decoded.restore(e, &semi.mesh).map_err(solver_failure)
}

impl Handler<FluidEndpoint> for CoupledFluid<'_> {
    fn init(&mut self, ep: &mut FluidEndpoint) -> Result<f64, Failure> {
        let (version, elements) = ep.read_topology(|h: &StepHeader, e: &[SurfaceElement]| {
            (h.topology_version, e.to_vec())
        })?;
        let (x, v) = ep.read_kinematics(|_, nodes| states(nodes))?;
        if elements.is_empty() != x.is_empty() {
            return Err(Failure::new(
                failure_code::UNSUPPORTED,
                format!(
                    "fluid-solver: the structure sent {} wet nodes and {} wet elements; the \
                     embedded boundary tracks a surface of triangles and quads over its nodes \
                     (give both, or neither)",
                    x.len(),
                    elements.len()
                ),
            ));
        }
        case::check_coupled(self.case).map_err(solver_failure)?;
        let mut run = FluidRun::open(self.case, self.case_text, &self.opts, Mode::Coupled)
            .map_err(solver_failure)?;
        let t0 = run.reached().t;
        if !x.is_empty() {
            let mut surface = Surface::new(&elements, x, version).map_err(protocol_failure)?;
            surface.check_states(&surface.x_b, &v).map_err(protocol_failure)?;
            surface.v_a.clone_from(&v);
            surface.v_b = v;
            surface.t_a = t0;
            surface.t_b = t0;
            let s = case::from_structure(self.case, &run.semidiscretization().mesh, surface)
                .map_err(solver_failure)?;
            let (x0, v0) = (&s.tracker.surface.x_b, &s.tracker.surface.v_b);
            let at_rest = Kinematics::Coupled {
                path: HermitePath { t_a: t0, t_b: t0 },
                x_from: x0.clone(),
                v_from: v0.clone(),
                x_to: x0.clone(),
                v_to: v0.clone(),
            };
            let dir = run.out_dir().to_path_buf();
            let mut e = EmbeddedRun::with(s.tracker, at_rest, s.loads, s.interface, s.p_cut, &dir)
                .map_err(solver_failure)?;
            match &self.opts.restart {
                Some(from) => restore_surface(&mut e, from, run.semidiscretization())?,
                None => e
                    .start_pressures(run.semidiscretization(), run.primitives())
                    .map_err(solver_failure)?,
            }
            run.embed(e);
        }
        self.topology_version = version;
        self.n_nodes = run.embedded().map_or(0, |e| e.tracker.surface.n_nodes());
        if self.opts.restart.is_none() {
            let header =
                StepHeader { step: 0, time: t0, dt: 0.0, topology_version: version, count: 0 };
            // The load at the start (F^0 of the schemes). A restart publishes none: the
            // structure reads the next loads at CORRECT (PROTOCOL.md §4, restart).
            publish_loads(ep, &run, header, self.n_nodes)?;
        }
        self.run = Some(run);
        // The fluid subcycles (CFL or fixed steps): it puts no limit on the coupling step.
        Ok(f64::INFINITY)
    }

    fn advance(&mut self, ep: &mut FluidEndpoint, c: &Command) -> Result<Progress, Failure> {
        let topology = ep.try_read_topology(|h: &StepHeader, e: &[SurfaceElement]| {
            (h.topology_version, e.to_vec())
        })?;
        // The target kinematics at t_to: consumed (lockstep), copied (the fluid keeps the pair).
        let (k_version, (x, v)) =
            ep.read_kinematics(|h, nodes| (h.topology_version, states(nodes)))?;
        let topology = match topology {
            // Kinematics of a newer topology than the fluid holds: that topology comes first.
            None if k_version != self.topology_version && self.n_nodes > 0 => {
                Some(ep.read_topology(|h: &StepHeader, e: &[SurfaceElement]| {
                    (h.topology_version, e.to_vec())
                })?)
            }
            t => t,
        };
        let n_nodes = self.n_nodes;
        let run = self.run()?;
        let t = run.reached().t;
        if (c.t_from - t).abs() > TIME_TOLERANCE * c.t_from.abs().max(c.t_to - c.t_from) {
            return Err(protocol_failure(format!(
                "`{}` starts at t = {:e}, but the fluid is at t = {t:e}",
                c.describe(),
                c.t_from
            )));
        }
        match run.embedded_mut() {
            None if topology.as_ref().is_some_and(|t| !t.1.is_empty()) || !x.is_empty() => {
                return Err(Failure::new(
                    failure_code::UNSUPPORTED,
                    "fluid-solver: the structure started without a wet surface and now sends one; \
                     a wet surface must be there at Init",
                ));
            }
            None => {}
            Some(e) => {
                let surface = &mut e.tracker.surface;
                if let Some((version, elements)) = &topology {
                    if x.len() > surface.n_nodes() {
                        // Nodes the new topology adds start the step where they are published.
                        let n = surface.n_nodes();
                        surface.append_nodes(&x[n..], &v[n..]);
                    }
                    surface.set_topology(elements, *version).map_err(protocol_failure)?;
                }
                surface.check_states(&x, &v).map_err(|err| {
                    protocol_failure(format!("kinematics for t = {:e}: {err}", c.t_to))
                })?;
                e.kinematics = Kinematics::Coupled {
                    path: HermitePath { t_a: c.t_from, t_b: c.t_to },
                    x_from: surface.x_b.clone(),
                    v_from: surface.v_b.clone(),
                    x_to: x,
                    v_to: v,
                };
            }
        }
        if let Some((version, _)) = topology {
            self.topology_version = version;
        }
        let run = self.run.as_mut().expect("checked above");
        run.advance_to(c.t_to).map_err(|e| {
            let code = if run.failed() { failure_code::SOLVER } else { failure_code::IO };
            Failure::new(code, format!("fluid-solver: {e:#}"))
        })?;
        self.n_nodes = run.embedded().map_or(n_nodes, |e| e.tracker.surface.n_nodes());
        let header = StepHeader {
            step: c.step,
            time: c.t_to,
            dt: c.t_to - c.t_from,
            topology_version: self.topology_version,
            count: 0,
        };
        publish_loads(ep, run, header, self.n_nodes)?;
        let interface_work = run.embedded().map_or(0.0, |e| e.interface_work);
        Ok(Progress { step: c.step, t: c.t_to, dt_stable: f64::INFINITY, interface_work })
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
    let info = HelloInfo {
        n_surface_nodes: 0,
        n_surface_elements: 0,
        case_hash: case.hash(),
        capabilities: capability::RESTART | capability::INTERFACE_WORK,
    };
    let mut endpoint =
        FluidEndpoint::open(run_id, info, Timeouts::from_secs(case.coupling.timeout_s))
            .map_err(|e| anyhow::anyhow!("cannot join run {run_id}: {e}"))?;
    let mut participant = CoupledFluid::new(case, case_text, opts);
    let result = serve(&mut endpoint, &mut participant);
    drop(endpoint);
    result.map_err(|e| anyhow::anyhow!("run {run_id} stopped: {e}"))
}
