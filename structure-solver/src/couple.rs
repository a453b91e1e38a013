//! `structure-solver run CASE --couple RUN_ID`: the finite-element structure as the structure
//! participant of the staggered schemes (coupling-sequence; DESIGN §4, thesis §3.2 after Farhat,
//! van der Zee and Geuzaine, CMAME 2006).
//!
//! The wet surface is the set `structure.wet_set` ([`crate::wet`]); every face carries
//! `phi = 1`. Every step the structure checks its state finite before it writes or publishes
//! anything (`state_check`, as a run alone does) and fails the step naming the node and dof.
//! The fluid's nodal loads are added to
//! the external force of the wet nodes' translations. Integrators per scheme: CSS and C0 central
//! differences (C0: `F^{n+1} = (F^{n+1/2} + F^{n+3/2})/2` in `a^{n+1}`), A6 the implicit
//! midpoint rule with `F^{n+1/2}` held over the step.

use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail};
use interface_protocol::case::{Case, Integrator, Scheme};
use interface_protocol::coupling::{
    a6_acceleration_estimate, a6_prediction, c0_load_average, c0_prediction, c0_start_prediction,
    kick,
};
use interface_protocol::endpoint::{StructureEndpoint, Timeouts};
use interface_protocol::handshake::HelloInfo;
use interface_protocol::io::checkpoint::Checkpoint;
use interface_protocol::io::outdir::{OutputDir, Policy};
use interface_protocol::io::probes::ProbeWriter;
use interface_protocol::messages::{scheme_phase, Command, NodeLoad, NodeState, StepHeader};
use interface_protocol::participant::{failure_code, serve, Failure, Handler, Progress};

use interface_protocol::io::progress::Progress as Bar;

use crate::assembly::{FeModel, RotaryInertia};
use crate::build::{build, field_error, need, section, Structure};
use crate::model::Model;
use crate::output::FieldOutput;
use crate::restart::{save_dynamics, save_state, PART};
use crate::state_check::{check_dofs, check_state};
use crate::time::{critical_dt, CentralDifference, Implicit, ImplicitScheme, StableStep};

pub use crate::wet::{wet_surface, WetSurface};

/// The integrator of the scheme, created at START from the load `F^0`.
enum Stepper {
    Explicit(CentralDifference),
    Midpoint(Implicit),
}

/// Velocity per dof: the integrator's, or `v0` before START.
fn velocity<'a>(stepper: &'a Option<Stepper>, v0: &'a [f64]) -> &'a [f64] {
    match stepper {
        Some(Stepper::Explicit(cd)) => &cd.state.v,
        Some(Stepper::Midpoint(im)) => &im.state.v,
        None => v0,
    }
}

/// The structure through the coupling sequence.
pub struct Participant {
    scheme: Scheme,
    model: FeModel,
    wet: WetSurface,
    /// Reference positions of all nodes, and the user's id of each (for messages).
    x0: Vec<[f64; 3]>,
    node_ids: Vec<u64>,
    v0: Vec<f64>,
    stepper: Option<Stepper>,
    /// Length of the first coupling step (START carries none), and the end of the run (the last
    /// state is always probed).
    first_dt: f64,
    t_end: f64,
    dt_stable: f64,
    stable_rule: Option<StableStep>,
    t: f64,
    /// Coupling steps completed.
    steps: u64,
    /// `<out>/checkpoints`.
    checkpoints: PathBuf,
    /// The fluid load just read, 6 per node (translations of wet nodes only).
    load: Vec<f64>,
    /// C0: `F^{n+1/2}` and `v^{n-1/2}`; A6: `â^n`; scratch for loads and velocities.
    f_half: Vec<f64>,
    v_half_prev: Vec<f64>,
    a_hat: Vec<f64>,
    scratch: Vec<f64>,
    /// Kinematics to publish, 6 per node (`up` displacements, `vp` velocities).
    up: Vec<f64>,
    vp: Vec<f64>,
    disp: Vec<[f64; 3]>,
    probes: ProbeWriter,
    probe_nodes: Vec<usize>,
    probes_every: u64,
    /// `structure.xdmf` (closed by `Finish`), written every `fields_every` coupling steps
    /// (0: the first and last states only); the time of the last state written.
    fields: Option<FieldOutput>,
    fields_every: u64,
    fields_t: f64,
    bar: Option<Bar>,
}

