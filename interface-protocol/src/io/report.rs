//! `run.json` (DESIGN §7): the case echo, versions, counts and the wall-time split, written
//! atomically. Each process times its work with a [`Timers`]; the launcher merges the solvers'
//! buckets (reported in their `Done` replies) into one [`RunReport`].

use std::collections::BTreeMap;
use std::io;
use std::path::Path;
use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};

/// Standard wall-time bucket names (DESIGN §7); processes may add their own.
pub mod bucket {
    /// Fluid residual evaluation (fluxes, reconstruction, boundary conditions).
    pub const RESIDUAL: &str = "residual";
    /// Embedded-surface tracking (intersections, node status).
    pub const TRACKING: &str = "tracking";
    /// Fluid loads on the structure.
    pub const LOADS: &str = "loads";
    /// Structure solve.
    pub const STRUCTURE: &str = "structure";
    /// Waiting on the peer or the launcher over IPC.
    pub const IPC_WAIT: &str = "ipc_wait";
    /// Writing fields, probes, checkpoints.
    pub const OUTPUT: &str = "output";
}

/// Accumulated wall time per named bucket; cheap enough for the time loop (a linear scan over a
/// handful of `&'static str` keys, no allocation after the first use of a bucket).
#[derive(Debug, Clone, Default)]
pub struct Timers {
    buckets: Vec<(&'static str, Duration)>,
}

impl Timers {
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds `d` to `bucket`.
    pub fn add(&mut self, bucket: &'static str, d: Duration) {
        match self.buckets.iter_mut().find(|(name, _)| *name == bucket) {
            Some((_, total)) => *total += d,
            None => self.buckets.push((bucket, d)),
        }
    }

    /// Adds the time elapsed since `start` to `bucket`, for spans a closure cannot wrap:
    /// `let t0 = Instant::now(); ...; timers.add_since(bucket::LOADS, t0);`
    pub fn add_since(&mut self, bucket: &'static str, start: Instant) {
        self.add(bucket, start.elapsed());
    }

    /// Runs `f`, charging its wall time to `bucket`.
    pub fn time<R>(&mut self, bucket: &'static str, f: impl FnOnce() -> R) -> R {
        let start = Instant::now();
        let r = f();
        self.add(bucket, start.elapsed());
        r
    }

    /// Total of one bucket (zero if never used).
    pub fn get(&self, bucket: &str) -> Duration {
        self.buckets.iter().find(|(n, _)| *n == bucket).map(|(_, d)| *d).unwrap_or_default()
    }

    /// Sum over all buckets.
    pub fn total(&self) -> Duration {
        self.buckets.iter().map(|(_, d)| *d).sum()
    }

    /// Seconds per bucket, for `run.json` or a `Done` reply.
    pub fn seconds(&self) -> BTreeMap<String, f64> {
        self.buckets.iter().map(|(n, d)| (n.to_string(), d.as_secs_f64())).collect()
    }
}

/// Versions this crate knows: `{"interface-protocol": "0.1.0", "hdf5": "1.10.8"}` (the HDF5
/// library linked at run time); each process adds its own crate.
pub fn versions() -> BTreeMap<String, String> {
    let (a, b, c) = hdf5::library_version();
    BTreeMap::from([
        ("interface-protocol".to_string(), env!("CARGO_PKG_VERSION").to_string()),
        ("hdf5".to_string(), format!("{a}.{b}.{c}")),
    ])
}

/// The content of `run.json`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct RunReport {
    /// The case file as given.
    pub case_file: String,
    /// The case file's content as JSON (see [`case_echo`]).
    pub case: serde_json::Value,
    /// Component -> version (see [`versions`]); each process adds its own crate.
    pub versions: BTreeMap<String, String>,
    /// `"completed"`, or the error that stopped the run.
    pub status: String,
    /// Steps taken (coupling steps when coupled).
    pub steps: u64,
    /// Simulated time reached.
    pub final_time: f64,
    /// Sizes and counters: nodes, cells, surface nodes, Newton iterations, ...
    pub counts: BTreeMap<String, u64>,
    /// Total wall time of the run in seconds.
    pub wall_seconds: f64,
    /// Process (`"fluid"`, `"structure"`, `"launcher"`) -> bucket -> seconds.
    pub timings: BTreeMap<String, BTreeMap<String, f64>>,
    /// The embedded surface of a fluid run that has one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub surface: Option<SurfaceReport>,
}

