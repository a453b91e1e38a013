//! System tests: they launch the real binaries (built first, found under `target/`) and couple
//! them over shared memory. The library holds what the tests share; `src/bin/` holds test-only
//! participants.
//!
//! Build the binaries for the profile the tests run with, then test:
//! `cargo build --release -p coupler-scripts -p rigid-structure -p fluid-solver -p
//! structure-solver -p fsi-system-tests --bins && cargo test --release -p fsi-system-tests`.

pub mod order;
pub mod restart;

use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::atomic::{AtomicU32, Ordering};
use std::time::{Duration, Instant};

/// `target/<profile>` of this workspace, for the profile these tests were built with.
pub fn bin_dir() -> PathBuf {
    let profile = if cfg!(debug_assertions) { "debug" } else { "release" };
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join("target"));
    target.join(profile)
}

/// A binary of the workspace; panics with the build command when it is missing.
pub fn bin(name: &str) -> PathBuf {
    let p = bin_dir().join(name);
    assert!(
        p.is_file(),
        "{} is missing: build the binaries first with `cargo build{} -p coupler-scripts -p \
         rigid-structure -p fluid-solver -p structure-solver -p fsi-system-tests --bins`",
        p.display(),
        if cfg!(debug_assertions) { "" } else { " --release" }
    );
    p
}

/// `structure.command=[".../spring-mass"]` (for `--set`) with the absolute path of the Python
/// structure's wrapper, `coupler-scripts/python/spring-mass` (its venv: `install.sh` there).
pub fn python_structure() -> String {
    let wrapper = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../coupler-scripts/python/spring-mass")
        .canonicalize()
        .expect("coupler-scripts/python/spring-mass exists");
    format!("structure.command=[\"{}\"]", wrapper.display())
}

/// A run id no other test or process uses: `t<pid>-<tag>-<counter>`.
pub fn unique_run_id(tag: &str) -> String {
    static NEXT: AtomicU32 = AtomicU32::new(0);
    let n = NEXT.fetch_add(1, Ordering::SeqCst);
    let tag: String = tag.chars().filter(|c| c.is_ascii_alphanumeric()).take(16).collect();
    format!("t{:x}-{tag}-{n}", std::process::id())
}

/// A temporary folder holding case files and run folders; removed when dropped.
pub struct Scratch {
    dir: tempfile::TempDir,
}

impl Default for Scratch {
    fn default() -> Self {
        Self::new()
    }
}

impl Scratch {
    pub fn new() -> Self {
        Scratch { dir: tempfile::Builder::new().prefix("fsi-test-").tempdir().expect("a temp dir") }
    }

    pub fn path(&self) -> &Path {
        self.dir.path()
    }

    /// Writes `<name>.toml` and returns its path.
    pub fn case(&self, name: &str, text: &str) -> PathBuf {
        let p = self.path().join(format!("{name}.toml"));
        std::fs::write(&p, text).expect("write the case file");
        p
    }

    /// Writes an executable shell script and returns its path.
    pub fn script(&self, name: &str, body: &str) -> PathBuf {
        use std::os::unix::fs::PermissionsExt;
        let p = self.path().join(name);
        std::fs::write(&p, format!("#!/bin/sh\n{body}\n")).expect("write the script");
        std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o755)).expect("chmod");
        p
    }
}

/// A running `fsi` with its output captured in files (a pipe could be held open by children
/// that outlive it).
pub struct Fsi {
    pub child: Child,
    pub run_id: String,
    stdout: PathBuf,
    stderr: PathBuf,
    pub started: Instant,
}

/// How an `fsi` ended.
#[derive(Debug)]
pub struct Finished {
    pub status: ExitStatus,
    pub stdout: String,
    pub stderr: String,
    /// From start to exit.
    pub elapsed: Duration,
}

impl Fsi {
    /// Starts `fsi <args...>` with its output in `scratch`.
    pub fn start(scratch: &Scratch, args: &[&str]) -> Fsi {
        static NEXT: AtomicU32 = AtomicU32::new(0);
        let n = NEXT.fetch_add(1, Ordering::SeqCst);
        let stdout = scratch.path().join(format!("fsi-{n}.out"));
        let stderr = scratch.path().join(format!("fsi-{n}.err"));
        let child = Command::new(bin("fsi"))
            .args(args)
            .stdin(Stdio::null())
            .stdout(std::fs::File::create(&stdout).expect("stdout file"))
            .stderr(std::fs::File::create(&stderr).expect("stderr file"))
            .spawn()
            .expect("start fsi");
        let run_id = args
            .windows(2)
            .find(|w| w[0] == "--run-id")
            .map(|w| w[1].to_string())
            .unwrap_or_default();
        Fsi { child, run_id, stdout, stderr, started: Instant::now() }
    }

