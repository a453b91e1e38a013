//! The rigid structure through the coupling sequence (coupling-sequence, DESIGN §4): the scheme's
//! structure state (`coupling::Staggered`) on the body's DOFs, prescribed DOFs imposed, loads
//! reduced from the wet nodes, kinematics written in place into the shared buffer.

use crate::finite::{check_dofs, check_loads, At};
use crate::model::Body;
use crate::setup::Setup;
use interface_protocol::coupling::{Oscillators, Staggered};
use interface_protocol::endpoint::StructureEndpoint;
use interface_protocol::io::checkpoint::{self, Checkpoint};
use interface_protocol::io::outdir::OutputDir;
use interface_protocol::io::probes::{ProbeError, ProbeWriter};
use interface_protocol::messages::{scheme_phase, Command, NodeLoad, StepHeader};
use interface_protocol::participant::{failure_code, Failure, Handler, Progress};
use std::path::Path;

mod restart_state;

/// The checkpoint part the rigid structure writes: `checkpoints/<tag>/structure.ckpt`.
pub const CHECKPOINT_PART: &str = "structure";

/// The rigid structure's state.
pub struct RigidSolver {
    pub body: Body,
    /// The body's DOFs and their state (`u`, `v`, `a`), and the scheme's own state.
    pub state: Oscillators,
    pub scheme: Staggered,
    /// Scratch for reduced loads.
    load: Vec<f64>,
    /// Time the state `u`, `v`, `a` refers to.
    pub t: f64,
    probes: ProbeWriter,
    probes_every: u64,
    out: OutputDir,
    /// Coupling steps completed.
    steps: u64,
    /// Length of the first coupling step (Δt, or t_end if that is shorter).
    first_dt: f64,
}

fn io_failure(what: &str, e: impl std::fmt::Display) -> Failure {
    Failure::new(failure_code::IO, format!("{what}: {e}"))
}

fn probe_failure(e: ProbeError) -> Failure {
    io_failure("cannot write structure_probes.csv", e)
}

impl RigidSolver {
    /// The solver of a case's setup, writing `structure_probes.csv` and checkpoints into `out`.
    pub fn new(setup: Setup, out: OutputDir) -> Result<RigidSolver, String> {
        Self::open(setup, out, None)
    }

    /// The solver continuing a coupled run from the checkpoint `--restart dir` names
    /// (`checkpoint::restart_point`): the state, the scheme's history and the step restored,
    /// `structure_probes.csv` kept up to the checkpoint's time.
    pub fn resumed(setup: Setup, out: OutputDir, dir: &Path) -> Result<RigidSolver, String> {
        let found = checkpoint::restart_point(dir, CHECKPOINT_PART)
            .map_err(|e| e.to_string())?
            .ok_or_else(|| format!("--restart {}: no structure checkpoint there", dir.display()))?;
        let file = found.dir.join(format!("{CHECKPOINT_PART}.{}", checkpoint::EXTENSION));
        let ck = Checkpoint::read_file(&file).map_err(|e| e.to_string())?;
        let mut solver = Self::open(setup, out, Some(ck.time))?;
        solver.restore(&ck).map_err(|e| format!("checkpoint `{}`: {e}", file.display()))?;
        Ok(solver)
    }

    /// [`RigidSolver::new`]; with `resume_at` the probe file is continued from that time.
    fn open(setup: Setup, out: OutputDir, resume_at: Option<f64>) -> Result<RigidSolver, String> {
        let Setup { body, scheme, dt, t_end, probes_every, .. } = setup;
        let mut state = Oscillators::new(body.dynamics.clone(), &body.u0, &body.v0);
        body.impose(0.0, &mut state.u, &mut state.v, Some(&mut state.a));
        let scheme = Staggered::new(scheme, body.u0.len());
        let probes = ProbeWriter::structure_from(out.path(), &[body.probe.as_str()], resume_at)
            .map_err(|e| format!("cannot open the probe file: {e}"))?;
        Ok(RigidSolver {
            load: vec![0.0; body.dofs.len()],
            body,
            state,
            scheme,
            t: 0.0,
            probes,
            probes_every,
            out,
            steps: 0,
            first_dt: dt.min(t_end),
        })
    }