fn io_failure(what: &str, e: impl std::fmt::Display) -> Failure {
    Failure::new(failure_code::IO, format!("{what}: {e}"))
}

/// The structure of a coupled case, checked before the run starts (shared with `check`): the
/// model for the scheme's integrator, its wet surface and the stable step of central
/// differences (infinite for A6).
pub struct Coupled {
    pub structure: Structure,
    pub wet: WetSurface,
    pub dt_stable: f64,
    /// Central differences: the stable step recomputed after every step from the element
    /// bound at the current configuration (reported to the launcher).
    pub stable_rule: Option<StableStep>,
}

/// Builds and checks the `[structure]` of a coupled `case`.
pub fn prepare_coupled(case: &Case) -> anyhow::Result<Coupled> {
    let s = section(case)?;
    let scheme = case.coupling.scheme;
    let explicit = scheme != Scheme::A6;
    let expected = if explicit { Integrator::CentralDifference } else { Integrator::Midpoint };
    if let Some(i) = s.integrator {
        if i != expected {
            return Err(field_error(
                case,
                "structure.integrator",
                format!(
                    "the {scheme:?} scheme integrates the structure with \"{}\", got \"{}\"",
                    expected.name(),
                    i.name()
                ),
            ));
        }
    }
    let rotary = if explicit { RotaryInertia::Scaled } else { RotaryInertia::Physical };
    let mut structure = build(case, rotary)?;
    if !explicit && !structure.model.has_tangent() {
        let field = if s.parts.is_empty() { "element" } else { "parts" };
        return Err(field_error(
            case,
            &format!("structure.{field}"),
            "bt4 shells are explicit; the A6 scheme needs mitc4 or dkt shells",
        ));
    }
    let wet_name = need(&s.wet_set, "wet_set", case)?;
    let wet = wet_surface(&structure.mesh, wet_name)
        .map_err(|e| field_error(case, "structure.wet_set", e))?;
    let (dt_stable, stable_rule) = if explicit {
        let estimate = critical_dt(&mut structure.model, 0.0, 100, 1e-9 * structure.length);
        (estimate.stable(1.0), Some(StableStep::new(&estimate, 1.0)))
    } else {
        (f64::INFINITY, None)
    };
    Ok(Coupled { structure, wet, dt_stable, stable_rule })
}

/// The refusal of a first coupling step `dt` above the stable step of the scheme's central
/// differences.
pub fn unstable_coupling(dt: f64, dt_stable: f64, scheme: Scheme) -> Option<String> {
    (dt > dt_stable).then(|| {
        format!(
            "coupling.dt = {dt:.3e} exceeds the stable step {dt_stable:.3e} of the {scheme:?} scheme's central differences"
        )
    })
}

impl Participant {
    /// The participant of `case` writing into `out`.
    pub fn new(case: &Case, out: &Path, quiet: bool) -> anyhow::Result<Participant> {
        let s = section(case)?;
        let scheme = case.coupling.scheme;
        let Coupled { structure, wet, dt_stable, stable_rule } = prepare_coupled(case)?;
        let Structure { mesh, model, v0, cells, .. } = structure;
        let dir = OutputDir::create(out, Policy::Existing)
            .or_else(|_| OutputDir::create(out, Policy::Overwrite))?;
        let names: Vec<&str> = s.probes.iter().map(|p| p.name.as_str()).collect();
        let probes = ProbeWriter::structure(dir.path(), &names)?;
        let n = model.n_dof();
        let fields = FieldOutput::create(dir.path(), &mesh, Some(cells))?;
        Ok(Participant {
            fields: Some(fields),
            fields_every: case.output.fields_every,
            fields_t: f64::NAN,
            bar: Some(Bar::new(case.coupling.t_end, quiet)),
            scheme,
            wet,
            x0: mesh.nodes.clone(),
            node_ids: (0..mesh.nodes.len()).map(|i| mesh.node_id(i)).collect(),
            v0,
            stepper: None,
            first_dt: case.coupling.dt.min(case.coupling.t_end),
            t_end: case.coupling.t_end,
            dt_stable,
            stable_rule,
            t: 0.0,
            steps: 0,
            checkpoints: dir.path().join("checkpoints"),
            load: vec![0.0; n],
            f_half: vec![0.0; n],
            v_half_prev: vec![0.0; n],
            a_hat: vec![0.0; n],
            scratch: vec![0.0; n],
            up: vec![0.0; n],
            vp: vec![0.0; n],
            disp: vec![[0.0; 3]; mesh.nodes.len()],
            probe_nodes: s.probes.iter().map(|p| mesh.nearest_node(p.point)).collect(),
            probes,
            probes_every: s.output_every.unwrap_or(1).max(1),
            model,
        })
    }

