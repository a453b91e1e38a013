//! `cases/shell-water-air` (thesis §5.2.3.1-2, DESIGN §8.4): water | thin shell | air, the shell
//! an embedded plate moving at 10 m/s towards the air, to t = 0.007, with stiffened-gas water and
//! with Tait water, on 400 points along x (the case has 800; here the shell still crosses a grid
//! plane, so the swept nodes change fluid). Each is run twice:
//! - alone, the motion prescribed in `[fluid.embedded]` (`case.toml`);
//! - through `fsi run` (`coupled.toml`), the shell a rigid body of `rigid-structure` whose state
//!   reaches the fluid over the protocol (C0, two coupling steps, the fluid subcycling).
//!
//! Checked: both sides against the exact one-sided Riemann solutions (the plateau between each
//! wave and the shell within 0.5% of each jump and of the wall speed, the air shock and the middle
//! of the water rarefaction within 2 cells); the coupled run's line samples at every line time
//! equal the prescribed run's to round-off (1e-11 of ρ, p and of the wall speed); the force on the
//! shell is (p*_water - p*_air) times the column's section, within 0.5%.
//!
//! Build the binaries first: `cargo build --release -p coupler-scripts -p rigid-structure -p
//! fluid-solver --bins`.

mod common;

use common::lines::{plateau, rows as line};
use fluid_solver::eos::{Eos, EosSpec};
use fluid_solver::riemann::{RiemannSolution, State1d};
use fluid_solver::solver::{self, RunOptions};
use interface_protocol::case::Case;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

const T: f64 = 7e-3;
const WALL_SPEED: f64 = 10.0;
const CELLS: usize = 399;
const LINE_TIMES: [&str; 4] = ["1.750000e-3", "3.500000e-3", "5.250000e-3", "7.000000e-3"];
const TAIT: &str =
    "fluid.fluids.water.eos={ kind = \"tait\", k1 = 2.066e9, k2 = 7.15, rho0 = 1000.0, p0 = 3e7 }";

fn case_path(file: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("../cases/shell-water-air/{file}"))
}

fn overrides(tait: bool) -> Vec<String> {
    let mut o = vec![format!("fluid.mesh.box.cells=[{CELLS}, 1, 1]")];
    if tait {
        o.push(TAIT.to_string());
    }
    o
}

/// The workspace binary `name`, next to `fluid-solver` in `target/<profile>`.
fn bin(name: &str) -> PathBuf {
    let p = Path::new(env!("CARGO_BIN_EXE_fluid-solver")).with_file_name(name);
    assert!(
        p.is_file(),
        "{} is missing: build first with `cargo build{} -p coupler-scripts -p rigid-structure -p \
         fluid-solver --bins`",
        p.display(),
        if cfg!(debug_assertions) { "" } else { " --release" }
    );
    p
}

fn run_alone(o: &[String], out: &Path) {
    let path = case_path("case.toml");
    let case = Case::load(&path, o).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let opts = RunOptions { out: out.to_path_buf(), quiet: true, restart: None, force: false };
    solver::run(&case, &text, &opts).unwrap();
}

fn run_coupled(o: &[String], out: &Path) {
    let mut fsi = Command::new(bin("fsi"));
    fsi.arg("run").arg(case_path("coupled.toml")).arg("--out").arg(out).arg("--quiet");
    for s in o {
        fsi.arg("--set").arg(s);
    }
    let r = fsi.stdin(Stdio::null()).output().unwrap();
    assert!(r.status.success(), "fsi run: {}", String::from_utf8_lossy(&r.stderr));
}

/// The exact solution: water left of the wall (x < 10 t) and air right of it, each the one-sided
/// Riemann problem of a wall moving at +10 m/s; air is the mirror image of a fluid left of a wall
/// at -10 m/s.
struct Exact {
    water: RiemannSolution,
    air: RiemannSolution,
    water_eos: Eos,
}

impl Exact {
    fn new(water_eos: Eos) -> Exact {
        let water =
            RiemannSolution::wall(&water_eos, State1d { rho: 1000.0, u: 0.0, p: 3e7 }, WALL_SPEED)
                .unwrap();
        let air_eos = Eos::PerfectGas { gamma: 1.4 };
        let air =
            RiemannSolution::wall(&air_eos, State1d { rho: 1.3, u: 0.0, p: 1e5 }, -WALL_SPEED)
                .unwrap();
        Exact { water, air, water_eos }
    }

    /// `(ρ, u, p)` at `x`, time `T`.
    fn at(&self, x: f64) -> [f64; 3] {
        if x < WALL_SPEED * T {
            let s = self.water.sample(x / T);
            [s.rho, s.u, s.p]
        } else {
            let s = self.air.sample(-x / T);
            [s.rho, -s.u, s.p]
        }
    }

    /// Where the water's pressure is halfway between its start and star values.
    fn rarefaction_middle(&self) -> f64 {
        let mid = 0.5 * (3e7 + self.water.star.p);
        let (mut lo, mut hi) = (-15.0, 0.0);
        for _ in 0..100 {
            let x = 0.5 * (lo + hi);
            if self.at(x)[2] > mid {
                lo = x;
            } else {
                hi = x;
            }
        }
        lo
    }
}

/// The first sample, walking from the left end (or the right end), where `p` passes `level`.
fn crossing(rows: &[Vec<f64>], level: f64, from_right: bool) -> f64 {
    let mut it: Box<dyn Iterator<Item = &Vec<f64>>> =
        if from_right { Box::new(rows.iter().rev()) } else { Box::new(rows.iter()) };
    let above = |r: &Vec<f64>| r[8] > level;
    let first = it.next().unwrap();
    let start = above(first);
    it.find(|r| above(r) != start).map(|r| r[0]).expect("no crossing")
}