    /// Number of wet nodes.
    pub fn n_nodes(&self) -> usize {
        self.body.wet_nodes.len()
    }

    /// The stable coupling step of the scheme's structure integrator.
    pub fn dt_stable(&self) -> f64 {
        crate::setup::dt_stable(self.scheme.scheme, &self.body)
    }

    /// Where a check of step `step` of length `dt` at time `t` happens.
    fn at(&self, t: f64, step: u64, dt: f64) -> At {
        At { t, step, dt, dt_stable: self.dt_stable() }
    }

    /// The kinematics to publish are finite.
    fn check_prediction(&self, at: At) -> Result<(), Failure> {
        check_dofs(&self.body, "predicted displacement", &self.scheme.up, at)?;
        check_dofs(&self.body, "predicted velocity", &self.scheme.vp, at)
    }

    /// The state reached is finite.
    fn check_state(&self, at: At) -> Result<(), Failure> {
        check_dofs(&self.body, "displacement", &self.state.u, at)?;
        check_dofs(&self.body, "velocity", &self.state.v, at)?;
        check_dofs(&self.body, "acceleration", &self.state.a, at)
    }

    /// START with the generalized load F^0 in `self.load`; returns whether a prediction is due.
    fn start(&mut self, dt: f64) -> Result<bool, Failure> {
        let Ok(publish) = self.scheme.start(&mut self.state, &self.load, dt);
        let s = &mut self.state;
        self.body.impose(0.0, &mut s.u, &mut s.v, Some(&mut s.a));
        let p = &mut self.scheme;
        self.body.impose(0.5 * dt, &mut p.up, &mut p.vp, None);
        self.check_state(self.at(0.0, 0, dt))?;
        self.check_prediction(self.at(0.5 * dt, 0, dt))?;
        Ok(publish)
    }

    /// PREDICT of step `step`, [t_from, t_from + dt]; `load` carries F^{1/2} at C0's first step.
    fn predict(
        &mut self,
        step: u64,
        t_from: f64,
        dt: f64,
        with_load: bool,
    ) -> Result<f64, Failure> {
        let load = with_load.then_some(self.load.as_slice());
        let Ok(()) = self.scheme.predict(&mut self.state, dt, load);
        let target = self.scheme.predicted_time(t_from, dt);
        let p = &mut self.scheme;
        self.body.impose(target, &mut p.up, &mut p.vp, None);
        self.check_prediction(self.at(target, step, dt))?;
        Ok(target)
    }

    /// CORRECT of step `step` with the generalized load in `self.load`; the state reaches `t_to`.
    fn correct(&mut self, step: u64, t_to: f64, dt: f64) -> Result<(), Failure> {
        let Ok(()) = self.scheme.correct(&mut self.state, &self.load, dt);
        let s = &mut self.state;
        self.body.impose(t_to, &mut s.u, &mut s.v, Some(&mut s.a));
        self.check_state(self.at(t_to, step, dt))?;
        self.t = t_to;
        self.steps = step + 1;
        Ok(())
    }

    /// Writes the probe row of the current state.
    fn write_probe(&mut self) -> Result<(), Failure> {
        let (u, v) = (self.body.full(&self.state.u), self.body.full(&self.state.v));
        self.probes.write_row(self.t, &[u[0], u[1], u[2], v[0], v[1], v[2]]).map_err(probe_failure)
    }

    /// Integrates alone from 0 to `t_end` with zero fluid load, the scheme's structure integrator
    /// (central difference for CSS and C0, implicit midpoint for A6).
    pub fn run_alone(&mut self, dt: f64, n_steps: u64, t_end: f64) -> Result<(), Failure> {
        self.write_probe()?;
        self.load.fill(0.0);
        self.start(dt)?;
        for step in 0..n_steps {
            let t_from = step as f64 * dt;
            let t_to = if step + 1 == n_steps { t_end } else { t_from + dt };
            self.load.fill(0.0);
            let with_load = self.scheme.predict_reads_load(step);
            self.predict(step, t_from, t_to - t_from, with_load)?;
            self.correct(step, t_to, t_to - t_from)?;
            if (step + 1) % self.probes_every == 0 || step + 1 == n_steps {
                self.write_probe()?;
            }
        }
        self.probes.flush().map_err(probe_failure)
    }