    /// What the launcher's `Hello` check compares.
    pub fn hello(&self, case: &Case) -> HelloInfo {
        HelloInfo {
            n_surface_nodes: self.wet.nodes.len() as u64,
            n_surface_elements: self.wet.elements.len() as u64,
            case_hash: case.hash(),
        }
    }

    /// Velocity per dof at the current state.
    fn velocity(&self) -> &[f64] {
        velocity(&self.stepper, &self.v0)
    }

    /// The model's displacement as 6 values per node (rotations zero) into `up`.
    fn displacement_into_up(&mut self) {
        self.model.displacement(&mut self.disp);
        self.up.fill(0.0);
        for (i, d) in self.disp.iter().enumerate() {
            self.up[6 * i..6 * i + 3].copy_from_slice(d);
        }
    }

    /// Publishes `x = X + up`, `v = vp` on the wet nodes for time `t`.
    fn publish(
        &self,
        ep: &mut StructureEndpoint,
        step: u64,
        t: f64,
        dt: f64,
    ) -> Result<(), Failure> {
        let header = StepHeader { step, time: t, dt, topology_version: 1, count: 0 };
        let (wet, x0, up, vp) = (&self.wet.nodes, &self.x0, &self.up, &self.vp);
        let ids = &self.node_ids;
        let id = |i: usize| ids[i];
        check_dofs("displacement sent", up, &id)
            .and_then(|()| check_dofs("velocity sent", vp, &id))
            .map_err(|e| {
                Failure::new(
                    failure_code::SOLVER,
                    format!("step {step}, t = {t:e}: {e}: the structure diverged"),
                )
            })?;
        ep.publish_kinematics(header, wet.len(), |out: &mut [NodeState]| {
            for (o, &n) in out.iter_mut().zip(wet) {
                for k in 0..3 {
                    o.x[k] = x0[n][k] + up[6 * n + k];
                    o.v[k] = vp[6 * n + k];
                }
            }
        })?;
        Ok(())
    }

    /// Publishes the current state `(u, v)`.
    fn publish_current(
        &mut self,
        ep: &mut StructureEndpoint,
        step: u64,
        t: f64,
        dt: f64,
    ) -> Result<(), Failure> {
        self.displacement_into_up();
        let v = velocity(&self.stepper, &self.v0);
        self.vp.copy_from_slice(v);
        self.publish(ep, step, t, dt)
    }

    /// Reads the fluid's loads into `self.load` (translations of the wet nodes).
    fn read_loads(&mut self, ep: &mut StructureEndpoint) -> Result<(), Failure> {
        let (wet, load) = (&self.wet.nodes, &mut self.load);
        let count = ep.read_loads(|_, loads: &[NodeLoad]| {
            if loads.len() == wet.len() {
                load.fill(0.0);
                for (l, &n) in loads.iter().zip(wet) {
                    load[6 * n..6 * n + 3].copy_from_slice(&l.f);
                }
            }
            loads.len()
        })?;
        if count != wet.len() {
            return Err(Failure::new(
                failure_code::PROTOCOL,
                format!(
                    "the fluid sent {count} nodal loads, the structure has {} wet nodes",
                    wet.len()
                ),
            ));
        }
        let ids = &self.node_ids;
        check_dofs("load from the fluid", &self.load, &|i| ids[i])
            .map_err(|e| Failure::new(failure_code::SOLVER, format!("{e}: the fluid diverged")))
    }

