// Scratch driver (not part of the tree): runs the coupling sequence against the real binaries.
use interface_protocol::case::{Case, Scheme};
use interface_protocol::endpoint::{LauncherLink, Timeouts};
use interface_protocol::messages::{reply_kind, scheme_phase as ph, Command, Role};
use std::process::{Command as Proc, Stdio};
use std::time::{Duration, Instant};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let case_path = std::path::PathBuf::from(&args[1]);
    let out = std::path::PathBuf::from(&args[2]);
    let sets: Vec<String> = args[3..].to_vec();
    let case = Case::load(&case_path, &sets).unwrap();
    let run_id = format!("scratch{}", std::process::id());
    let mut link = LauncherLink::open(&run_id, Timeouts::default()).unwrap();
    let bin = std::path::Path::new("target/debug");
    let spawn = |exe: &str| {
        let mut c = Proc::new(bin.join(exe));
        c.arg("run").arg(&case_path).arg("--couple").arg(&run_id).arg("--out").arg(&out);
        for s in &sets { c.arg("--set").arg(s); }
        c.env("FSI_LAUNCHER_PID", std::process::id().to_string()).stdin(Stdio::null());
        c.spawn().unwrap()
    };
    let mut fc = spawn("piston-fluid");
    let mut sc = spawn("rigid-structure");
    let soon = Instant::now() + Duration::from_secs(10);
    let f = link.wait_hello(Role::Fluid, soon).unwrap();
    let s = link.wait_hello(Role::Structure, soon).unwrap();
    LauncherLink::check(&f, &s, case.hash()).unwrap();
    let mut go = |role: Role, c: Command| {
        link.send(role, &c).unwrap();
        let r = link.wait_reply(role, Instant::now() + Duration::from_secs(10)).unwrap();
        assert_ne!(r.kind, reply_kind::FAILED, "{:?} {}: {}", role, c.describe(), r.message_str());
        r
    };
    let c = &case.coupling;
    let (dt, n) = (c.dt, c.n_steps());
    go(Role::Structure, Command::init());
    go(Role::Fluid, Command::init());
    go(Role::Structure, Command::advance(0, 0.0, 0.0, ph::START));
    if c.scheme == Scheme::C0 { go(Role::Fluid, Command::advance(0, 0.0, dt / 2.0, ph::START)); }
    let mut wait = 0.0;
    for k in 0..n {
        let t0 = k as f64 * dt;
        let t1 = if k + 1 == n { c.t_end } else { t0 + dt };
        go(Role::Structure, Command::advance(k, t0, t1, ph::PREDICT));
        let (ff, ft) = match c.scheme { Scheme::Css => (t0, t1), Scheme::C0 => (t0 + dt / 2.0, t1 + dt / 2.0), Scheme::A6 => ((t0 - dt / 2.0).max(0.0), t0 + dt / 2.0) };
        let r = go(Role::Fluid, Command::advance(k, ff, ft, ph::NONE));
        wait += r.wait_s;
        go(Role::Structure, Command::advance(k, t0, t1, ph::CORRECT));
    }
    go(Role::Structure, Command::finish());
    go(Role::Fluid, Command::finish());
    println!("fluid exit {:?}, structure exit {:?}, fluid wait {wait}", fc.wait().unwrap(), sc.wait().unwrap());
    println!("removed {}", link.remove_resources().unwrap());
    println!("left {:?}", interface_protocol::shm::run_files(&run_id));
}