    /// Publishes the kinematics (`up`, `vp` when `predicted`, else `u`, `v`) for time `t`.
    fn publish(
        &self,
        ep: &mut StructureEndpoint,
        step: u64,
        t: f64,
        dt: f64,
        predicted: bool,
    ) -> Result<(), Failure> {
        let (u, v) = if predicted {
            (&self.scheme.up, &self.scheme.vp)
        } else {
            (&self.state.u, &self.state.v)
        };
        let header = StepHeader { step, time: t, dt, topology_version: 1, count: 0 };
        ep.publish_kinematics(header, self.n_nodes(), |nodes| self.body.node_states(u, v, nodes))?;
        Ok(())
    }

    /// Reads the fluid's loads into `self.load` (generalized, at the current state); `at` names
    /// the step in the error of a non-finite load.
    fn read_loads(&mut self, ep: &mut StructureEndpoint, at: At) -> Result<(), Failure> {
        let n = self.n_nodes();
        let (body, u, load) = (&self.body, &self.state.u, &mut self.load);
        let (count, finite) = ep.read_loads(|_, loads: &[NodeLoad]| {
            let finite = check_loads(loads, at);
            if loads.len() == n && finite.is_ok() {
                body.reduce(u, loads, load);
            }
            (loads.len(), finite)
        })?;
        if count != n {
            return Err(Failure::new(
                failure_code::PROTOCOL,
                format!("the fluid sent {count} nodal loads, the structure has {n} wet nodes"),
            ));
        }
        finite
    }
}

impl Handler<StructureEndpoint> for RigidSolver {
    /// Publishes the topology and the state; a restarted solver publishes the checkpoint's state
    /// and writes no probe row (its file holds that one).
    fn init(&mut self, ep: &mut StructureEndpoint) -> Result<f64, Failure> {
        let (step, t) = (self.steps, self.t);
        let header = StepHeader { step, time: t, dt: 0.0, topology_version: 1, count: 0 };
        let elements = &self.body.elements;
        ep.publish_topology(header, elements.len(), |out| out.copy_from_slice(elements))?;
        self.publish(ep, step, t, 0.0, false)?;
        if step == 0 {
            self.write_probe()?;
        }
        Ok(self.dt_stable())
    }

    fn advance(&mut self, ep: &mut StructureEndpoint, c: &Command) -> Result<Progress, Failure> {
        let dt = c.t_to - c.t_from;
        match c.scheme_phase {
            scheme_phase::START => {
                // START carries t_from = t_to = 0: the first step's Δt comes from the case.
                let first = self.first_dt;
                self.read_loads(ep, self.at(0.0, c.step, first))?;
                if self.start(first)? {
                    self.publish(ep, 0, 0.5 * first, first, true)?;
                }
            }
            scheme_phase::PREDICT => {
                let with_load = self.scheme.predict_reads_load(c.step);
                if with_load {
                    self.read_loads(ep, self.at(c.t_from, c.step, dt))?;
                }
                let target = self.predict(c.step, c.t_from, dt, with_load)?;
                self.publish(ep, c.step, target, dt, true)?;
            }
            scheme_phase::CORRECT => {
                self.read_loads(ep, self.at(c.t_to, c.step, dt))?;
                self.correct(c.step, c.t_to, dt)?;
                if (c.step + 1) % self.probes_every == 0 {
                    self.write_probe()?;
                }
            }
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
            dt_stable: self.dt_stable(),
            interface_work: self.scheme.interface_work(),
        })
    }

    fn checkpoint(&mut self, _ep: &mut StructureEndpoint, tag: &str) -> Result<(), Failure> {
        self.write_checkpoint(tag)
    }

    fn finish(&mut self, _ep: &mut StructureEndpoint) -> Result<(), Failure> {
        self.probes.flush().map_err(probe_failure)
    }
}

/// The solver of `case` writing into the existing folder `dir` (tests).
#[cfg(test)]
fn solver_in(case: &interface_protocol::case::Case, dir: &std::path::Path) -> RigidSolver {
    use interface_protocol::io::outdir::Policy;
    let out = OutputDir::create(dir, Policy::Existing).unwrap();
    RigidSolver::new(Setup::new(case).unwrap(), out).unwrap()
}

