//! `cases/underwater-bubble`: a sphere of gas at 10 MPa in water at 1 MPa, on one octant with
//! symmetry planes, against the Keller-Miksis equation ([`keller_miksis`]): the first maximum
//! radius and the time of the first minimum, the radius the equivalent one `(3V/(4π/8))^(1/3)` of
//! the volume where the piecewise-linear interpolant of the level set is positive
//! ([`gas_volume::piecewise_linear`], `O(h²)`), written to `radius.csv` with the gas mass.
//!
//! The comparison runs the case folder's mesh; `BUBBLE_SET="key=value;..."` adds case
//! overrides (another mesh: `fluid.mesh.octant.cells=24;fluid.mesh.octant.coarsen=[]`),
//! `BUBBLE_T_END=<s>` another end time, `BUBBLE_OUT=<dir>` keeps the run (its `radius.csv`) and
//! `BUBBLE_PNG=<path>` writes the pressure picture there (the case folder's:
//! `BUBBLE_PNG=$PWD/cases/underwater-bubble/pressure.png`).
//! The equation's own checks: Rayleigh's collapse time of an empty cavity, the Rayleigh-Plesset
//! limit (`c = ∞`: its energy invariant, the maximum radius it fixes, the minimum back at `R0`),
//! and Keller-Miksis tending to Rayleigh-Plesset as `1/c`.

mod common;
#[path = "underwater_bubble/gas_volume.rs"]
mod gas_volume;
#[path = "underwater_bubble/keller_miksis.rs"]
mod keller_miksis;
#[path = "underwater_bubble/picture.rs"]
mod picture;

use fluid_solver::solver::{self, FluidRun, Mode, RunOptions};
use interface_protocol::case::Case;
use keller_miksis::{Bubble, Cycle, RAYLEIGH_FACTOR};
use std::io::Write;
use std::path::{Path, PathBuf};

/// The case's bubble and liquid (`cases/underwater-bubble/case.toml`).
const R0: f64 = 0.01;
const P_G0: f64 = 1e7;
const GAMMA_GAS: f64 = 1.4;
const P_INF: f64 = 1e6;
const RHO_WATER: f64 = 1000.0;
/// Stiffened-gas water (γ 4.4, p_c 6e8): `c² = γ (p + p_c)/ρ` at the ambient state.
fn c_water() -> f64 {
    (4.4 * (P_INF + 6e8) / RHO_WATER).sqrt()
}

fn bubble(c: f64) -> Bubble {
    Bubble { r0: R0, p_g0: P_G0, gamma: GAMMA_GAS, p_inf: P_INF, rho: RHO_WATER, c }
}

fn case_path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../cases/underwater-bubble/case.toml")
}

#[test]
fn rayleigh_collapse_time_of_an_empty_cavity() {
    let r_max = 0.03;
    let empty = Bubble { p_g0: 0.0, c: f64::INFINITY, ..bubble(1.0) };
    let samples = empty.integrate(r_max, 0.0, 1e-7, 1e-3, |_, y, _| y[0] < 1e-3 * r_max);
    let t = samples.last().unwrap().0;
    let exact = RAYLEIGH_FACTOR * r_max * (RHO_WATER / P_INF).sqrt();
    println!("collapse in {t:.6e} s, Rayleigh {exact:.6e} s ({} steps)", samples.len());
    // The time left from 1e-3 r_max to 0 is 2.5e-8 t_c.
    assert!((t / exact - 1.0).abs() < 1e-6, "{t} against {exact}");
}

