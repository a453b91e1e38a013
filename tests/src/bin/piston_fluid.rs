//! `piston-fluid`: the analytic acoustic-column fluid participant. The face's load is
//! F = -A (p0 + ρ0 c0 v·n) n (linear acoustics of a semi-infinite column, `[fluid.piston]`), with
//! v the mean velocity of the wet nodes read from the kinematics; F is spread equally over the
//! nodes. It computes nothing else.
//!
//! - `piston-fluid run CASE [--couple RUN_ID] [--out DIR] [--set key=value]... [--force]`;
//!   alone, the face is at rest and the pressure stays p0, written into a fresh folder (a
//!   non-empty one only with `--force`); coupled, into the launcher's folder.
//! - `piston-fluid check CASE [--set key=value]...`: everything `run` does before the first step,
//!   then a one-line summary; creates no file.
//!
//! Writes `probes.csv` (`time,<probe>.rho,<probe>.vx,<probe>.vy,<probe>.vz,<probe>.p`: the
//! acoustic state at the face, ρ = ρ0 + (p - p0)/c0²). Kinematics that are not finite fail the
//! step, naming the wet node, the time and the step.

use clap::{Parser, Subcommand};
use interface_protocol::case::{Case, PistonFluid};
use interface_protocol::cli::{CheckArgs, RunArgs};
use interface_protocol::endpoint::{FluidEndpoint, Timeouts};
use interface_protocol::handshake::HelloInfo;
use interface_protocol::io::finite::FiniteScan;
use interface_protocol::io::outdir::{OutputDir, Policy};
use interface_protocol::io::probes::{check_probe_name, ProbeError, ProbeWriter};
use interface_protocol::messages::{Command, NodeLoad, NodeState, StepHeader};
use interface_protocol::participant::{failure_code, serve, Failure, Handler, Progress};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(name = "piston-fluid", version, about = "Analytic acoustic-column fluid participant")]
struct Cli {
    #[command(subcommand)]
    command: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Run a case: coupled with --couple RUN_ID, alone (face at rest) otherwise.
    Run(RunArgs),
    /// Check a case as `run` would before its first step, then exit.
    Check(CheckArgs),
}

/// The face: its acoustic law and the probe file.
struct Piston {
    law: PistonFluid,
    probes: ProbeWriter,
}

fn probe_failure(e: ProbeError) -> Failure {
    Failure::new(failure_code::IO, format!("cannot write probes.csv: {e}"))
}

/// Everything `run` does before its first step, shared with `check`: the case's
/// `[fluid.piston]` law with a usable probe name.
fn setup(case: &Case) -> Result<PistonFluid, String> {
    let file = case.source.path.display();
    let law = case
        .fluid
        .as_ref()
        .and_then(|f| f.piston.clone())
        .ok_or_else(|| format!("{file}: piston-fluid needs a [fluid.piston] section"))?;
    check_probe_name(&law.probe).map_err(|e| format!("{file}: field `fluid.piston.probe`: {e}"))?;
    Ok(law)
}

impl Piston {
    fn new(law: PistonFluid, out: &OutputDir) -> Result<Piston, String> {
        let probes = ProbeWriter::fluid(out.path(), &[law.probe.as_str()])
            .map_err(|e| format!("cannot create the probe file: {e}"))?;
        Ok(Piston { law, probes })
    }

    /// Face pressure for the face velocity `v`: p = p0 + ρ0 c0 v·n.
    fn pressure(&self, v: [f64; 3]) -> f64 {
        let vn: f64 = (0..3).map(|i| v[i] * self.law.normal[i]).sum();
        self.law.p0 + self.law.rho0 * self.law.c0 * vn
    }

    /// Reads the kinematics, publishes the loads at `t`, writes the probe row.
    fn respond(
        &mut self,
        ep: &mut FluidEndpoint,
        step: u64,
        t: f64,
        dt: f64,
    ) -> Result<(), Failure> {
        let (v, n, bad) = ep.read_kinematics(|_, nodes: &[NodeState]| {
            (mean_velocity(nodes), nodes.len(), non_finite(nodes))
        })?;
        if let Some(what) = bad {
            return Err(Failure::new(
                failure_code::SOLVER,
                format!("the structure sent {what} for t = {t:e} (coupling step {step})"),
            ));
        }
        let Some(v) = v else {
            return Err(Failure::new(failure_code::PROTOCOL, "the kinematics hold no wet node"));
        };
        let p = self.pressure(v);
        if !p.is_finite() {
            return Err(Failure::new(
                failure_code::SOLVER,
                format!("the face pressure is {p} at t = {t:e} (coupling step {step})"),
            ));
        }
        let per_node = -self.law.area * p / n as f64;
        let header = StepHeader { step, time: t, dt, topology_version: 1, count: 0 };
        let normal = self.law.normal;
        ep.publish_loads(header, n, |loads: &mut [NodeLoad]| {
            loads.fill(NodeLoad { f: normal.map(|c| per_node * c) })
        })?;
        self.row(t, v, p).map_err(probe_failure)
    }

    fn row(&mut self, t: f64, v: [f64; 3], p: f64) -> Result<(), ProbeError> {
        let rho = self.law.rho0 + (p - self.law.p0) / (self.law.c0 * self.law.c0);
        self.probes.write_row(t, &[rho, v[0], v[1], v[2], p])
    }
}

