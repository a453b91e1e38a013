//! `structure-solver run CASE --couple RUN_ID`: the finite-element structure as the structure
//! participant of the staggered schemes (coupling-sequence; DESIGN §4, thesis §3.2 after Farhat,
//! van der Zee and Geuzaine, CMAME 2006).
//!
//! The wet surface is the set `structure.wet_set` ([`crate::wet`]); every face carries
//! `phi = 1`. Every step the structure checks its state finite before it writes or publishes
//! anything (`state_check`, as a run alone does) and fails the step naming the node and dof.
//! The fluid's nodal loads are added to
//! the external force of the wet nodes' translations. The schemes are sequenced by
//! [`interface_protocol::coupling::Staggered`], the one implementation every structure
//! participant uses, over the model as its [`Dynamics`] ([`fe_dynamics`]): CSS and C0 central
//! differences (C0: `F^{n+1} = (F^{n+1/2} + F^{n+3/2})/2` in `a^{n+1}`), A6 the implicit
//! midpoint rule with `F^{n+1/2}` held over the step.

use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail};
use interface_protocol::case::{Case, Integrator, Scheme};
use interface_protocol::coupling::{Dynamics, Staggered};
use interface_protocol::endpoint::{StructureEndpoint, Timeouts};
use interface_protocol::handshake::HelloInfo;
use interface_protocol::io::checkpoint::{self, Checkpoint};
use interface_protocol::io::outdir::{OutputDir, Policy};
use interface_protocol::io::probes::ProbeWriter;
use interface_protocol::messages::{
    capability, scheme_phase, Command, NodeLoad, NodeState, StepHeader,
};
use interface_protocol::participant::{failure_code, serve, Failure, Handler, Progress};

use interface_protocol::io::progress::Progress as Bar;

use crate::assembly::RotaryInertia;
use crate::build::{build, field_error, need, section, Structure};
use crate::model::Model;
use crate::output::FieldOutput;
use crate::restart::{load_dynamics, restore_state, save_dynamics, save_state, PART};
use crate::state_check::{check_dofs, check_state};
use crate::time::{critical_dt, StableStep};

pub mod fe_dynamics;

pub use crate::wet::{wet_surface, WetSurface};
use fe_dynamics::FeDynamics;

/// The structure through the coupling sequence.
pub struct Participant {
    /// The model and its integrator, and the scheme's own state.
    dynamics: FeDynamics,
    scheme: Staggered,
    wet: WetSurface,
    /// Reference positions of all nodes, and the user's id of each (for messages).
    x0: Vec<[f64; 3]>,
    node_ids: Vec<u64>,
    /// Length of the first coupling step (START carries none), and the end of the run (the last
    /// state is always probed).
    first_dt: f64,
    t_end: f64,
    dt_stable: f64,
    stable_rule: Option<StableStep>,
    /// `structure.substeps` (None: as many as the stable step needs).
    substeps: Option<u32>,
    t: f64,
    /// Coupling steps completed.
    steps: u64,
    /// `<out>/checkpoints`.
    checkpoints: PathBuf,
    /// The fluid load just read, 6 per node (translations of wet nodes only).
    load: Vec<f64>,
    /// The current displacement, 6 per node (the state `Init` publishes).
    current: Vec<f64>,
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

/// The refusal of a coupling step `dt` whose substeps exceed the stable step of the scheme's
/// central differences: only with a fixed `structure.substeps` (by default the structure takes
/// as many as the stable step needs).
pub fn unstable_coupling(
    dt: f64,
    dt_stable: f64,
    scheme: Scheme,
    substeps: Option<u32>,
) -> Option<String> {
    let m = substeps?.max(1);
    let h = dt / f64::from(m);
    (scheme != Scheme::A6 && h > dt_stable).then(|| {
        let each = if m > 1 { format!(" in {m} substeps of {h:.3e}") } else { String::new() };
        format!(
            "coupling.dt = {dt:.3e}{each} exceeds the stable step {dt_stable:.3e} of the \
             {scheme:?} scheme's central differences (structure.substeps = {m}; leave it out to \
             subcycle as the stable step needs)"
        )
    })
}

impl Participant {
    /// The participant of `case` writing into `out`; with `restart`, continuing a coupled run
    /// from the checkpoint it names (`checkpoint::restart_point`): model, integrator, the
    /// scheme's history, step and time restored, `structure_probes.csv` kept up to the
    /// checkpoint's time (`structure.xdmf` starts anew at it).
    pub fn new(
        case: &Case,
        out: &Path,
        quiet: bool,
        restart: Option<&Path>,
    ) -> anyhow::Result<Participant> {
        let ck = match restart {
            Some(dir) => {
                let found = checkpoint::restart_point(dir, PART)?.ok_or_else(|| {
                    anyhow!("--restart {}: no structure checkpoint there", dir.display())
                })?;
                let file = found.dir.join(format!("{PART}.{}", checkpoint::EXTENSION));
                Some(Checkpoint::read_file(&file)?)
            }
            None => None,
        };
        let mut p = Self::fresh(case, out, quiet, ck.as_ref().map(|c| c.time))?;
        if let Some(ck) = &ck {
            p.restore(ck)?;
        }
        Ok(p)
    }