    /// `fsi run <case> --out <out> --quiet --run-id <fresh id> [extra...]`.
    pub fn run(scratch: &Scratch, case: &Path, out: &Path, extra: &[&str]) -> Fsi {
        let run_id = unique_run_id(case.file_stem().and_then(|s| s.to_str()).unwrap_or("run"));
        let mut args =
            vec!["run", case.to_str().unwrap(), "--out", out.to_str().unwrap(), "--quiet"];
        args.extend(["--run-id", run_id.as_str()]);
        args.extend(extra);
        Fsi::start(scratch, &args)
    }

    pub fn pid(&self) -> i32 {
        self.child.id() as i32
    }

    /// Waits until `fsi` exits; panics (after killing it) past `limit`.
    pub fn wait(mut self, limit: Duration) -> Finished {
        let deadline = Instant::now() + limit;
        let status = loop {
            if let Some(s) = self.child.try_wait().expect("try_wait") {
                break s;
            }
            if Instant::now() >= deadline {
                let _ = self.child.kill();
                let _ = self.child.wait();
                panic!(
                    "fsi did not exit within {limit:?}; stderr:\n{}",
                    std::fs::read_to_string(&self.stderr).unwrap_or_default()
                );
            }
            std::thread::sleep(Duration::from_millis(2));
        };
        Finished {
            status,
            elapsed: self.started.elapsed(),
            stdout: std::fs::read_to_string(&self.stdout).unwrap_or_default(),
            stderr: std::fs::read_to_string(&self.stderr).unwrap_or_default(),
        }
    }

    /// The participants `fsi` started: (pid, program name), once both are running.
    pub fn participants(&self, limit: Duration) -> Vec<(i32, String)> {
        let deadline = Instant::now() + limit;
        loop {
            let kids = children(self.pid());
            if kids.len() >= 2 || Instant::now() >= deadline {
                return kids;
            }
            std::thread::sleep(Duration::from_millis(5));
        }
    }
}

/// Child processes of `pid` with their command names (`/proc/<pid>/task/*/children`).
pub fn children(pid: i32) -> Vec<(i32, String)> {
    let mut out = Vec::new();
    let Ok(tasks) = std::fs::read_dir(format!("/proc/{pid}/task")) else { return out };
    for t in tasks.flatten() {
        let text = std::fs::read_to_string(t.path().join("children")).unwrap_or_default();
        for c in text.split_whitespace().filter_map(|c| c.parse::<i32>().ok()) {
            let comm = std::fs::read_to_string(format!("/proc/{c}/comm")).unwrap_or_default();
            out.push((c, comm.trim().to_string()));
        }
    }
    out
}

/// Whether `pid` is a live process (a zombie counts as gone).
pub fn alive(pid: i32) -> bool {
    match std::fs::read_to_string(format!("/proc/{pid}/stat")) {
        Ok(stat) => {
            // The state follows the parenthesised command name.
            let state = stat.rsplit(')').next().and_then(|r| r.split_whitespace().next());
            !matches!(state, Some("Z") | Some("X"))
        }
        Err(_) => false,
    }
}

/// Waits until none of `pids` is alive; returns how long that took, or `None` past `limit`.
pub fn wait_gone(pids: &[i32], limit: Duration) -> Option<Duration> {
    let start = Instant::now();
    while pids.iter().any(|&p| alive(p)) {
        if start.elapsed() >= limit {
            return None;
        }
        std::thread::sleep(Duration::from_millis(2));
    }
    Some(start.elapsed())
}

/// Sends `signal` to `pid`.
pub fn signal(pid: i32, signal: i32) {
    // SAFETY: `kill` only sends a signal to a process these tests started.
    let rc = unsafe { libc::kill(pid, signal) };
    assert_eq!(rc, 0, "kill({pid}, {signal}) failed: {}", std::io::Error::last_os_error());
}

/// The files a run left in `/dev/shm` and `/tmp/iceoryx2`.
pub fn run_files(run_id: &str) -> Vec<PathBuf> {
    interface_protocol::shm::run_files(run_id)
}