/// Mean velocity of the wet nodes, `None` if there are none.
fn mean_velocity(nodes: &[NodeState]) -> Option<[f64; 3]> {
    if nodes.is_empty() {
        return None;
    }
    let mut v = [0.0; 3];
    for n in nodes {
        for i in 0..3 {
            v[i] += n.v[i];
        }
    }
    Some(v.map(|c| c / nodes.len() as f64))
}

/// The first non-finite position or velocity of the wet nodes, said in words.
fn non_finite(nodes: &[NodeState]) -> Option<String> {
    nodes.iter().enumerate().find_map(|(i, n)| {
        [("position", &n.x), ("velocity", &n.v)].into_iter().find_map(|(what, x)| {
            x[..].first_non_finite().map(|b| {
                let c = ["x", "y", "z"][b.index];
                format!("a non-finite {what} {} (component {c}) of wet node {i}", b.value)
            })
        })
    })
}

impl Handler<FluidEndpoint> for Piston {
    fn init(&mut self, ep: &mut FluidEndpoint) -> Result<f64, Failure> {
        // The face needs no elements, but the topology is part of the start-up: consume it.
        ep.read_topology(|_, _| ())?;
        self.respond(ep, 0, 0.0, 0.0)?;
        Ok(f64::INFINITY)
    }

    fn advance(&mut self, ep: &mut FluidEndpoint, c: &Command) -> Result<Progress, Failure> {
        // Every fluid Advance (NONE, or C0's START half step) returns the load at t_to for the
        // face state received for t_to.
        self.respond(ep, c.step, c.t_to, c.t_to - c.t_from)?;
        Ok(Progress { step: c.step, t: c.t_to, dt_stable: f64::INFINITY, interface_work: 0.0 })
    }

    fn checkpoint(&mut self, _ep: &mut FluidEndpoint, _tag: &str) -> Result<(), Failure> {
        // The face has no state of its own: a checkpoint only flushes the probes.
        self.probes.flush().map_err(probe_failure)
    }

    fn finish(&mut self, ep: &mut FluidEndpoint) -> Result<(), Failure> {
        self.checkpoint(ep, "")
    }
}

fn main() -> ExitCode {
    let result = match Cli::parse().command {
        Cmd::Run(args) => run(&args),
        Cmd::Check(args) => check(&args).map(|summary| println!("piston-fluid: {summary}")),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("piston-fluid: {message}");
            ExitCode::FAILURE
        }
    }
}

fn check(args: &CheckArgs) -> Result<String, String> {
    let case = args.load_case().map_err(|e| e.to_string())?;
    let law = setup(&case)?;
    Ok(format!(
        "{}: ok: face `{}`, area {:e} m², p0 {:e} Pa, impedance ρ0 c0 {:e} kg/(m² s), normal \
         {:?}; {} coupling steps to t_end {:e} s",
        case.source.path.display(),
        law.probe,
        law.area,
        law.p0,
        law.rho0 * law.c0,
        law.normal,
        case.coupling.n_steps(),
        case.coupling.t_end
    ))
}

fn run(args: &RunArgs) -> Result<(), String> {
    let case = args.load_case().map_err(|e| e.to_string())?;
    let law = setup(&case)?;
    let dir =
        args.out_dir(&case, || PathBuf::from("runs").join(format!("{}-piston", case.case.name)));
    // Coupled, the launcher made the folder; alone, the folder rule of every binary.
    let policy =
        if args.couple.is_some() { Policy::Existing } else { Policy::from_force(args.force) };
    let out = OutputDir::create(dir, policy).map_err(|e| e.to_string())?;
    let mut piston = Piston::new(law, &out)?;
    let Some(run_id) = args.couple.as_deref() else {
        // Alone: the face at rest, the pressure p0 at every coupling time.
        let c = &case.coupling;
        let p = piston.pressure([0.0; 3]);
        for step in 0..=c.n_steps() {
            let t = (step as f64 * c.dt).min(c.t_end);
            piston.row(t, [0.0; 3], p).map_err(|e| e.to_string())?;
        }
        return piston.probes.flush().map_err(|e| e.to_string());
    };
    let info = HelloInfo {
        n_surface_nodes: 0,
        n_surface_elements: 0,
        case_hash: case.hash(),
        capabilities: 0,
    };
    let mut endpoint =
        FluidEndpoint::open(run_id, info, Timeouts::from_secs(case.coupling.timeout_s))
            .map_err(|e| format!("cannot join run {run_id}: {e}"))?;
    let result = serve(&mut endpoint, &mut piston);
    drop(endpoint);
    result.map_err(|e| format!("run {run_id} stopped: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn non_finite_kinematics_name_the_wet_node_and_component() {
        let mut nodes = vec![NodeState::default(); 3];
        assert_eq!(non_finite(&nodes), None);
        nodes[2].v[1] = f64::NAN;
        assert_eq!(
            non_finite(&nodes).as_deref(),
            Some("a non-finite velocity NaN (component y) of wet node 2")
        );
        nodes[1].x[0] = f64::INFINITY;
        assert_eq!(
            non_finite(&nodes).as_deref(),
            Some("a non-finite position inf (component x) of wet node 1")
        );
    }
}
