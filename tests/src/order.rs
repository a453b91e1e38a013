//! Temporal order studies of the staggered schemes through the real binaries
//! (`tests/coupling_order.rs`): one case run by `fsi run` at coupling steps Δt, Δt/2, ..., the
//! finest the reference, on one mesh, the fluid taking `fluid.time.substeps = M` equal steps per
//! coupling interval so that its own time error shrinks with Δt too.
//!
//! A structure probe column is sampled at the coarse coupling times. The errors are the max over
//! those times of |u_Δt - u_ref|; the orders are those of successive differences,
//! log2(|u_h - u_h/2| / |u_h/2 - u_h/4|), which are free of the reference's own error (against
//! the reference an order p shows as log2((1 - 8^-p) / (2^-p - 8^-p)) and log2((2^-p - 8^-p) /
//! (4^-p - 8^-p)) with four levels, 2.07 and 2.32 for p = 2, 1.22 and 1.58 for p = 1; both are in
//! the table). The table (`coupling-order.json`) is written to the scratch folder and compared
//! with the committed one in the case's folder (`FIVER_BLESS=1` rewrites that); the gates are on
//! the values the run computes: C0 and A6 at least 1.9, CSS within [0.8, 1.3].
//!
//! The same runs give the energy ledger's order: `run.json`'s `interface_energy.error`, the work
//! the fluid's loads did along the surface motion minus the work the structure's applied loads
//! did along its displacement over the run (PROTOCOL.md §3), is the energy the staggering creates
//! at the interface, zero for an exact coupling; its orders over all four levels pass the same
//! gates, the finest pair exactly, the coarser ones within 0.1 (the gas piston's C0 shows 1.90,
//! 1.95, 1.98).

use crate::{observed_orders, Fsi, Probes, Scratch};
use interface_protocol::case::Case;
use serde_json::{json, Map, Value};
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// The schemes a study runs, in the table's order.
pub const SCHEMES: [&str; 3] = ["C0", "A6", "CSS"];

/// One case's study.
pub struct OrderStudy {
    /// The case's folder under `cases/`; the table is `coupling-order.json` there.
    pub case: &'static str,
    /// The case file in that folder.
    pub file: &'static str,
    /// The structure probe column whose differences give the orders, and its unit.
    pub probe: &'static str,
    pub unit: &'static str,
    /// The structure's displacement column, and its value at rest: the largest |u - rest| of the
    /// reference run (`amplitude_m`) must lie in `motion` (it moves, and stays well inside the
    /// cell between the plate and its nearest node, so that no node crossing makes the load
    /// non-smooth in time).
    pub displacement: &'static str,
    pub rest: f64,
    pub motion: Range<f64>,
    pub t_end: f64,
    /// The coarsest coupling step; the others are Δt/2, ..., Δt/2^(levels-1), the reference.
    pub dt: f64,
    pub levels: usize,
    pub substeps: u32,
    /// Further `--set`s of every run (they are applied to the case for the table's fluid cells
    /// and CFL number too).
    pub sets: Vec<String>,
    /// Further entries of the table, describing the case.
    pub about: Vec<(&'static str, Value)>,
    /// Checks a finished run's folder (a case's own conditions, e.g. no cavitation).
    pub check_run: Option<fn(&Path)>,
}

fn cases_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../cases")
}

fn max_difference(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}

/// Whether `a` and `b` agree: numbers to a relative `tol`, everything else exactly.
pub fn agrees(a: &Value, b: &Value, tol: f64) -> bool {
    match (a, b) {
        (Value::Number(x), Value::Number(y)) => {
            let (x, y) = (x.as_f64().unwrap(), y.as_f64().unwrap());
            (x - y).abs() <= tol * x.abs().max(y.abs())
        }
        (Value::Array(x), Value::Array(y)) => {
            x.len() == y.len() && x.iter().zip(y).all(|(x, y)| agrees(x, y, tol))
        }
        (Value::Object(x), Value::Object(y)) => {
            x.len() == y.len() && x.iter().all(|(k, v)| y.get(k).is_some_and(|w| agrees(v, w, tol)))
        }
        _ => a == b,
    }
}