/// A probes CSV file: the header and the rows (lines starting with `#` are comments).
pub struct Probes {
    pub columns: Vec<String>,
    pub rows: Vec<Vec<f64>>,
}

impl Probes {
    pub fn read(path: &Path) -> Probes {
        let text = std::fs::read_to_string(path)
            .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
        let mut lines = text.lines().filter(|l| !l.trim().is_empty() && !l.starts_with('#'));
        let columns: Vec<String> =
            lines.next().expect("a header").split(',').map(|c| c.trim().to_string()).collect();
        let rows = lines
            .map(|l| l.split(',').map(|v| v.trim().parse::<f64>().expect("a number")).collect())
            .collect();
        Probes { columns, rows }
    }

    /// The values of column `name` with their times (column 0).
    pub fn series(&self, name: &str) -> Vec<(f64, f64)> {
        let c = self
            .columns
            .iter()
            .position(|n| n == name)
            .unwrap_or_else(|| panic!("no column `{name}` among {:?}", self.columns));
        self.rows.iter().map(|r| (r[0], r[c])).collect()
    }
}

/// Observed orders between successive errors of step sizes halved each time.
pub fn observed_orders(errors: &[f64]) -> Vec<f64> {
    errors.windows(2).map(|w| (w[0] / w[1]).log2()).collect()
}

/// A mass on a spring and damper closing an acoustic column (`piston-fluid` coupled to
/// `rigid-structure`, translation along x): m u'' + (c + A ρ0 c0) u' + k u = -A p0, from rest at
/// u = 0 (DESIGN §8 item 7).
#[derive(Debug, Clone, Copy)]
pub struct Oscillator {
    pub m: f64,
    pub k: f64,
    pub c: f64,
    pub area: f64,
    pub p0: f64,
    pub rho0: f64,
    pub c0: f64,
}

impl Oscillator {
    /// The oscillator of a case's `[fluid.piston]` and one-dof `[structure.rigid]` sections.
    pub fn from_case(case: &interface_protocol::case::Case) -> Oscillator {
        let piston = case.fluid.as_ref().and_then(|f| f.piston.clone()).expect("[fluid.piston]");
        let body =
            case.structure.as_ref().and_then(|s| s.rigid.clone()).expect("[structure.rigid]");
        assert_eq!(body.dofs, ["x"], "a one-dof body along x");
        let one = |v: &interface_protocol::case::PerDof| v.values(1).expect("one value")[0];
        assert_eq!((one(&body.u0), one(&body.v0)), (0.0, 0.0), "a body starting at rest");
        Oscillator {
            m: body.mass,
            k: one(&body.stiffness),
            c: one(&body.damping),
            area: piston.area,
            p0: piston.p0,
            rho0: piston.rho0,
            c0: piston.c0,
        }
    }

    /// Exact displacement: u_s + e^{-γt} (C1 cos ω_d t + C2 sin ω_d t), with the static offset
    /// u_s = -A p0 / k, γ = (c + A ρ0 c0) / 2m, ω_d = sqrt(k/m - γ²) (underdamped).
    pub fn displacement(&self, t: f64) -> f64 {
        let u_s = -self.area * self.p0 / self.k;
        let gamma = (self.c + self.area * self.rho0 * self.c0) / (2.0 * self.m);
        let wd = (self.k / self.m - gamma * gamma).sqrt();
        let (c1, c2) = (-u_s, -gamma * u_s / wd);
        u_s + (-gamma * t).exp() * (c1 * (wd * t).cos() + c2 * (wd * t).sin())
    }

    /// Largest |u - u_exact| of the probe `<probe>.ux` in a run folder's `structure_probes.csv`,
    /// relative to the static offset A p0 / k; checks the run reached `t_end`.
    pub fn max_error(&self, out: &Path, probe: &str, t_end: f64) -> f64 {
        let probes = Probes::read(&out.join("structure_probes.csv"));
        let series = probes.series(&format!("{probe}.ux"));
        assert!(series.len() >= 10, "only {} probe rows in {}", series.len(), out.display());
        let last = series.last().unwrap().0;
        assert!((last - t_end).abs() < 1e-9, "the run ended at t = {last}, not {t_end}");
        let scale = self.area * self.p0 / self.k;
        series.iter().map(|&(t, u)| (u - self.displacement(t)).abs()).fold(0.0, f64::max) / scale
    }
}