    /// START: `a^0` from `F^0`; C0 publishes the prediction for `t^{1/2}`.
    fn start(&mut self, ep: &mut StructureEndpoint) -> Result<(), Failure> {
        self.read_loads(ep)?;
        let v0 = self.v0.clone();
        let dt = self.first_dt;
        match self.scheme {
            Scheme::A6 => {
                let im = Implicit::new(
                    &mut self.model,
                    ImplicitScheme::Midpoint,
                    0.0,
                    v0,
                    Some(&self.load),
                );
                self.a_hat.copy_from_slice(&im.state.a);
                self.stepper = Some(Stepper::Midpoint(im));
            }
            Scheme::Css | Scheme::C0 => {
                let cd = CentralDifference::new(&mut self.model, 0.0, v0, Some(&self.load));
                if self.scheme == Scheme::C0 {
                    let s = &cd.state;
                    kick(&s.v, &s.a, -0.5 * dt, &mut self.v_half_prev);
                    self.displacement_into_up();
                    self.scratch.copy_from_slice(&self.up);
                    c0_start_prediction(&self.scratch, &s.v, &s.a, dt, &mut self.up, &mut self.vp);
                    self.stepper = Some(Stepper::Explicit(cd));
                    self.publish(ep, 0, 0.5 * dt, dt)?;
                } else {
                    self.stepper = Some(Stepper::Explicit(cd));
                }
            }
        }
        Ok(())
    }

    /// PREDICT of step `n` over `[t_from, t_from + dt]`.
    fn predict(
        &mut self,
        ep: &mut StructureEndpoint,
        n: u64,
        t_from: f64,
        dt: f64,
    ) -> Result<(), Failure> {
        match (self.scheme, self.stepper.as_mut()) {
            (Scheme::Css, Some(_)) => self.publish_current(ep, n, t_from, dt),
            (Scheme::C0, Some(Stepper::Explicit(_))) => {
                if n == 0 {
                    self.read_loads(ep)?;
                    self.f_half.copy_from_slice(&self.load);
                }
                let Some(Stepper::Explicit(cd)) = self.stepper.as_mut() else { unreachable!() };
                cd.advance_positions(&mut self.model, dt);
                self.displacement_into_up();
                self.scratch.copy_from_slice(&self.up);
                let Some(Stepper::Explicit(cd)) = self.stepper.as_ref() else { unreachable!() };
                c0_prediction(
                    &self.scratch,
                    &cd.v_half,
                    &self.v_half_prev,
                    dt,
                    &mut self.up,
                    &mut self.vp,
                );
                self.publish(ep, n, t_from + 1.5 * dt, dt)
            }
            (Scheme::A6, Some(Stepper::Midpoint(_))) => {
                self.displacement_into_up();
                self.scratch.copy_from_slice(&self.up);
                let Some(Stepper::Midpoint(im)) = self.stepper.as_ref() else { unreachable!() };
                a6_prediction(
                    &self.scratch,
                    &im.state.v,
                    &self.a_hat,
                    dt,
                    &mut self.up,
                    &mut self.vp,
                );
                self.publish(ep, n, t_from + 0.5 * dt, dt)
            }
            _ => Err(Failure::new(
                failure_code::PROTOCOL,
                format!("PREDICT of step {n} before START"),
            )),
        }
    }