/// The rows of `structure_probes.csv` in `dir`, header skipped (tests).
#[cfg(test)]
fn probe_rows(dir: &std::path::Path) -> Vec<Vec<f64>> {
    let csv = std::fs::read_to_string(dir.join("structure_probes.csv")).unwrap();
    csv.lines().skip(1).map(|l| l.split(',').map(|x| x.parse().unwrap()).collect()).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use interface_protocol::case::Case;
    use std::path::Path;

    /// m u'' + c u' + k u = 0, u(0) = u0, u'(0) = 0: the closed form.
    fn damped(m: f64, k: f64, c: f64, u0: f64, t: f64) -> f64 {
        let g = c / (2.0 * m);
        let wd = (k / m - g * g).sqrt();
        u0 * (-g * t).exp() * ((wd * t).cos() + g / wd * (wd * t).sin())
    }

    fn case(scheme: &str, dt: f64, extra: &str) -> Case {
        let text = format!(
            "[coupling]\nscheme = \"{scheme}\"\ndt = {dt:e}\nt_end = 1.0\n[structure.rigid]\nmass = 2.0\n\
             stiffness = 50.0\ndamping = 0.8\nu0 = 0.01\n{extra}"
        );
        Case::parse(&text, Path::new("case.toml"), &[]).unwrap()
    }

    fn final_error(scheme: &str, dt: f64) -> f64 {
        let dir = tempfile::tempdir().unwrap();
        let c = case(scheme, dt, "");
        let mut s = solver_in(&c, dir.path());
        s.run_alone(dt, c.coupling.n_steps(), 1.0).unwrap();
        assert_eq!(s.t, 1.0);
        (s.state.u[0] - damped(2.0, 50.0, 0.8, 0.01, 1.0)).abs()
    }

    #[test]
    fn central_difference_and_implicit_midpoint_converge_at_second_order() {
        for scheme in ["C0", "CSS", "A6"] {
            let e: Vec<f64> =
                [4e-3, 2e-3, 1e-3].iter().map(|&dt| final_error(scheme, dt)).collect();
            let p = (e[1] / e[2]).log2();
            assert!((1.9..2.1).contains(&p), "{scheme}: errors {e:?}, order {p}");
            assert!(e[2] < 1e-5, "{scheme}: error {}", e[2]);
        }
    }

    #[test]
    fn prescribed_motion_is_followed_exactly_and_probes_are_written() {
        let dir = tempfile::tempdir().unwrap();
        let extra = "probe = \"piston\"\n[[structure.rigid.prescribed]]\ndof = \"x\"\namplitude = 0.002\nfrequency = 3.0\n";
        let c = case("C0", 1e-2, extra);
        let mut s = solver_in(&c, dir.path());
        s.run_alone(1e-2, c.coupling.n_steps(), 1.0).unwrap();
        let w = 2.0 * std::f64::consts::PI * 3.0;
        assert!((s.state.u[0] - 0.002 * (1.0 - (w * 1.0).cos())).abs() < 1e-15);
        let csv = std::fs::read_to_string(dir.path().join("structure_probes.csv")).unwrap();
        let mut lines = csv.lines();
        assert_eq!(
            lines.next().unwrap(),
            "time,piston.ux,piston.uy,piston.uz,piston.vx,piston.vy,piston.vz"
        );
        assert_eq!(lines.count(), 101);
    }
}

#[cfg(test)]
mod failure_tests {
    //! A diverging state fails the step at once, before any probe row or checkpoint holds it.
    use super::*;
    use interface_protocol::case::Case;
    use interface_protocol::io::checkpoint;
    use std::path::Path;

    fn case(scheme: &str, dt: f64) -> Case {
        // ω = 100 rad/s: central differences are stable up to dt = 2e-2 s.
        let text = format!(
            "[coupling]\nscheme = \"{scheme}\"\ndt = {dt:e}\nt_end = 20.0\n[structure.rigid]\n\
             mass = 10.0\nstiffness = 1e5\nu0 = 0.01\nprobe = \"piston\"\n"
        );
        Case::parse(&text, Path::new("case.toml"), &[]).unwrap()
    }

