//! IPC round-trip benchmark (DESIGN §3, §7 `fsi bench ipc`): the structure writes the kinematics of
//! n wet nodes, the fluid reads them and writes one load per node, the structure reads the loads.
//! Timed on the structure's side from the loan to the last load read, for iceoryx2 (in place,
//! event-driven waits, two nodes in two threads) and, for comparison, a Unix socket pair (bytes
//! copied in and out). Speed is measured here, never asserted in tests.

use crate::endpoint::{FluidEndpoint, ProtocolError, StructureEndpoint, Timeouts};
use crate::handshake::HelloInfo;
use crate::messages::{NodeLoad, NodeState, StepHeader};
use crate::shm;
use serde::Serialize;
use std::io::{Read, Write};
use std::os::unix::net::UnixStream;
use std::time::Instant;

/// One transport at one size.
#[derive(Debug, Clone, Serialize)]
pub struct IpcBenchRow {
    pub transport: String,
    pub nodes: u64,
    pub repeats: u64,
    /// Round trip (kinematics out, loads back) [µs].
    pub round_trip_us_median: f64,
    pub round_trip_us_min: f64,
    /// Payload bytes moved per round trip (48 per node out, 24 back).
    pub bytes_per_round_trip: u64,
}

/// The whole benchmark.
#[derive(Debug, Clone, Serialize)]
pub struct IpcBench {
    pub cores: u64,
    pub rows: Vec<IpcBenchRow>,
}

/// The sizes of `fsi bench ipc`.
pub const DEFAULT_SIZES: [usize; 4] = [1_000, 10_000, 100_000, 1_000_000];

/// Runs both transports at each size; `run_id` names the iceoryx2 run (removed afterwards).
pub fn run(run_id: &str, sizes: &[usize]) -> Result<IpcBench, ProtocolError> {
    let mut rows = Vec::new();
    for &n in sizes {
        let repeats = (2_000_000 / n.max(1)).clamp(10, 1000);
        rows.push(row("iceoryx2", n, repeats, iceoryx2_round_trips(run_id, n, repeats))?);
        rows.push(row("unix-socket", n, repeats, socket_round_trips(n, repeats))?);
    }
    let cores = std::thread::available_parallelism().map_or(1, |c| c.get()) as u64;
    Ok(IpcBench { cores, rows })
}

fn row(
    transport: &str,
    n: usize,
    repeats: usize,
    times: Result<Vec<f64>, ProtocolError>,
) -> Result<IpcBenchRow, ProtocolError> {
    let mut t = times?;
    t.sort_by(f64::total_cmp);
    Ok(IpcBenchRow {
        transport: transport.to_string(),
        nodes: n as u64,
        repeats: repeats as u64,
        round_trip_us_median: t[t.len() / 2] * 1e6,
        round_trip_us_min: t[0] * 1e6,
        bytes_per_round_trip: (n * (48 + 24)) as u64,
    })
}

/// The fluid's answer to a node: a load that depends on its state (so nothing is optimized away).
fn load_of(s: &NodeState) -> NodeLoad {
    NodeLoad { f: [-s.v[0] - s.x[0], -s.v[1], -s.v[2]] }
}

