//! `piston-fluid`: the analytic acoustic-column fluid participant. The face's load is
//! F = -A (p0 + ρ0 c0 v·n) n (linear acoustics of a semi-infinite column, `[fluid.piston]`), with
//! v the mean velocity of the wet nodes read from the kinematics; F is spread equally over the
//! nodes. It computes nothing else.
//!
//! `piston-fluid run CASE [--couple RUN_ID] [--out DIR] [--set key=value]...`; alone, the face is
//! at rest and the pressure stays p0. Writes `probes.csv` (`time,<probe>.rho,<probe>.vx,
//! <probe>.vy,<probe>.vz,<probe>.p`: the acoustic state at the face, ρ = ρ0 + (p - p0)/c0²).

use clap::{Parser, Subcommand};
use interface_protocol::case::PistonFluid;
use interface_protocol::cli::RunArgs;
use interface_protocol::endpoint::{FluidEndpoint, Timeouts};
use interface_protocol::handshake::HelloInfo;
use interface_protocol::messages::{Command, NodeLoad, NodeState, StepHeader};
use interface_protocol::participant::{failure_code, serve, Failure, Handler, Progress};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
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
}

/// The face: its acoustic law and the probe file.
struct Piston {
    law: PistonFluid,
    probes: BufWriter<File>,
}

impl Piston {
    fn new(law: PistonFluid, out: &Path) -> Result<Piston, String> {
        std::fs::create_dir_all(out)
            .map_err(|e| format!("cannot create {}: {e}", out.display()))?;
        let path = out.join("probes.csv");
        let mut probes = BufWriter::new(
            File::create(&path).map_err(|e| format!("cannot create {}: {e}", path.display()))?,
        );
        let p = &law.probe;
        writeln!(probes, "time,{p}.rho,{p}.vx,{p}.vy,{p}.vz,{p}.p").map_err(|e| e.to_string())?;
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
        let (v, n) =
            ep.read_kinematics(|_, nodes: &[NodeState]| (mean_velocity(nodes), nodes.len()))?;
        let Some(v) = v else {
            return Err(Failure::new(failure_code::PROTOCOL, "the kinematics hold no wet node"));
        };
        let p = self.pressure(v);
        let per_node = -self.law.area * p / n as f64;
        let header = StepHeader { step, time: t, dt, topology_version: 1, count: 0 };
        let normal = self.law.normal;
        ep.publish_loads(header, n, |loads: &mut [NodeLoad]| {
            loads.fill(NodeLoad { f: normal.map(|c| per_node * c) })
        })?;
        self.row(t, v, p)
            .map_err(|e| Failure::new(failure_code::IO, format!("cannot write probes.csv: {e}")))
    }

    fn row(&mut self, t: f64, v: [f64; 3], p: f64) -> std::io::Result<()> {
        let rho = self.law.rho0 + (p - self.law.p0) / (self.law.c0 * self.law.c0);
        writeln!(
            self.probes,
            "{t:.17e},{rho:.17e},{:.17e},{:.17e},{:.17e},{p:.17e}",
            v[0], v[1], v[2]
        )
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
        Ok(Progress { step: c.step, t: c.t_to, dt_stable: f64::INFINITY })
    }

    fn checkpoint(&mut self, _ep: &mut FluidEndpoint, _tag: &str) -> Result<(), Failure> {
        // The face has no state of its own: a checkpoint only flushes the probes.
        self.probes
            .flush()
            .map_err(|e| Failure::new(failure_code::IO, format!("cannot write probes.csv: {e}")))
    }

    fn finish(&mut self, ep: &mut FluidEndpoint) -> Result<(), Failure> {
        self.checkpoint(ep, "")
    }
}

fn main() -> ExitCode {
    let Cmd::Run(args) = Cli::parse().command;
    match run(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("piston-fluid: {message}");
            ExitCode::FAILURE
        }
    }
}

fn run(args: &RunArgs) -> Result<(), String> {
    let case = args.load_case().map_err(|e| e.to_string())?;
    let case_path = &args.case;
    let law = case.fluid.as_ref().and_then(|f| f.piston.clone()).ok_or_else(|| {
        format!("{}: piston-fluid needs a [fluid.piston] section", case_path.display())
    })?;
    let out =
        args.out_dir(&case, || PathBuf::from("runs").join(format!("{}-piston", case.case.name)));
    let mut piston = Piston::new(law, &out)?;
    let Some(run_id) = args.couple.as_deref() else {
        // Alone: the face at rest, the pressure p0 at every coupling time.
        let c = &case.coupling;
        let p = piston.pressure([0.0; 3]);
        for step in 0..=c.n_steps() {
            let t = (step as f64 * c.dt).min(c.t_end);
            piston.row(t, [0.0; 3], p).map_err(|e| format!("cannot write probes.csv: {e}"))?;
        }
        return piston.probes.flush().map_err(|e| format!("cannot write probes.csv: {e}"));
    };
    let info = HelloInfo { n_surface_nodes: 0, n_surface_elements: 0, case_hash: case.hash() };
    let mut endpoint =
        FluidEndpoint::open(run_id, info, Timeouts::from_secs(case.coupling.timeout_s))
            .map_err(|e| format!("cannot join run {run_id}: {e}"))?;
    let result = serve(&mut endpoint, &mut piston);
    drop(endpoint);
    result.map_err(|e| format!("run {run_id} stopped: {e}"))
}