    #[test]
    fn an_unstable_step_fails_naming_the_dof_the_step_and_the_stable_step() {
        let dir = tempfile::tempdir().unwrap();
        let c = case("C0", 0.03);
        let mut s = solver_in(&c, dir.path());
        let f = s.run_alone(0.03, c.coupling.n_steps(), 20.0).unwrap_err();
        assert_eq!(f.code, failure_code::SOLVER);
        let m = &f.message;
        assert!(m.contains("of DOF \"x\" is") && m.contains("coupling step"), "{m}");
        assert!(m.contains("above the stable step 2e-2 s"), "{m}");
        // It stopped long before t_end, and no probe row holds a NaN or an infinity.
        assert!(s.t < 20.0, "t = {}", s.t);
        drop(s);
        let rows = probe_rows(dir.path());
        assert!(rows.len() > 10, "{} rows", rows.len());
        assert!(rows.iter().flatten().all(|x| x.is_finite()), "a non-finite probe row");
        // The stable step converges, and A6 is unconditionally stable.
        let mut s = solver_in(&case("C0", 0.019), tempfile::tempdir().unwrap().path());
        s.run_alone(0.019, 50, 0.95).unwrap();
        let mut s = solver_in(&case("A6", 0.03), tempfile::tempdir().unwrap().path());
        s.run_alone(0.03, 100, 3.0).unwrap();
    }

    #[test]
    fn checkpoints_are_checksummed_parts_named_as_everywhere() {
        let dir = tempfile::tempdir().unwrap();
        let mut s = solver_in(&case("A6", 0.01), dir.path());
        s.run_alone(0.01, 5, 0.05).unwrap();
        s.write_checkpoint(&checkpoint::tag_for_step(5)).unwrap();
        let found = checkpoint::latest(&dir.path().join("checkpoints"), &[CHECKPOINT_PART])
            .unwrap()
            .unwrap();
        assert_eq!((found.tag.as_str(), found.step, found.time), ("step_0000000005", 5, 0.05));
        let ck = Checkpoint::read_file(&found.dir.join("structure.ckpt")).unwrap();
        assert_eq!(ck.meta::<Vec<String>>().unwrap(), ["x"]);
        assert_eq!(ck.f64("u").unwrap(), s.state.u.as_slice());
        assert_eq!(ck.f64("v").unwrap(), s.state.v.as_slice());
    }
}

#[cfg(test)]
mod coupled_tests {
    //! The rigid solver through the real transport: a launcher thread drives the coupling
    //! sequence, an analytic piston face answers in a fluid thread, and the piston's motion is
    //! compared with the closed form of m u'' + ρ0 c0 A u' + k u = -A p0.
    use super::*;
    use interface_protocol::case::Case;
    use interface_protocol::case::Scheme;
    use interface_protocol::endpoint::{ControlPort, FluidEndpoint, LauncherLink, Timeouts};
    use interface_protocol::handshake::HelloInfo;
    use interface_protocol::messages::{command_kind, reply_kind, Reply, Role};
    use interface_protocol::participant::serve;
    use std::path::Path;
    use std::time::{Duration, Instant};

    const M: f64 = 10.0;
    const K: f64 = 1e5;
    const A: f64 = 0.1;
    const P0: f64 = 1e5;
    const Z: f64 = 1.2 * 340.0; // ρ0 c0
    const T_END: f64 = 0.1;

    fn exact(t: f64) -> f64 {
        let ueq = -A * P0 / K;
        let g = Z * A / (2.0 * M);
        let wd = (K / M - g * g).sqrt();
        ueq + (-g * t).exp() * (-ueq * (wd * t).cos() - g * ueq / wd * (wd * t).sin())
    }

    /// The face: answers every fluid command with F = -A (p0 + ρ0 c0 v_x) on its single node.
    fn fluid(run_id: String) {
        let mut f =
            FluidEndpoint::open(&run_id, HelloInfo::default(), Timeouts::default()).unwrap();
        loop {
            let c = f.control().next_command().unwrap();
            if c.kind == command_kind::INIT {
                f.read_topology(|_, _| ()).unwrap();
            }
            if c.kind == command_kind::INIT || c.kind == command_kind::ADVANCE {
                f.answer_kinematics(|_, nodes, loads| {
                    loads[0].f = [-A * (P0 + Z * nodes[0].v[0]), 0.0, 0.0];
                })
                .unwrap();
            }
            f.control().reply(&Reply::done(c.step, c.t_to, f64::INFINITY, 0.0, 0.0)).unwrap();
            if c.kind == command_kind::FINISH {
                return;
            }
        }
    }