    /// CORRECT of step `n`: the structure reaches `t_to`.
    fn correct(
        &mut self,
        ep: &mut StructureEndpoint,
        n: u64,
        t_to: f64,
        dt: f64,
    ) -> Result<(), Failure> {
        self.read_loads(ep)?;
        match self.stepper.as_mut() {
            Some(Stepper::Explicit(cd)) if self.scheme == Scheme::Css => {
                cd.step(&mut self.model, dt, Some(&self.load));
            }
            Some(Stepper::Explicit(cd)) => {
                c0_load_average(&self.f_half, &self.load, &mut self.scratch);
                cd.complete(&mut self.model, dt, Some(&self.scratch));
                self.v_half_prev.copy_from_slice(&cd.v_half);
                self.f_half.copy_from_slice(&self.load);
            }
            Some(Stepper::Midpoint(im)) => {
                self.scratch.copy_from_slice(&im.state.v);
                im.step(&mut self.model, dt, Some(&self.load)).map_err(|e| {
                    Failure::new(failure_code::SOLVER, format!("step {n} to t = {t_to}: {e}"))
                })?;
                a6_acceleration_estimate(&im.state.v, &self.scratch, dt, &mut self.a_hat);
            }
            None => {
                return Err(Failure::new(
                    failure_code::PROTOCOL,
                    format!("CORRECT of step {n} before START"),
                ))
            }
        }
        self.check_state(n, t_to, dt)?;
        if let Some(rule) = self.stable_rule {
            self.dt_stable = rule.at(&self.model);
        }
        self.t = t_to;
        self.steps = n + 1;
        let (fields, model) = (self.fields.as_mut(), &self.model);
        let v = velocity(&self.stepper, &self.v0);
        if let Some(f) = fields {
            f.gather(t_to, model, Some(model), v).map_err(|e| {
                Failure::new(
                    failure_code::SOLVER,
                    format!("{e} (step {n}, Δt = {dt:.3e}, stable step {:.3e})", self.dt_stable),
                )
            })?;
        }
        if self.fields_every > 0 && (n + 1).is_multiple_of(self.fields_every) {
            self.write_fields()?;
        }
        if let Some(bar) = self.bar.as_mut() {
            bar.update(n + 1, t_to, dt);
        }
        if (n + 1).is_multiple_of(self.probes_every) || t_to >= self.t_end * (1.0 - 1e-12) {
            self.write_probes()?;
        }
        Ok(())
    }

    /// The state after step `n` (to `t_to`), checked finite before anything is written.
    fn check_state(&mut self, n: u64, t_to: f64, dt: f64) -> Result<(), Failure> {
        let (v, a, f_int) = match &self.stepper {
            Some(Stepper::Explicit(cd)) => (&cd.state.v, &cd.state.a, Some(cd.internal_force())),
            Some(Stepper::Midpoint(im)) => (&im.state.v, &im.state.a, None),
            None => return Ok(()),
        };
        let ids = &self.node_ids;
        check_state(&self.model, &mut self.disp, (v, a, f_int), &|i| ids[i]).map_err(|e| {
            let note = match unstable_coupling(dt, self.dt_stable, self.scheme) {
                Some(m) => format!(" ({m})"),
                None => String::new(),
            };
            Failure::new(
                failure_code::SOLVER,
                format!("step {n} to t = {t_to:e}: {e}: the structure diverged{note}"),
            )
        })
    }

    /// Writes the state last gathered into `structure.xdmf` (once per time).
    fn write_fields(&mut self) -> Result<(), Failure> {
        if let Some(f) = self.fields.as_mut() {
            if self.fields_t != self.t {
                f.write(self.t).map_err(|e| io_failure("cannot write structure.xdmf", e))?;
                self.fields_t = self.t;
            }
        }
        Ok(())
    }

    /// Flushes the probes and closes the field series with the final state.
    fn close(&mut self) -> Result<(), Failure> {
        self.write_fields()?;
        if let Some(f) = self.fields.take() {
            f.finish().map_err(|e| io_failure("cannot write structure.xdmf", e))?;
        }
        if let Some(bar) = self.bar.take() {
            bar.finish();
        }
        self.probes.flush().map_err(|e| io_failure("structure_probes.csv", e))
    }

    /// Writes `checkpoints/<tag>/structure.ckpt`: the model's state, velocities and
    /// accelerations, and the scheme's own state (C0: `F^{n+1/2}`, `v^{n-1/2}`; A6: `â^n`).
    fn write_checkpoint(&self, tag: &str) -> anyhow::Result<()> {
        let Some(d) = (match &self.stepper {
            Some(Stepper::Explicit(cd)) => Some(&cd.state),
            Some(Stepper::Midpoint(im)) => Some(&im.state),
            None => None,
        }) else {
            bail!("a checkpoint needs START first");
        };
        let mut ck = Checkpoint::new(self.steps, self.t);
        save_state(&self.model, &mut ck)?;
        save_dynamics(&mut ck, d)?;
        ck.put("coupling.f_half", self.f_half.clone())?;
        ck.put("coupling.v_half_prev", self.v_half_prev.clone())?;
        ck.put("coupling.a_hat", self.a_hat.clone())?;
        ck.write(&self.checkpoints, tag, PART)?;
        Ok(())
    }

