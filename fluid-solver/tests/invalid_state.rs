//! An invalid state during a run stops it with a message naming the step, the time, the node
//! (its index and position) and its values; the message is checked against a replay of the
//! failing step from the last good checkpoint, which must fail at the same node with the same
//! values. Cases (the shrunk `cases/sod-tube`): a perfect gas whose pressure goes negative
//! between two streams leaving each other, and Tait water pulled below cavitation the same way;
//! and a non-positive density, which the time step reports with its node and values.

use fluid_solver::eos::{Eos, StateError};
use fluid_solver::semidiscretization::FluidError;
use fluid_solver::setup::{self, Mode};
use fluid_solver::solver::{self, read_checkpoint, RunOptions};
use fluid_solver::state::Workspace;
use fluid_solver::time::rk2_step;
use interface_protocol::case::Case;
use std::path::{Path, PathBuf};

fn case_path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../cases/sod-tube/case.toml")
}

/// The sod-tube case on 50 cells with two streams leaving x = 0.5 at `speed` each way.
fn separating(eos: &str, rho: f64, p: f64, speed: f64) -> Vec<String> {
    let state = |u: f64| format!("[{rho},{u},0.0,0.0,{p}]");
    vec![
        "fluid.mesh.box.cells=[50,1,1]".into(),
        "fluid.time.t_end=0.1".into(),
        // A small step, so that the state fails a few steps in, not in the first.
        "fluid.numerics.cfl=0.3".into(),
        format!("fluid.eos={eos}"),
        format!("fluid.initial.state={}", state(-speed)),
        format!(
            "fluid.initial.regions=[{{region={{shape=\"half_space\",point=[0.5,0,0],normal=[1,0,0]}},state={}}}]",
            state(speed)
        ),
        format!("fluid.boundary.xmin={{kind=\"far_field\",state={}}}", state(-speed)),
        format!("fluid.boundary.xmax={{kind=\"far_field\",state={}}}", state(speed)),
    ]
}

/// The text of `msg` between `start` and the next `end`.
fn between<'m>(msg: &'m str, start: &str, end: &str) -> &'m str {
    let from = msg.find(start).unwrap_or_else(|| panic!("no `{start}` in: {msg}")) + start.len();
    let len = msg[from..].find(end).unwrap_or_else(|| panic!("no `{end}` after `{start}`: {msg}"));
    &msg[from..from + len]
}

fn numbers(list: &str) -> Vec<f64> {
    list.split(',').map(|s| s.trim().parse().unwrap_or_else(|_| panic!("`{s}`"))).collect()
}

/// Runs the case, expects it to stop on an invalid state, and checks the message against a
/// replay of the failing step from the last good checkpoint; returns the message and the error
/// of the replay.
fn stops_naming_node_time_and_values(out: &Path, overrides: &[String]) -> (String, StateError) {
    let path = case_path();
    let case = Case::load(&path, overrides).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let opts = RunOptions { out: out.to_path_buf(), quiet: true, restart: None, force: false };
    let msg = solver::run(&case, &text, &opts).unwrap_err().to_string();
    println!("{msg}");

    let step: u64 = between(&msg, "stopped at step ", ",").parse().unwrap();
    let time: f64 = between(&msg, ", t = ", ":").parse().unwrap();
    let node: usize = between(&msg, "invalid fluid state at node ", " ").parse().unwrap();
    let position = numbers(between(&msg, "(x = [", "]"));
    let values = numbers(between(&msg, "primitive [ρ, u, v, w, p] = [", "]"));
    // A few steps in, so that the time is that of the failing step, not the start.
    assert!(step > 1 && time > 0.0, "{msg}");

    let problem = setup::problem(&case, Mode::Alone).unwrap();
    let semi = &problem.semi;
    let (mut state, at_step, at_time) = read_checkpoint(out, semi.mesh.n_nodes()).unwrap();
    assert_eq!((at_step + 1, at_time.to_bits()), (step, time.to_bits()), "{msg}");
    let mut ws = Workspace::new(semi.mesh.n_nodes());
    let replay = rk2_step(semi, &mut state, &mut ws, problem.stepping, problem.t_end - at_time)
        .expect_err("the replayed step fails");
    let FluidError::InvalidState { node: n, position: x, prim, error } = replay else {
        panic!("replay: {replay}");
    };
    assert_eq!(node, n, "{msg}");
    assert_eq!(position, x.to_vec(), "{msg}");
    assert_eq!(values, prim.to_vec(), "{msg}");
    assert_eq!(semi.mesh.coords[node].to_vec(), position);
    (msg, error)
}

#[test]
fn negative_pressure_stops_the_run_naming_node_time_and_values() {
    let dir = tempfile::tempdir().unwrap();
    // Mach 6.7 each way: a jump in velocity of 5 > 2(c_L + c_R)/(γ - 1) = 3.74, so the exact
    // solution holds a vacuum and the pressure between the streams goes negative.
    let o = separating("{kind=\"perfect_gas\",gamma=1.4}", 1.0, 0.1, 2.5);
    let (msg, error) = stops_naming_node_time_and_values(&dir.path().join("gas"), &o);
    let StateError::Pressure { rho, p, p_min } = error else { panic!("{error:?}") };
    assert!(p <= p_min && p_min == 0.0 && rho > 0.0, "{error:?}");
    assert!(msg.contains(&format!("pressure {p} at or below the EOS limit 0")), "{msg}");
}

#[test]
fn tait_water_below_cavitation_stops_the_run_naming_node_time_and_values() {
    let dir = tempfile::tempdir().unwrap();
    // Water at 1 bar pulled apart at 0.1 m/s each way: the acoustic drop ρ c u = 1.5e5 Pa is
    // more than the 1e5 Pa there is, so the exact star state is below cavitation.
    let tait = "{kind=\"tait\",k1=2.07e9,k2=7.15,rho0=1000.0,p0=1e5}";
    let o = separating(tait, 1000.0, 1e5, 0.1);
    let (msg, error) = stops_naming_node_time_and_values(&dir.path().join("tait"), &o);
    let StateError::Cavitation { rho, rho_cav, p, p_cav } = error else { panic!("{error:?}") };
    assert!(rho < rho_cav && p < p_cav, "{error:?}");
    assert!(msg.contains(&format!("cavitates: density {rho} below {rho_cav}")), "{msg}");
}

#[test]
fn non_positive_density_is_reported_with_its_node_and_values() {
    let path = case_path();
    let case = Case::load(&path, &["fluid.mesh.box.cells=[20,1,1]".to_string()]).unwrap();
    let problem = setup::problem(&case, Mode::Alone).unwrap();
    let semi = &problem.semi;
    let eos = semi.eos[0];
    assert!(matches!(eos, Eos::PerfectGas { .. }));
    let mut state = problem.initial.clone();
    let node = semi.mesh.n_nodes() / 3;
    state.cons[node][0] = -0.25;
    let mut ws = Workspace::new(semi.mesh.n_nodes());
    let e = rk2_step(semi, &mut state, &mut ws, problem.stepping, 1.0).unwrap_err();
    let msg = e.to_string();
    println!("{msg}");
    let FluidError::InvalidState { node: n, position, prim, error } = e else { panic!("{msg}") };
    assert_eq!((n, position), (node, semi.mesh.coords[node]));
    assert_eq!(error, StateError::Density { rho: -0.25 });
    assert_eq!(prim[0], -0.25);
    assert!(msg.contains(&format!("at node {node} ")), "{msg}");
    assert!(msg.contains("non-positive or non-finite density -0.25"), "{msg}");
    assert!(msg.contains(&format!("{:?}", prim)), "{msg}");
}