#[test]
fn rayleigh_plesset_limit_keeps_its_energy_and_returns_to_r0() {
    let rp = bubble(f64::INFINITY);
    let e0 = rp.rayleigh_plesset_energy(R0, 0.0);
    let mut drift = 0.0f64;
    let samples = rp.integrate(R0, 0.0, 1e-7, 1e-3, |t, y, _| {
        drift = drift.max((rp.rayleigh_plesset_energy(y[0], y[1]) / e0 - 1.0).abs());
        t > 2e-3
    });
    // The maximum radius the invariant fixes: E(R_max, 0) = E(R0, 0), by bisection.
    let f = |r: f64| rp.rayleigh_plesset_energy(r, 0.0) - e0;
    let (mut lo, mut hi) = (1.5 * R0, 10.0 * R0);
    assert!(f(lo) < 0.0 && f(hi) > 0.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if f(mid) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let cycle = rp.first_cycle(1e-7);
    let r_max_samples = samples.iter().map(|s| s.1).fold(0.0, f64::max);
    println!(
        "Rayleigh-Plesset: R_max {:.9e} (invariant {lo:.9e}), R_min {:.9e}, t_max {:.6e}, t_min \
         {:.6e}, energy drift {drift:.2e}",
        cycle.r_max, cycle.r_min, cycle.t_max, cycle.t_min
    );
    assert!(drift < 1e-9, "energy drift {drift}");
    assert!((cycle.r_max / lo - 1.0).abs() < 1e-8 && (r_max_samples / lo - 1.0).abs() < 1e-8);
    assert!((cycle.r_min / R0 - 1.0).abs() < 1e-8, "R_min {}", cycle.r_min);
    // Without damping the cycle is symmetric about its maximum.
    assert!((cycle.t_min / cycle.t_max - 2.0).abs() < 1e-6);
}

#[test]
fn keller_miksis_tends_to_rayleigh_plesset_as_one_over_c() {
    let rp = bubble(f64::INFINITY).first_cycle(1e-7);
    let c = c_water();
    let diff = |k: &Cycle| [k.r_max / rp.r_max - 1.0, k.t_min / rp.t_min - 1.0];
    let water = diff(&bubble(c).first_cycle(1e-7));
    let stiffer = diff(&bubble(10.0 * c).first_cycle(1e-7));
    println!(
        "Keller-Miksis against Rayleigh-Plesset: c = {c:.1}: R_max {:+.4e}, t_min {:+.4e}; 10 c: \
         R_max {:+.4e}, t_min {:+.4e}",
        water[0], water[1], stiffer[0], stiffer[1]
    );
    // The acoustic radiation takes energy: a smaller maximum, an earlier minimum.
    assert!(water[0] < -1e-3 && water[1] < -1e-3, "{water:?}");
    for k in 0..2 {
        let ratio = water[k] / stiffer[k];
        assert!((8.0..12.5).contains(&ratio), "first-order in 1/c: ratio {ratio}");
    }
}

/// The radius of a sphere whose octant holds `v`.
fn equivalent_radius(v: f64) -> f64 {
    (3.0 * v / (4.0 * std::f64::consts::PI / 8.0)).cbrt()
}

/// What a run gives: `(t, R)` samples and the final pressure field.
struct BubbleRun {
    radius: Vec<(f64, f64)>,
    coords: Vec<[f64; 3]>,
    /// The cell faces on the plane `z = 0`.
    plane: Vec<Vec<usize>>,
    pressure: Vec<f64>,
    nodes: usize,
    steps: u64,
    seconds: f64,
}

/// The case with `overrides`, run to `t_end`, and its text.
fn load(overrides: &[String], t_end: f64) -> (Case, String) {
    let mut all = overrides.to_vec();
    all.push(format!("fluid.time.t_end={t_end:e}"));
    (Case::load(&case_path(), &all).unwrap(), std::fs::read_to_string(case_path()).unwrap())
}

/// The run of `case` writing into `out`.
fn open<'a>(case: &'a Case, text: &'a str, out: &Path) -> FluidRun<'a> {
    let opts = RunOptions { out: out.to_path_buf(), quiet: true, restart: None, force: true };
    FluidRun::open(case, text, &opts, Mode::Alone).unwrap()
}

/// The mesh overrides of an octant of radius `radius` with a uniform core `[0, core]³` of `cells`
/// cells per edge, layers growing by `grading` beyond it.
fn octant(core: f64, cells: usize, radius: f64, grading: f64) -> Vec<String> {
    vec![format!(
        "fluid.mesh.octant={{ core = {core:e}, cells = {cells}, radius = {radius:e}, grading = \
         {grading} }}"
    )]
}

/// Runs the case with `overrides` to `t_end` into `out`, sampling the equivalent radius every
/// `every` seconds into `out/radius.csv`.
fn run(overrides: &[String], t_end: f64, every: f64, out: &Path) -> BubbleRun {
    let start = std::time::Instant::now();
    let (case, text) = load(overrides, t_end);
    let mut run = open(&case, &text, out);
    let mesh = run.semidiscretization().mesh.clone();
    let coords = mesh.coords.clone();
    let nodes = coords.len();
    let plane = mesh
        .cells
        .iter()
        .flat_map(|c| c.kind.faces().iter().map(move |f| f.iter().map(|&l| c.nodes[l] as usize)))
        .map(|f| f.collect::<Vec<usize>>())
        .filter(|f| f.iter().all(|&i| coords[i][2] == 0.0))
        .collect();
    let radius_of = |run: &FluidRun| {
        equivalent_radius(gas_volume::piecewise_linear(&mesh, &run.state().phi).unwrap())
    };
    let r_dual = equivalent_radius(gas_volume::smoothed_heaviside(&mesh, &run.state().phi));
    println!(
        "R(0): piecewise-linear {:.5} R0, dual cells {:.5} R0",
        radius_of(&run) / R0,
        r_dual / R0
    );
    // The gas mass, a diagnostic written beside the radius (the ghost-fluid method does not
    // conserve it).
    let gas_mass_of = |run: &FluidRun| {
        let state = run.state();
        let rho: Vec<f64> = state.cons.iter().map(|u| u[0]).collect();
        gas_volume::piecewise_linear_integral(&mesh, &state.phi, &rho).unwrap()
    };
    let mut radius = vec![(0.0, radius_of(&run))];
    let mut gas_mass = vec![gas_mass_of(&run)];
    let samples = (t_end / every).round() as usize;
    for k in 1..=samples {
        let t = t_end * k as f64 / samples as f64;
        let reached = match run.advance_to(t) {
            Ok(reached) => reached,
            Err(e) => {
                println!("run stopped: {e}");
                break;
            }
        };
        radius.push((reached.t, radius_of(&run)));
        gas_mass.push(gas_mass_of(&run));
    }
    let drift = gas_mass.iter().map(|m| (m / gas_mass[0] - 1.0).abs()).fold(0.0, f64::max);
    println!(
        "gas mass: largest drift {:.2}%, at the end {:+.2}%",
        100.0 * drift,
        100.0 * (gas_mass.last().unwrap() / gas_mass[0] - 1.0)
    );
    let mut csv = std::fs::File::create(out.join("radius.csv")).unwrap();
    writeln!(csv, "time,radius,gas_mass").unwrap();
    for ((t, r), m) in radius.iter().zip(&gas_mass) {
        writeln!(csv, "{t:e},{r:e},{m:e}").unwrap();
    }
    let steps = run.reached().step;
    let eos = run.semidiscretization().eos.clone();
    run.finish().unwrap();
    let (end, _, _) = solver::read_checkpoint(out, nodes).unwrap();
    let pressure = (0..nodes).map(|i| eos[end.material[i] as usize].cons_to_prim(&end.cons[i])[4]);
    let pressure = pressure.collect();
    BubbleRun {
        radius,
        coords,
        plane,
        pressure,
        nodes,
        steps,
        seconds: start.elapsed().as_secs_f64(),
    }
}

/// The extremum of the parabola through three equally spaced samples around `k`.
fn vertex(s: &[(f64, f64)], k: usize) -> (f64, f64) {
    let (a, b, c) = (s[k - 1].1, s[k].1, s[k + 1].1);
    let h = s[k + 1].0 - s[k].0;
    let d = a - 2.0 * b + c;
    let x = if d == 0.0 { 0.0 } else { 0.5 * (a - c) / d };
    (s[k].0 + x * h, b - 0.25 * (a - c) * x)
}

/// The first maximum (the largest sample) and the minimum after it (the smallest sample after
/// it), each refined on the parabola through its neighbours.
fn measured_cycle(s: &[(f64, f64)]) -> Cycle {
    let argext = |range: std::ops::Range<usize>, sign: f64| {
        range.max_by(|&i, &j| (sign * s[i].1).total_cmp(&(sign * s[j].1))).unwrap()
    };
    let k_max = argext(1..s.len() - 1, 1.0);
    let k_min = argext(k_max + 1..s.len() - 1, -1.0);
    let (t_max, r_max) = vertex(s, k_max);
    let (t_min, r_min) = vertex(s, k_min);
    Cycle { t_max, r_max, t_min, r_min }
}

/// The initial radius from the level set on octant meshes whose uniform core `[0, 1.5 R0]³` has
/// cells `h0 = R0/n`, for `n = 4, 8, 16`: the piecewise-linear volume
/// ([`gas_volume::piecewise_linear`]) against the dual-cell ramp
/// ([`gas_volume::smoothed_heaviside`]).
#[test]
fn initial_radius_from_the_level_set_converges_at_second_order() {
    let dir = tempfile::tempdir().unwrap();
    let mut errors = Vec::new();
    for n in [4.0, 8.0, 16.0] {
        let mut overrides = octant(1.5 * R0, (1.5 * n) as usize, 3.0 * R0, 1.3);
        overrides.extend(["fluid.lines=[]".into(), "fluid.probes=[]".into()]);
        let (case, text) = load(&overrides, 1e-6);
        let run = open(&case, &text, &dir.path().join(format!("r{n}")));
        let mesh = &run.semidiscretization().mesh;
        let phi = &run.state().phi;
        let pl = equivalent_radius(gas_volume::piecewise_linear(mesh, phi).unwrap()) / R0 - 1.0;
        let dual = equivalent_radius(gas_volume::smoothed_heaviside(mesh, phi)) / R0 - 1.0;
        println!("R0/h0 = {n}: R(0) piecewise-linear {:+.3e}, dual cells {:+.3e}", pl, dual);
        errors.push((n, pl, dual));
    }
    // Seen: -7.08e-3, -1.77e-3, -4.43e-4 (order 2.00, 2.00; the interpolant's surface lies inside
    // the convex sphere) against the dual cells' +3.96e-3, +1.28e-3, +2.19e-4 (order 1.63, 2.54)
    // on these uniform cores; on graded cells the dual cells' point rule is off by O(h).
    assert!(errors[0].1.abs() < 0.01, "R0/h0 = 4: piecewise-linear R(0) error {}", errors[0].1);
    for w in errors.windows(2) {
        let order = |k: fn(&(f64, f64, f64)) -> f64| {
            (k(&w[0]) / k(&w[1])).abs().ln() / (w[1].0 / w[0].0).ln()
        };
        let (pl, dual) = (order(|e| e.1), order(|e| e.2));
        println!(
            "R0/h0 {} -> {}: order piecewise-linear {pl:.2}, dual cells {dual:.2}",
            w[0].0, w[1].0
        );
        assert!(pl > 1.8, "piecewise-linear R(0) order {pl} from R0/h0 = {}", w[0].0);
    }
}

#[test]
fn bubble_follows_keller_miksis_to_its_first_minimum() {
    let km = bubble(c_water()).first_cycle(1e-8);
    let rp = bubble(f64::INFINITY).first_cycle(1e-8);
    println!(
        "Keller-Miksis: R_max {:.4} R0 at {:.4e} s, R_min {:.4} R0 at {:.4e} s (Rayleigh-Plesset \
         R_max {:.4} R0, t_min {:.4e} s)",
        km.r_max / R0,
        km.t_max,
        km.r_min / R0,
        km.t_min,
        rp.r_max / R0,
        rp.t_min
    );
    let mut overrides = Vec::new();
    if let Ok(extra) = std::env::var("BUBBLE_SET") {
        overrides.extend(extra.split(';').filter(|s| !s.is_empty()).map(String::from));
    }
    let dir = tempfile::tempdir().unwrap();
    let out = std::env::var("BUBBLE_OUT").map_or_else(|_| dir.path().join("run"), PathBuf::from);
    // To 6% past the minimum, the radius 150 times a cycle.
    let t_end = std::env::var("BUBBLE_T_END")
        .map_or(1.06 * km.t_min, |s| s.parse().expect("end time in s"));
    let result = run(&overrides, t_end, km.t_min / 150.0, &out);
    let cycle = measured_cycle(&result.radius);
    let err = [cycle.r_max / km.r_max - 1.0, cycle.t_min / km.t_min - 1.0];
    println!(
        "{} nodes, {} steps in {:.1} s: R(0) {:.4} R0; R_max {:.4} R0 at {:.4e} s, R_min {:.4} R0 \
         at {:.4e} s; against Keller-Miksis: R_max {:+.2}%, t_min {:+.2}% (t_max {:+.2}%, R_min \
         {:+.2}%)",
        result.nodes,
        result.steps,
        result.seconds,
        result.radius[0].1 / R0,
        cycle.r_max / R0,
        cycle.t_max,
        cycle.r_min / R0,
        cycle.t_min,
        100.0 * err[0],
        100.0 * err[1],
        100.0 * (cycle.t_max / km.t_max - 1.0),
        100.0 * (cycle.r_min / km.r_min - 1.0)
    );
    let png = std::env::var("BUBBLE_PNG").map_or_else(|_| out.join("pressure.png"), PathBuf::from);
    let caption = format!("underwater bubble: p - p∞ on z = 0 at t = {:.3} ms", t_end * 1e3);
    let r_end = result.radius.last().unwrap().1;
    let scale = picture::draw_pressure(
        &png,
        &result.coords,
        &result.plane,
        &result.pressure,
        P_INF,
        4.0 * km.r_max,
        r_end,
        &caption,
    )
    .unwrap();
    println!("pressure picture {} (±{scale:.3e} Pa)", png.display());
    assert!(std::fs::metadata(&png).unwrap().len() > 1000);
    // The initial radius is the sphere's, to the volume estimate's accuracy.
    assert!((result.radius[0].1 / R0 - 1.0).abs() < 0.02, "R(0) = {}", result.radius[0].1);
    // Seen on the case: R_max -3.78%, t_min -0.83% (R_min +20.1%).
    assert!(err[0].abs() < 0.05 && err[1].abs() < 0.05, "against Keller-Miksis: {err:?}");
}