fn iceoryx2_round_trips(run_id: &str, n: usize, repeats: usize) -> Result<Vec<f64>, ProtocolError> {
    let id = format!("{run_id}-n{n}");
    let info = HelloInfo {
        n_surface_nodes: n as u64,
        n_surface_elements: 0,
        case_hash: 0,
        capabilities: 0,
    };
    let timeouts = Timeouts::default();
    let result = (|| {
        let mut s = StructureEndpoint::open(&id, info, timeouts)?;
        // The fluid's ports live in its own thread (iceoryx2 ipc ports are not Send); the
        // structure publishes only once they exist.
        let (opened, is_open) = std::sync::mpsc::channel();
        let fluid_id = id.clone();
        let fluid = std::thread::spawn(move || -> Result<(), ProtocolError> {
            let mut f = FluidEndpoint::open(&fluid_id, info, timeouts)?;
            let _ = opened.send(());
            for _ in 0..repeats + 1 {
                f.answer_kinematics(|_, nodes, loads| {
                    for (l, s) in loads.iter_mut().zip(nodes) {
                        *l = load_of(s);
                    }
                })?;
            }
            Ok(())
        });
        if is_open.recv().is_err() {
            return match fluid.join() {
                Ok(Err(e)) => Err(e),
                _ => Err(ProtocolError::Setup("the bench's fluid thread ended early".into())),
            };
        }
        let mut times = Vec::with_capacity(repeats);
        let mut check = 0.0;
        for step in 0..repeats + 1 {
            let start = Instant::now();
            let header = StepHeader {
                step: step as u64,
                time: step as f64,
                dt: 1.0,
                topology_version: 1,
                count: 0,
            };
            s.publish_kinematics(header, n, |nodes| {
                for (i, x) in nodes.iter_mut().enumerate() {
                    *x = NodeState { x: [i as f64, 0.0, 0.0], v: [step as f64, 1.0, 2.0] };
                }
            })?;
            check += s.read_loads(|_, loads| loads.iter().map(|l| l.f[0]).sum::<f64>())?;
            // The first round trip maps the segments: not timed.
            if step > 0 {
                times.push(start.elapsed().as_secs_f64());
            }
        }
        fluid
            .join()
            .map_err(|_| ProtocolError::Setup("the bench's fluid thread panicked".into()))??;
        std::hint::black_box(check);
        Ok(times)
    })();
    shm::cleanup_run(&id)?;
    result
}

fn socket_round_trips(n: usize, repeats: usize) -> Result<Vec<f64>, ProtocolError> {
    let err = |e: std::io::Error| ProtocolError::Setup(format!("unix socket: {e}"));
    let (mut s, mut f) = UnixStream::pair().map_err(err)?;
    let fluid = std::thread::spawn(move || -> std::io::Result<()> {
        let mut kin = vec![0u8; n * 48];
        let mut out = vec![0u8; n * 24];
        for _ in 0..repeats + 1 {
            f.read_exact(&mut kin)?;
            for (node, o) in kin.chunks_exact(48).zip(out.chunks_exact_mut(24)) {
                let v: [f64; 6] = std::array::from_fn(|k| {
                    f64::from_le_bytes(node[8 * k..8 * k + 8].try_into().unwrap())
                });
                let l = load_of(&NodeState { x: [v[0], v[1], v[2]], v: [v[3], v[4], v[5]] });
                for k in 0..3 {
                    o[8 * k..8 * k + 8].copy_from_slice(&l.f[k].to_le_bytes());
                }
            }
            f.write_all(&out)?;
        }
        Ok(())
    });
    let mut kin = vec![0u8; n * 48];
    let mut back = vec![0u8; n * 24];
    let mut times = Vec::with_capacity(repeats);
    let mut check = 0.0;
    for step in 0..repeats + 1 {
        let start = Instant::now();
        for (i, node) in kin.chunks_exact_mut(48).enumerate() {
            let v = [i as f64, 0.0, 0.0, step as f64, 1.0, 2.0];
            for k in 0..6 {
                node[8 * k..8 * k + 8].copy_from_slice(&v[k].to_le_bytes());
            }
        }
        s.write_all(&kin).map_err(err)?;
        s.read_exact(&mut back).map_err(err)?;
        check += back
            .chunks_exact(24)
            .map(|l| f64::from_le_bytes(l[..8].try_into().unwrap()))
            .sum::<f64>();
        if step > 0 {
            times.push(start.elapsed().as_secs_f64());
        }
    }
    fluid
        .join()
        .map_err(|_| ProtocolError::Setup("the bench's socket thread panicked".into()))?
        .map_err(err)?;
    std::hint::black_box(check);
    Ok(times)
}

#[cfg(test)]
mod tests {
    #[test]
    fn both_transports_run_and_report_every_size() {
        let b = super::run(&format!("t{}-bench", std::process::id()), &[10, 1000]).unwrap();
        assert_eq!(b.rows.len(), 4);
        assert!(b.rows.iter().all(|r| r.round_trip_us_min > 0.0 && r.repeats >= 10));
        assert!(crate::shm::run_files(&format!("t{}-bench-n10", std::process::id())).is_empty());
    }
}