/// Both sides at t = 0.007 against the exact solution.
fn check_exact(rows: &[Vec<f64>], exact: &Exact, what: &str) {
    let dx = 20.0 / CELLS as f64;
    let (p0w, rho0w, p0a, rho0a) = (3e7, 1000.0, 1e5, 1.3);
    let w = exact.water.star;
    let a = exact.air.star;
    let water = plateau(rows, -9.0, -0.5);
    let air = plateau(rows, 0.5, 1.8);
    eprintln!(
        "{what}: water plateau {water:?} (exact ρ {} u {WALL_SPEED} p {}), air plateau {air:?} \
         (exact ρ {} p {})",
        w.rho_l, w.p, a.rho_l, a.p
    );
    let close = |got: f64, exact: f64, jump: f64, name: &str| {
        let e = (got - exact).abs() / jump.abs();
        assert!(e < 5e-3, "{what}: {name} {got} vs exact {exact}: {e:.2e} of the jump {jump}");
    };
    close(water[0], w.rho_l, w.rho_l - rho0w, "water ρ*");
    close(water[1], WALL_SPEED, WALL_SPEED, "water u*");
    close(water[2], w.p, w.p - p0w, "water p*");
    close(air[0], a.rho_l, a.rho_l - rho0a, "air ρ*");
    close(air[1], WALL_SPEED, WALL_SPEED, "air u*");
    close(air[2], a.p, a.p - p0a, "air p*");
    // The air shock (mirrored: the left wave of the mirror problem) and the water rarefaction.
    let shock = -exact.air.left_wave().0 * T;
    let got = crossing(rows, 0.5 * (p0a + a.p), true);
    assert!((got - shock).abs() < 2.0 * dx, "{what}: air shock at {got}, exact {shock}");
    let middle = exact.rarefaction_middle();
    let got = crossing(rows, 0.5 * (p0w + w.p), false);
    assert!((got - middle).abs() < 2.0 * dx, "{what}: rarefaction middle {got}, exact {middle}");
    // The water EOS really is the one asked for: its sound speed sets the rarefaction head.
    let c = exact.water_eos.sound_speed(rho0w, p0w);
    assert!((exact.water.left_wave().0 + c).abs() < 1e-9 * c);
}

/// The largest differences between two line samples: of ρ and p relative to their values, of the
/// velocity relative to the wall speed.
fn differences(a: &[Vec<f64>], b: &[Vec<f64>]) -> [f64; 3] {
    assert_eq!(a.len(), b.len());
    let mut d = [0.0f64; 3];
    for (ra, rb) in a.iter().zip(b) {
        assert_eq!(ra[0], rb[0]);
        d[0] = d[0].max((ra[4] - rb[4]).abs() / ra[4].abs());
        d[1] = d[1].max((5..8).map(|k| (ra[k] - rb[k]).abs()).fold(0.0, f64::max) / WALL_SPEED);
        d[2] = d[2].max((ra[8] - rb[8]).abs() / ra[8].abs());
        assert_eq!(ra[9], rb[9], "material at x = {}", ra[0]);
    }
    d
}

/// The force on the shell along x at t = 0.007 in `surface_forces.csv`.
fn force_at_end(dir: &Path) -> f64 {
    let text = std::fs::read_to_string(dir.join("surface_forces.csv")).unwrap();
    let row = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|s| s.parse::<f64>().unwrap()).collect::<Vec<_>>())
        .find(|r| (r[0] - T).abs() < 1e-12 * T)
        .expect("a row at t = 0.007");
    row[1]
}

fn run_both(tait: bool) {
    let water_eos = if tait {
        Eos::try_from(EosSpec::Tait { k1: 2.066e9, k2: 7.15, rho0: 1000.0, p0: 3e7 }).unwrap()
    } else {
        Eos::StiffenedGas { gamma: 7.15, p_c: 2.89e8 }
    };
    let what = if tait { "Tait water | air" } else { "stiffened-gas water | air" };
    let dir = tempfile::tempdir().unwrap();
    let (alone, coupled) = (dir.path().join("alone"), dir.path().join("coupled"));
    let o = overrides(tait);
    run_alone(&o, &alone);
    run_coupled(&o, &coupled);
    let exact = Exact::new(water_eos);
    let name = |t: &str| format!("lines/axis_t{t}.csv");
    for (k, t) in LINE_TIMES.iter().enumerate() {
        let (a, b) = (line(&alone.join(name(t))), line(&coupled.join(name(t))));
        let d = differences(&a, &b);
        eprintln!(
            "{what}: t = {t}: coupled - prescribed: ρ {:.1e}, v {:.1e}, p {:.1e}",
            d[0], d[1], d[2]
        );
        assert!(d.iter().all(|d| *d < 1e-11), "{what} at t = {t}: {d:?}");
        if k + 1 == LINE_TIMES.len() {
            for (rows, how) in [(&a, "prescribed"), (&b, "coupled")] {
                check_exact(rows, &exact, &format!("{what}, {how}"));
            }
        }
    }
    let area = 0.1 * 0.1;
    let f_exact = (exact.water.star.p - exact.air.star.p) * area;
    for dir in [&alone, &coupled] {
        let f = force_at_end(dir);
        assert!((f - f_exact).abs() < 5e-3 * f_exact, "{what}: force {f} N, exact {f_exact} N");
    }
}

#[test]
fn stiffened_gas_water_shell_air_prescribed_and_coupled() {
    run_both(false);
}

#[test]
fn tait_water_shell_air_prescribed_and_coupled() {
    run_both(true);
}