    /// One row of `structure_probes.csv` at the current state.
    fn write_probes(&mut self) -> Result<(), Failure> {
        self.model.displacement(&mut self.disp);
        let v = self.velocity();
        let mut row = Vec::with_capacity(6 * self.probe_nodes.len());
        for &p in &self.probe_nodes {
            row.extend_from_slice(&self.disp[p]);
            row.extend_from_slice(&v[6 * p..6 * p + 3]);
        }
        self.probes.write_row(self.t, &row).map_err(|e| io_failure("structure_probes.csv", e))
    }
}

impl Handler<StructureEndpoint> for Participant {
    fn init(&mut self, ep: &mut StructureEndpoint) -> Result<f64, Failure> {
        if let Some(message) = unstable_coupling(self.first_dt, self.dt_stable, self.scheme) {
            return Err(Failure::new(failure_code::SOLVER, message));
        }
        let header = StepHeader { step: 0, time: 0.0, dt: 0.0, topology_version: 1, count: 0 };
        let elements = &self.wet.elements;
        ep.publish_topology(header, elements.len(), |out| out.copy_from_slice(elements))?;
        self.publish_current(ep, 0, 0.0, 0.0)?;
        self.write_probes()?;
        if let Some(f) = self.fields.as_mut() {
            f.gather(0.0, &self.model, Some(&self.model), &self.v0)
                .map_err(|e| Failure::new(failure_code::SOLVER, format!("initial state: {e}")))?;
        }
        self.write_fields()?;
        Ok(self.dt_stable)
    }

    fn advance(&mut self, ep: &mut StructureEndpoint, c: &Command) -> Result<Progress, Failure> {
        let dt = c.t_to - c.t_from;
        match c.scheme_phase {
            scheme_phase::START => self.start(ep)?,
            scheme_phase::PREDICT => self.predict(ep, c.step, c.t_from, dt)?,
            scheme_phase::CORRECT => self.correct(ep, c.step, c.t_to, dt)?,
            p => {
                return Err(Failure::new(
                    failure_code::UNSUPPORTED,
                    format!(
                    "the structure has no Advance phase {p} (expected START, PREDICT or CORRECT)"
                ),
                ))
            }
        }
        Ok(Progress { step: c.step, t: self.t, dt_stable: self.dt_stable })
    }

    fn checkpoint(&mut self, _ep: &mut StructureEndpoint, tag: &str) -> Result<(), Failure> {
        self.probes.flush().map_err(|e| io_failure("structure_probes.csv", e))?;
        self.write_checkpoint(tag).map_err(|e| io_failure("cannot write the checkpoint", e))
    }

    fn finish(&mut self, _ep: &mut StructureEndpoint) -> Result<(), Failure> {
        self.close()
    }
}

/// Joins run `run_id` and answers the launcher until `Finish`.
pub fn run(
    case_path: &Path,
    run_id: &str,
    out: Option<PathBuf>,
    set: &[String],
    quiet: bool,
) -> anyhow::Result<()> {
    let case = Case::load(case_path, set)?;
    let out = out
        .or_else(|| case.output.dir.as_ref().map(|d| case.dir().join(d)))
        .unwrap_or_else(|| PathBuf::from("runs").join(format!("{}-structure", case.case.name)));
    let mut participant = Participant::new(&case, &out, quiet)?;
    let mut endpoint = StructureEndpoint::open(
        run_id,
        participant.hello(&case),
        Timeouts::from_secs(case.coupling.timeout_s),
    )
    .map_err(|e| anyhow!("cannot join run {run_id}: {e}"))?;
    let result = serve(&mut endpoint, &mut participant);
    // Ports and node go before the process does, whatever happened.
    drop(endpoint);
    result.map_err(|e| anyhow!("run {run_id} stopped: {e}"))
}