    /// The participant at the start; `resume_at`: the probe file is continued from that time.
    fn fresh(
        case: &Case,
        out: &Path,
        quiet: bool,
        resume_at: Option<f64>,
    ) -> anyhow::Result<Participant> {
        let s = section(case)?;
        let scheme = case.coupling.scheme;
        let Coupled { structure, wet, dt_stable, stable_rule } = prepare_coupled(case)?;
        let Structure { mesh, model, v0, cells, .. } = structure;
        let dir = OutputDir::create(out, Policy::Existing)
            .or_else(|_| OutputDir::create(out, Policy::Overwrite))?;
        let names: Vec<&str> = s.probes.iter().map(|p| p.name.as_str()).collect();
        let probes = ProbeWriter::structure_from(dir.path(), &names, resume_at)?;
        let n = model.n_dof();
        let fields = FieldOutput::create(dir.path(), &mesh, Some(cells))?;
        Ok(Participant {
            fields: Some(fields),
            fields_every: case.output.fields_every,
            fields_t: f64::NAN,
            bar: Some(Bar::new(case.coupling.t_end, quiet)),
            dynamics: FeDynamics::new(model, scheme, v0),
            scheme: Staggered::new(scheme, n).with_substeps(s.substeps),
            substeps: s.substeps,
            wet,
            x0: mesh.nodes.clone(),
            node_ids: (0..mesh.nodes.len()).map(|i| mesh.node_id(i)).collect(),
            first_dt: case.coupling.dt.min(case.coupling.t_end),
            t_end: case.coupling.t_end,
            dt_stable,
            stable_rule,
            t: 0.0,
            steps: 0,
            checkpoints: dir.path().join("checkpoints"),
            load: vec![0.0; n],
            current: vec![0.0; n],
            disp: vec![[0.0; 3]; mesh.nodes.len()],
            probe_nodes: s.probes.iter().map(|p| mesh.nearest_node(p.point)).collect(),
            probes,
            probes_every: s.output_every.unwrap_or(1).max(1),
        })
    }

    /// Puts the checkpoint `ck` ([`Participant::write_checkpoint`]) back: the sequence goes on
    /// with PREDICT of step `ck.step` as if never stopped. An error names the file and field.
    fn restore(&mut self, ck: &Checkpoint) -> anyhow::Result<()> {
        let d = &mut self.dynamics;
        restore_state(&mut d.model, ck)?;
        let state = load_dynamics(ck, d.model.n_dof())?;
        d.resume(state, ck.f64("v_half").ok());
        self.scheme
            .restore(|name| ck.f64(&format!("coupling.{name}")).ok().map(<[f64]>::to_vec))
            .map_err(|e| anyhow!("checkpoint at step {}: {e}", ck.step))?;
        if let Some(rule) = self.stable_rule {
            self.dt_stable = rule.at(&self.dynamics.model);
        }
        (self.steps, self.t) = (ck.step, ck.time);
        Ok(())
    }

    /// What the launcher's `Hello` check compares.
    pub fn hello(&self, case: &Case) -> HelloInfo {
        HelloInfo {
            n_surface_nodes: self.wet.nodes.len() as u64,
            n_surface_elements: self.wet.elements.len() as u64,
            case_hash: case.hash(),
            capabilities: capability::RESTART | capability::INTERFACE_WORK,
        }
    }

    /// Publishes `x = X + u`, `v` (6 values per node) on the wet nodes for time `t`.
    fn publish(
        &self,
        ep: &mut StructureEndpoint,
        (step, t, dt): (u64, f64, f64),
        u: &[f64],
        v: &[f64],
    ) -> Result<(), Failure> {
        let header = StepHeader { step, time: t, dt, topology_version: 1, count: 0 };
        let (wet, x0) = (&self.wet.nodes, &self.x0);
        let ids = &self.node_ids;
        let id = |i: usize| ids[i];
        check_dofs("displacement sent", u, &id)
            .and_then(|()| check_dofs("velocity sent", v, &id))
            .map_err(|e| {
                Failure::new(
                    failure_code::SOLVER,
                    format!("step {step}, t = {t:e}: {e}: the structure diverged"),
                )
            })?;
        ep.publish_kinematics(header, wet.len(), |out: &mut [NodeState]| {
            for (o, &n) in out.iter_mut().zip(wet) {
                for k in 0..3 {
                    o.x[k] = x0[n][k] + u[6 * n + k];
                    o.v[k] = v[6 * n + k];
                }
            }
        })?;
        Ok(())
    }

