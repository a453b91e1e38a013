//! Real IPC between threads of one process (each with its own node): the transport, the handshake,
//! the deadlines and the clean-up.

use super::*;
use crate::endpoint::ControlPort;
use crate::handshake::HelloInfo;
use crate::messages::{
    reply_kind, Command, NodeLoad, NodeState, Reply, Role, StepHeader, SurfaceElement,
};
use crate::shm;
use std::thread;

/// A run id unique to this test and process.
fn run_id(test: &str) -> String {
    format!("t{}-{test}", std::process::id())
}

fn header(step: u64) -> StepHeader {
    StepHeader { step, time: step as f64 * 1e-3, dt: 1e-3, topology_version: 1, count: 0 }
}

fn quick() -> Timeouts {
    Timeouts { wait: Duration::from_secs(10), delivery: Duration::from_millis(200) }
}

#[test]
fn fluid_and_structure_exchange_ten_thousand_nodes_then_leave_no_file() {
    let id = run_id("exchange");
    const N: usize = 10_000;
    let info = HelloInfo {
        n_surface_nodes: N as u64,
        n_surface_elements: 1,
        case_hash: 5,
        capabilities: 0,
    };
    let mut link = LauncherLink::open(&id, quick()).unwrap();
    // Both sides subscribe before either publishes, as after the launcher's handshake.
    let both_open = std::sync::Arc::new(std::sync::Barrier::new(2));
    let structure = {
        let (id, both_open) = (id.clone(), both_open.clone());
        thread::spawn(move || {
            let mut s = StructureEndpoint::open(&id, info, quick()).unwrap();
            both_open.wait();
            s.publish_topology(header(0), 1, |e| e[0] = SurfaceElement::default()).unwrap();
            for step in 0..3u64 {
                let t = step as f64;
                s.publish_kinematics(header(step), N, |nodes| {
                    for (i, n) in nodes.iter_mut().enumerate() {
                        *n = NodeState { x: [i as f64, t, 0.0], v: [t, 0.0, 1.0] };
                    }
                })
                .unwrap();
                // The fluid answers each node with f = -(x + v): check every one came back.
                let bad = s
                    .read_loads(|h, loads| {
                        assert_eq!(h.step, step);
                        loads
                            .iter()
                            .enumerate()
                            .filter(|(i, l)| l.f != [-(*i as f64) - t, -t, -1.0])
                            .count()
                    })
                    .unwrap();
                assert_eq!(bad, 0);
            }
        })
    };
    let fluid = {
        let id = id.clone();
        thread::spawn(move || {
            let mut f = FluidEndpoint::open(&id, HelloInfo { n_surface_nodes: 0, ..info }, quick())
                .unwrap();
            both_open.wait();
            let n_el = f.read_topology(|h, e| (h.topology_version, e.len(), e[0].phi)).unwrap();
            assert_eq!(n_el, (1, 1, [1.0; 4]));
            for step in 0..3u64 {
                let (h, sums): (StepHeader, Vec<[f64; 3]>) = f
                    .read_kinematics(|h, nodes| {
                        (
                            *h,
                            nodes
                                .iter()
                                .map(|n| [n.x[0] + n.v[0], n.x[1] + n.v[1], n.x[2] + n.v[2]])
                                .collect(),
                        )
                    })
                    .unwrap();
                assert_eq!((h.step, h.count as usize), (step, N));
                f.publish_loads(h, N, |loads| {
                    for (l, s) in loads.iter_mut().zip(&sums) {
                        *l = NodeLoad { f: [-s[0], -s[1], -s[2]] };
                    }
                })
                .unwrap();
            }
        })
    };
    let soon = Instant::now() + Duration::from_secs(10);
    let f = link.wait_hello(Role::Fluid, soon).unwrap();
    let s = link.wait_hello(Role::Structure, soon).unwrap();
    LauncherLink::check(&f, &s, 5).unwrap();
    let e = LauncherLink::check(&f, &s, 6).unwrap_err().to_string();
    assert!(e.contains("launcher 0000000000000006"), "{e}");
    structure.join().unwrap();
    fluid.join().unwrap();
    assert!(!shm::run_files(&id).is_empty());
    link.remove_resources().unwrap();
    assert_eq!(shm::run_files(&id), Vec::<std::path::PathBuf>::new());
}