/// `run.json`'s `surface` section: what the embedded boundary cost and what it did to the fluid.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct SurfaceReport {
    /// Wall seconds of the tracking (refit, intersections, sides, filling the swept nodes).
    pub tracking_seconds: f64,
    /// Seconds in the fluxes of the cut and frozen edges (Alg. 5.1 and the slip walls), summed
    /// over the threads that computed them.
    pub wall_flux_seconds: f64,
    /// Wall seconds of `p*` at the cut edges and the loads (Alg. 5.3 or 5.4).
    pub loads_seconds: f64,
    /// Cut edges at the end of the run.
    pub cut_edges: u64,
    /// Active, occluded and inactive mesh nodes at the end of the run.
    pub active_nodes: u64,
    pub occluded_nodes: u64,
    pub inactive_nodes: u64,
    /// Fluid mass `M = Σ |C_i| ρ_i` over the active nodes at the start and at the end (kg).
    pub mass_start: f64,
    pub mass_end: f64,
    /// Net mass that left through the domain's boundary over the run (kg; the time integral of
    /// the mass component of the boundary fluxes of the active nodes, as the scheme applies them).
    pub boundary_outflow: f64,
    /// The mass the surface created (positive) or destroyed: `mass_end - mass_start +
    /// boundary_outflow`, accumulated step by step (kg). It includes the mass of the nodes that
    /// change status (covered nodes leave `M` with their state, uncovered ones join it with
    /// the state they are filled with) and whatever the cut-edge fluxes do not conserve.
    pub mass_change: f64,
}

impl RunReport {
    /// Writes the report as pretty JSON, atomically.
    pub fn write(&self, path: &Path) -> io::Result<()> {
        super::atomic::write_atomic(path, |w| {
            serde_json::to_writer_pretty(&mut *w, self).map_err(io::Error::other)?;
            io::Write::write_all(w, b"\n")
        })
    }

    /// Reads a report written by [`RunReport::write`].
    pub fn read(path: &Path) -> io::Result<Self> {
        let text = std::fs::read_to_string(path)?;
        serde_json::from_str(&text).map_err(|e| {
            io::Error::new(io::ErrorKind::InvalidData, format!("{}: {e}", path.display()))
        })
    }
}

/// The case file's TOML text as a JSON value, for [`RunReport::case`]. The text is echoed as
/// written (after `--set` overrides if the caller applied them to the text).
pub fn case_echo(toml_text: &str) -> Result<serde_json::Value, toml::de::Error> {
    let value: toml::Value = toml::from_str(toml_text)?;
    Ok(serde_json::to_value(value).expect("a TOML value is always representable as JSON"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn timers_accumulate_per_bucket() {
        let mut t = Timers::new();
        t.add(bucket::RESIDUAL, Duration::from_millis(30));
        t.add(bucket::OUTPUT, Duration::from_millis(5));
        t.add(bucket::RESIDUAL, Duration::from_millis(12));
        let x = t.time(bucket::LOADS, || 7);
        assert_eq!(x, 7);
        t.add_since(bucket::LOADS, Instant::now());
        assert_eq!(t.get(bucket::RESIDUAL), Duration::from_millis(42));
        assert_eq!(t.get(bucket::TRACKING), Duration::ZERO);
        assert!(t.total() >= Duration::from_millis(47));
        let s = t.seconds();
        assert_eq!(s.len(), 3);
        assert!((s["residual"] - 0.042).abs() < 1e-12);
    }

    #[test]
    fn report_round_trips_through_run_json() {
        let dir = tempfile::tempdir().unwrap();
        let case = "[fluid]\nmesh = \"box\"\ncfl = 0.5\n[output]\nfields_every = 10\n";
        let mut timers = Timers::new();
        timers.add(bucket::IPC_WAIT, Duration::from_millis(250));
        let report = RunReport {
            case_file: "cases/piston/case.toml".into(),
            case: case_echo(case).unwrap(),
            versions: versions(),
            status: "completed".into(),
            steps: 120,
            final_time: 1.5e-3,
            counts: BTreeMap::from([("fluid_nodes".to_string(), 4096)]),
            wall_seconds: 3.25,
            timings: BTreeMap::from([("fluid".to_string(), timers.seconds())]),
            surface: Some(SurfaceReport {
                cut_edges: 12,
                mass_change: -1.5e-9,
                ..Default::default()
            }),
        };
        let path = dir.path().join("run.json");
        report.write(&path).unwrap();
        assert_eq!(RunReport::read(&path).unwrap(), report);
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        assert_eq!(json["case"]["fluid"]["cfl"], 0.5);
        assert_eq!(json["timings"]["fluid"]["ipc_wait"], 0.25);
        assert!(json["versions"]["hdf5"].as_str().unwrap().starts_with("1."));
    }

    #[test]
    fn bad_case_text_is_an_error() {
        assert!(case_echo("[fluid\n").is_err());
    }
}