    /// Drives one coupled run (coupling-sequence) and returns the largest displacement error.
    fn coupled_error(scheme: &str, dt: f64) -> f64 {
        let run_id = format!("t{}-rigid-{scheme}-{}", std::process::id(), (1.0 / dt).round());
        let dir = tempfile::tempdir().unwrap();
        let text = format!(
            "[coupling]\nscheme = \"{scheme}\"\ndt = {dt:e}\nt_end = {T_END:e}\n\
             [structure.rigid]\nmass = {M:e}\nstiffness = {K:e}\n"
        );
        let case = Case::parse(&text, Path::new("case.toml"), &[]).unwrap();
        let mut link = LauncherLink::open(&run_id, Timeouts::default()).unwrap();
        let structure = {
            let (run_id, case, out) = (run_id.clone(), case.clone(), dir.path().to_path_buf());
            std::thread::spawn(move || {
                let mut solver = solver_in(&case, &out);
                let info = HelloInfo {
                    n_surface_nodes: 1,
                    n_surface_elements: 0,
                    case_hash: 0,
                    capabilities: 0,
                };
                let mut ep = StructureEndpoint::open(&run_id, info, Timeouts::default()).unwrap();
                serve(&mut ep, &mut solver).unwrap();
            })
        };
        let fluid = std::thread::spawn({
            let run_id = run_id.clone();
            move || fluid(run_id)
        });
        let soon = Instant::now() + Duration::from_secs(10);
        link.wait_hello(Role::Fluid, soon).unwrap();
        link.wait_hello(Role::Structure, soon).unwrap();
        let mut go = |role: Role, c: Command| {
            link.send(role, &c).unwrap();
            let r = link.wait_reply(role, Instant::now() + Duration::from_secs(10)).unwrap();
            assert_ne!(r.kind, reply_kind::FAILED, "{}: {}", c.describe(), r.message_str());
        };
        let c = &case.coupling;
        let n = c.n_steps();
        go(Role::Structure, Command::init());
        go(Role::Fluid, Command::init());
        go(Role::Structure, Command::advance(0, 0.0, 0.0, scheme_phase::START));
        if c.scheme == Scheme::C0 {
            go(Role::Fluid, Command::advance(0, 0.0, dt / 2.0, scheme_phase::START));
        }
        for k in 0..n {
            let t0 = k as f64 * dt;
            let t1 = if k + 1 == n { c.t_end } else { t0 + dt };
            go(Role::Structure, Command::advance(k, t0, t1, scheme_phase::PREDICT));
            let (from, to) = match c.scheme {
                Scheme::Css => (t0, t1),
                Scheme::C0 => (t0 + dt / 2.0, t1 + dt / 2.0),
                Scheme::A6 => ((t0 - dt / 2.0).max(0.0), t0 + dt / 2.0),
            };
            go(Role::Fluid, Command::advance(k, from, to, scheme_phase::NONE));
            go(Role::Structure, Command::advance(k, t0, t1, scheme_phase::CORRECT));
        }
        go(Role::Structure, Command::finish());
        go(Role::Fluid, Command::finish());
        structure.join().unwrap();
        fluid.join().unwrap();
        link.remove_resources().unwrap();
        let rows = probe_rows(dir.path());
        assert_eq!(rows.len() as u64, n + 1);
        rows.iter().map(|r| (r[1] - exact(r[0])).abs()).fold(0.0, f64::max)
    }

    #[test]
    fn coupled_piston_converges_at_the_order_of_each_scheme() {
        for (scheme, lo, hi) in [("C0", 1.8, 2.3), ("A6", 1.8, 2.3), ("CSS", 0.7, 1.3)] {
            let e = [coupled_error(scheme, 1e-3), coupled_error(scheme, 5e-4)];
            let p = (e[0] / e[1]).log2();
            eprintln!("{scheme}: max errors {e:?}, observed order {p:.2}");
            assert!((lo..hi).contains(&p), "{scheme}: errors {e:?}, order {p}");
        }
    }
}