#[test]
fn commands_and_replies_travel_both_ways() {
    let id = run_id("control");
    let mut link = LauncherLink::open(&id, quick()).unwrap();
    let participant = {
        let id = id.clone();
        thread::spawn(move || {
            let mut s = StructureEndpoint::open(&id, HelloInfo::default(), quick()).unwrap();
            let mut seen = Vec::new();
            loop {
                let c = s.control().next_command().unwrap();
                seen.push(c.describe());
                let finish = c.kind == crate::messages::command_kind::FINISH;
                s.control().reply(&Reply::done(c.step, c.t_to, 1.0, 0.0, 0.0)).unwrap();
                if finish {
                    return seen;
                }
            }
        })
    };
    let soon = Instant::now() + Duration::from_secs(10);
    link.wait_hello(Role::Structure, soon).unwrap();
    for c in [Command::init(), Command::advance(0, 0.0, 0.5, 2), Command::finish()] {
        link.send(Role::Structure, &c).unwrap();
        let r = link.wait_reply(Role::Structure, Instant::now() + Duration::from_secs(10)).unwrap();
        assert_eq!((r.kind, r.step, r.t), (reply_kind::DONE, c.step, c.t_to));
    }
    let seen = participant.join().unwrap();
    assert_eq!(seen, ["Init", "Advance PREDICT step 0 [0, 0.5]", "Finish"]);
    link.remove_resources().unwrap();
    assert!(shm::run_files(&id).is_empty());
}

#[test]
fn waits_end_at_their_deadline_with_a_clear_error() {
    let id = run_id("timeout");
    let mut link = LauncherLink::open(&id, quick()).unwrap();
    let start = Instant::now();
    let e = link.wait_hello(Role::Fluid, start + Duration::from_millis(300)).unwrap_err();
    assert!(start.elapsed() >= Duration::from_millis(300));
    assert!(matches!(e, ProtocolError::Timeout { .. }), "{e:?}");
    assert!(e.to_string().contains("waiting for the hello of the fluid"), "{e}");
    let short = Timeouts { wait: Duration::from_millis(200), delivery: Duration::from_millis(100) };
    let mut s = StructureEndpoint::open(&id, HelloInfo::default(), short).unwrap();
    let e = s.read_loads(|_, l| l.len()).unwrap_err().to_string();
    assert!(e.starts_with("timed out after 0.2") && e.contains("surface/loads"), "{e}");
    let waited = Instant::now();
    let e = s.control().next_command().unwrap_err().to_string();
    assert!(e.contains("next command to the structure"), "{e}");
    // A command is awaited longer than a reply: 2 x 0.2 s + 0.2 s.
    assert!(e.starts_with("timed out after 0.6"), "{e}");
    assert!(waited.elapsed() >= short.command(), "{:?}", waited.elapsed());
    drop(s);
    link.remove_resources().unwrap();
    assert!(shm::run_files(&id).is_empty());
}

#[test]
fn a_second_sample_before_the_first_is_read_is_a_delivery_error() {
    let id = run_id("lockstep");
    let short = Timeouts { wait: Duration::from_secs(5), delivery: Duration::from_millis(100) };
    let mut s = StructureEndpoint::open(&id, HelloInfo::default(), short).unwrap();
    let mut f = FluidEndpoint::open(&id, HelloInfo::default(), short).unwrap();
    s.publish_kinematics(header(0), 4, |n| n.fill(NodeState::default())).unwrap();
    let e = s.publish_kinematics(header(1), 4, |n| n.fill(NodeState::default())).unwrap_err();
    assert!(matches!(e, ProtocolError::Delivery(_)), "{e:?}");
    assert!(e.to_string().contains("lockstep"), "{e}");
    // The first sample is still there, intact.
    assert_eq!(f.read_kinematics(|h, n| (h.step, n.len())).unwrap(), (0, 4));
    drop((s, f));
    shm::cleanup_run(&id).unwrap();
    assert!(shm::run_files(&id).is_empty());
}

#[test]
fn slices_grow_past_their_initial_length() {
    let id = run_id("grow");
    let mut s = StructureEndpoint::open(
        &id,
        HelloInfo { n_surface_nodes: 8, ..Default::default() },
        quick(),
    )
    .unwrap();
    let mut f = FluidEndpoint::open(&id, HelloInfo::default(), quick()).unwrap();
    for n in [8usize, 100, 5000] {
        s.publish_kinematics(header(0), n, |x| x.fill(NodeState { x: [1.0; 3], v: [2.0; 3] }))
            .unwrap();
        let sum = f.read_kinematics(|_, x| x.iter().map(|s| s.x[0] + s.v[2]).sum::<f64>()).unwrap();
        assert_eq!(sum, 3.0 * n as f64);
    }
    drop((s, f));
    shm::cleanup_run(&id).unwrap();
}