    /// Publishes the scheme's prediction (`up`, `vp`).
    fn publish_prediction(
        &self,
        ep: &mut StructureEndpoint,
        at: (u64, f64, f64),
    ) -> Result<(), Failure> {
        self.publish(ep, at, &self.scheme.up, &self.scheme.vp)
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
        let dt = self.first_dt;
        let solver = |e: String| Failure::new(failure_code::SOLVER, format!("START: {e}"));
        if self.scheme.start(&mut self.dynamics, &self.load, dt).map_err(solver)? {
            self.publish_prediction(ep, (0, 0.5 * dt, dt))?;
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
        if self.dynamics.stepper.is_none() {
            return Err(Failure::new(
                failure_code::PROTOCOL,
                format!("PREDICT of step {n} before START"),
            ));
        }
        let load = if self.scheme.predict_reads_load(n) {
            self.read_loads(ep)?;
            Some(self.load.as_slice())
        } else {
            None
        };
        self.scheme
            .predict(&mut self.dynamics, dt, load)
            .map_err(|e| Failure::new(failure_code::SOLVER, format!("PREDICT of step {n}: {e}")))?;
        self.publish_prediction(ep, (n, self.scheme.predicted_time(t_from, dt), dt))
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
        if self.dynamics.stepper.is_none() {
            return Err(Failure::new(
                failure_code::PROTOCOL,
                format!("CORRECT of step {n} before START"),
            ));
        }
        self.scheme.correct(&mut self.dynamics, &self.load, dt).map_err(|e| {
            Failure::new(failure_code::SOLVER, format!("step {n} to t = {t_to}: {e}"))
        })?;
        self.check_state(n, t_to, dt)?;
        if let Some(rule) = self.stable_rule {
            self.dt_stable = rule.at(&self.dynamics.model);
            self.scheme.set_stable_step(self.dt_stable);
        }
        self.t = t_to;
        self.steps = n + 1;
        let (fields, d) = (self.fields.as_mut(), &self.dynamics);
        if let Some(f) = fields {
            f.gather(t_to, &d.model, Some(&d.model), d.velocity()).map_err(|e| {
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
        let d = &self.dynamics;
        let Some(state) = d.state() else { return Ok(()) };
        let (v, a, f_int) = (&state.v, &state.a, d.internal_force());
        let ids = &self.node_ids;
        let (scheme, substeps) = (self.scheme.scheme, self.substeps);
        check_state(&d.model, &mut self.disp, (v, a, f_int), &|i| ids[i]).map_err(|e| {
            let note = match unstable_coupling(dt, self.dt_stable, scheme, substeps) {
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
    /// accelerations (central differences: and `v^{n+1/2}`), and the scheme's own state (C0:
    /// `F^{n+1/2}`, `v^{n-1/2}`; A6: `â^n`). The midpoint rule's kept factor is dropped first,
    /// as in a run alone, so that a restart continues bitwise.
    fn write_checkpoint(&mut self, tag: &str) -> anyhow::Result<()> {
        self.dynamics.forget_factor();
        let Some(d) = self.dynamics.state() else {
            bail!("a checkpoint needs START first");
        };
        let mut ck = Checkpoint::new(self.steps, self.t);
        save_state(&self.dynamics.model, &mut ck)?;
        save_dynamics(&mut ck, d)?;
        if let Some(v) = self.dynamics.v_half() {
            ck.put("v_half", v.to_vec())?;
        }
        for (name, values) in self.scheme.history() {
            ck.put(&format!("coupling.{name}"), values)?;
        }
        ck.write(&self.checkpoints, tag, PART)?;
        Ok(())
    }

    /// One row of `structure_probes.csv` at the current state.
    fn write_probes(&mut self) -> Result<(), Failure> {
        self.dynamics.model.displacement(&mut self.disp);
        let v = self.dynamics.velocity();
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
        let (dt, stable) = (self.first_dt, self.dt_stable);
        if let Some(message) = unstable_coupling(dt, stable, self.scheme.scheme, self.substeps) {
            return Err(Failure::new(failure_code::SOLVER, message));
        }
        self.scheme.set_stable_step(stable);
        let header = StepHeader { step: 0, time: 0.0, dt: 0.0, topology_version: 1, count: 0 };
        let elements = &self.wet.elements;
        ep.publish_topology(header, elements.len(), |out| out.copy_from_slice(elements))?;
        self.dynamics.displacement(&mut self.current);
        // A restarted structure publishes the checkpoint's state; its probe file holds its row.
        let (step, t) = (self.steps, self.t);
        self.publish(ep, (step, t, 0.0), &self.current, self.dynamics.velocity())?;
        if step == 0 {
            self.write_probes()?;
        }
        let d = &self.dynamics;
        if let Some(f) = self.fields.as_mut() {
            f.gather(t, &d.model, Some(&d.model), d.velocity())
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
        Ok(Progress {
            step: c.step,
            t: self.t,
            dt_stable: self.dt_stable,
            interface_work: self.scheme.interface_work(),
        })
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
    restart: Option<&Path>,
) -> anyhow::Result<()> {
    let case = Case::load(case_path, set)?;
    let out = out
        .or_else(|| case.output.dir.as_ref().map(|d| case.dir().join(d)))
        .unwrap_or_else(|| PathBuf::from("runs").join(format!("{}-structure", case.case.name)));
    let mut participant = Participant::new(&case, &out, quiet, restart)?;
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