/// One run's probe and displacement at the coarse coupling times, and its interface energy
/// error (J).
struct Level {
    probe: Vec<f64>,
    displacement: Vec<f64>,
    energy_error: f64,
}

impl OrderStudy {
    pub fn case_file(&self) -> PathBuf {
        cases_dir().join(self.case).join(self.file)
    }

    pub fn table_file(&self) -> PathBuf {
        cases_dir().join(self.case).join("coupling-order.json")
    }

    fn step(&self, level: usize) -> f64 {
        self.dt / (1u32 << level) as f64
    }

    /// Every run's `--set`s but the scheme and the step.
    fn common_sets(&self) -> Vec<String> {
        let mut sets = vec![
            format!("coupling.t_end={:e}", self.t_end),
            format!("fluid.time.substeps={}", self.substeps),
        ];
        sets.extend(self.sets.iter().cloned());
        sets
    }

    /// The run with step `dt / 2^level`, sampled at the coarse coupling times.
    fn run(&self, scratch: &Scratch, scheme: &str, level: usize) -> Level {
        let dt = self.step(level);
        let out = scratch.path().join(format!("{}-{scheme}-{level}", self.case));
        let mut sets = vec![format!("coupling.scheme=\"{scheme}\""), format!("coupling.dt={dt:e}")];
        sets.extend(self.common_sets());
        let args: Vec<&str> = sets.iter().flat_map(|s| ["--set", s.as_str()]).collect();
        let done = Fsi::run(scratch, &self.case_file(), &out, &args).wait(Duration::from_secs(120));
        let what = format!("{}, {scheme} at Δt = {dt:e}", self.case);
        assert!(done.status.success(), "{what}: {}", done.stderr);
        if let Some(check) = self.check_run {
            check(&out);
        }
        let probes = Probes::read(&out.join("structure_probes.csv"));
        let n = (self.t_end / self.dt).round() as usize;
        let stride = 1 << level;
        let sample = |name: &str| -> Vec<f64> {
            let series = probes.series(name);
            assert_eq!(series.len(), n * stride + 1, "{what}: one row per step");
            (0..=n)
                .map(|i| {
                    let (t, u) = series[i * stride];
                    let at = i as f64 * self.dt;
                    assert!((t - at).abs() < 1e-12, "{what}: row {} at t = {t}", i * stride);
                    u
                })
                .collect()
        };
        let report: Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("run.json")).expect("run.json"))
                .expect("run.json is JSON");
        let energy_error = report["interface_energy"]["error"]
            .as_f64()
            .unwrap_or_else(|| panic!("{what}: run.json has no interface_energy.error"));
        Level { probe: sample(self.probe), displacement: sample(self.displacement), energy_error }
    }

    /// One scheme's row of the table: the errors against the reference, the successive
    /// differences and both sets of orders.
    fn scheme(&self, scratch: &Scratch, scheme: &str) -> Value {
        let started = Instant::now();
        let runs: Vec<Level> = (0..self.levels).map(|l| self.run(scratch, scheme, l)).collect();
        let reference = &runs[self.levels - 1];
        let amplitude =
            reference.displacement.iter().map(|x| (x - self.rest).abs()).fold(0.0, f64::max);
        assert!(
            self.motion.contains(&amplitude),
            "{}, {scheme}: amplitude {amplitude:e} m outside {:?}",
            self.case,
            self.motion
        );
        let u: Vec<&[f64]> = runs.iter().map(|r| r.probe.as_slice()).collect();
        let errors: Vec<f64> =
            u[..self.levels - 1].iter().map(|x| max_difference(x, &reference.probe)).collect();
        let differences: Vec<f64> = u.windows(2).map(|w| max_difference(w[0], w[1])).collect();
        let orders = observed_orders(&differences);
        let against_reference = observed_orders(&errors);
        let energy: Vec<f64> = runs.iter().map(|r| r.energy_error.abs()).collect();
        let energy_orders = observed_orders(&energy);
        let seconds = started.elapsed().as_secs_f64();
        let e = |v: &[f64]| v.iter().map(|x| format!("{x:.3e}")).collect::<Vec<_>>().join(", ");
        println!(
            "{}, {scheme}: {} errors against Δt/{} [{}] (orders {against_reference:.3?}), \
             successive differences [{}] (orders {orders:.3?}); interface energy errors [{}] J \
             (orders {energy_orders:.3?}); amplitude {amplitude:.3e} m; {seconds:.1} s",
            self.case,
            self.probe,
            1u32 << (self.levels - 1),
            e(&errors),
            e(&differences),
            e(&energy)
        );
        json!({
            "scheme": scheme,
            "dt": (0..self.levels - 1).map(|l| self.step(l)).collect::<Vec<_>>(),
            "max_error_against_reference": errors,
            "orders_against_reference": against_reference,
            "max_successive_difference": differences,
            "observed_orders": orders,
            "interface_energy_error": energy,
            "interface_energy_orders": energy_orders,
            "amplitude_m": amplitude,
        })
    }

    /// Runs every scheme at every level and returns the table.
    pub fn table(&self, scratch: &Scratch) -> Value {
        let case = Case::load(&self.case_file(), &self.common_sets()).expect("the case parses");
        let fluid = case.fluid.as_ref().expect("[fluid]");
        let cells =
            fluid.mesh.as_ref().and_then(|m| m.box_mesh.as_ref()).expect("a box mesh").cells;
        let mut table = Map::new();
        let mut put = |k: &str, v: Value| table.insert(k.to_string(), v);
        put("case", json!(format!("cases/{}", self.case)));
        put("t_end", json!(self.t_end));
        put("fluid_substeps", json!(self.substeps));
        put("fluid_cells", json!(cells[0]));
        put("fluid_cfl", json!(fluid.numerics.cfl));
        put("reference_dt", json!(self.step(self.levels - 1)));
        put(
            "error",
            json!(format!(
                "max over the coarse coupling times of |u_dt - u_ref| of {} [{}]",
                self.probe, self.unit
            )),
        );
        put("observed_orders", json!("log2 of successive max differences |u_h - u_h/2|"));
        for (k, v) in &self.about {
            put(k, v.clone());
        }
        let schemes: Vec<Value> = SCHEMES.iter().map(|s| self.scheme(scratch, s)).collect();
        put("schemes", Value::Array(schemes));
        Value::Object(table)
    }

    /// The whole study: runs it, writes the table to `scratch` (and, with `FIVER_BLESS=1`, to
    /// the case's folder), checks the gates on this run's orders, then compares the table with
    /// the committed one (errors to 5%, which a half-step or sign error in a scheme exceeds by
    /// far).
    pub fn check(&self) {
        let scratch = Scratch::new();
        let started = Instant::now();
        let table = self.table(&scratch);
        let text = serde_json::to_string_pretty(&table).unwrap() + "\n";
        std::fs::write(scratch.path().join("coupling-order.json"), &text).unwrap();
        println!("{text}{}: all runs {:.1} s", self.case, started.elapsed().as_secs_f64());
        let file = self.table_file();
        if std::env::var("FIVER_BLESS").is_ok_and(|v| v == "1") {
            std::fs::write(&file, &text).unwrap();
        }
        for s in table["schemes"].as_array().unwrap() {
            let name = s["scheme"].as_str().unwrap();
            let ok = |p: f64| match name {
                "CSS" => (0.8..=1.3).contains(&p),
                _ => p >= 1.9,
            };
            let orders = |key: &str| -> Vec<f64> {
                s[key].as_array().unwrap().iter().map(|p| p.as_f64().unwrap()).collect()
            };
            let probe = orders("observed_orders");
            assert!(probe.iter().all(|&p| ok(p)), "{}, {name}: orders {probe:?}", self.case);
            // The energy error comes from the coarsest step on (four levels, three orders): the
            // finest order passes the gate, the coarser ones may sit at most 0.1 below it.
            let energy = orders("interface_energy_orders");
            let (last, coarser) = energy.split_last().unwrap();
            assert!(
                ok(*last) && coarser.iter().all(|&p| ok(p + 0.1)),
                "{}, {name}: interface energy orders {energy:?}",
                self.case
            );
        }
        let committed: Value =
            serde_json::from_str(&std::fs::read_to_string(&file).expect("the committed table"))
                .expect("the committed table is JSON");
        assert!(
            agrees(&committed, &table, 0.05),
            "{} differs from this run's table (FIVER_BLESS=1 rewrites it):\n{text}",
            file.display()
        );
    }
}
