//! `cases/heaving-plate` shrunk to t = 1.4 ms: an open strip plate heaving in air (Alg. 4.2
//! tracking, Alg. 5.1 fluxes on both faces). Until the diffraction from the free edges reaches the
//! probes on the plate's axis (about 1.5 ms), each face radiates the plane simple wave of a piston
//! (`p' ≈ ±ρ c w`, `riemann::simple_wave`): the probes above and below follow it, and the two
//! sides' pressure disturbances are opposite. On the way the loads of the run's state are taken
//! with both Alg. 5.3 and Alg. 5.4, each side's alone and both summed: each face's load on the
//! plate's middle node column is the face pressure of the simple wave, and the two algorithms'
//! resultants agree. The pressure on the cut plane `y = -0.025` is drawn to a PNG (set
//! `HEAVING_PLATE_PNG=<path>` to choose where; the case folder's picture is the full case at
//! t = 5 ms, drawn by `HEAVING_PLATE_PNG=cases/heaving-plate/pressure.png HEAVING_PLATE_END=5e-3`).

mod common;

use common::plot::diverging;
use fluid_solver::embedded::loads::{nodal_loads, LoadAlgorithm, LoadView};
use fluid_solver::eos::Eos;
use fluid_solver::riemann::simple_wave::SimpleWave;
use fluid_solver::solver::{self, FluidRun, Mode, RunOptions};
use interface_protocol::case::Case;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

const RHO0: f64 = 1.3;
const P0: f64 = 1e5;
/// The plate's rest height, heave amplitude and angular frequency.
const Z0: f64 = 0.02;
const A: f64 = 0.005;
const OMEGA: f64 = std::f64::consts::TAU * 200.0;

fn case_path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../cases/heaving-plate/case.toml")
}

/// Columns of a CSV file by name.
fn columns(path: &Path) -> std::collections::HashMap<String, Vec<f64>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let names: Vec<String> = lines.next().unwrap().split(',').map(str::to_string).collect();
    let mut cols: Vec<Vec<f64>> = vec![Vec::new(); names.len()];
    for l in lines {
        for (c, v) in cols.iter_mut().zip(l.split(',')) {
            c.push(v.parse().unwrap());
        }
    }
    names.into_iter().zip(cols).collect()
}

/// The plate's height and velocity at `t`.
fn plate(t: f64) -> (f64, f64) {
    (Z0 + A * (1.0 - (OMEGA * t).cos()), A * OMEGA * (OMEGA * t).sin())
}

/// The plane simple wave's pressure at height `z` and time `t` on the side `below` (the gas
/// below the plate sees it withdraw; above, the mirror image: it advances).
fn piston_pressure(z: f64, t: f64, below: bool) -> f64 {
    let s = if below { 1.0 } else { -1.0 };
    let piston = move |t: f64| {
        let (zp, w) = plate(t);
        (s * zp, s * w)
    };
    let wave = SimpleWave { piston, gamma: 1.4, rho0: RHO0, p0: P0 };
    wave.state(s * z, t).expect("smooth before the shock").2
}

/// The pressure on the face of the plate on the side `below`: the simple wave's at the piston,
/// `p0 (1 - (γ - 1) u / (2 c0))^(2γ / (γ - 1))` with `u` the face's speed away from the gas (the
/// Riemann invariant `u + 2c / (γ - 1)` of the gas at rest).
fn face_pressure(t: f64, below: bool) -> f64 {
    let gamma = 1.4f64;
    let c0 = (gamma * P0 / RHO0).sqrt();
    let u = if below { plate(t).1 } else { -plate(t).1 };
    P0 * (1.0 - 0.5 * (gamma - 1.0) * u / c0).powf(2.0 * gamma / (gamma - 1.0))
}

/// The slab's width in y (the mesh's), over which the plate is wet.
const SLAB: f64 = 0.05;
/// The plate's node spacing along x (1 m in 8 cells).
const DX: f64 = 0.125;

/// The loads of the run's current state by both algorithms (`[Alg. 5.3, Alg. 5.4]`).
struct LoadSample {
    t: f64,
    /// `z` resultant of both sides summed.
    fz: [f64; 2],
    /// Per side (`[below, above]`), the pressure disturbance `p* - p0` its load puts on the middle
    /// node column `x = 0`: `±f_z / (Δx · slab)` (the column's shape functions sum to the hat of
    /// width `2 Δx` in x; the disturbance alone, since the distribution's O(h) error in the
    /// column's share of the area would weigh on all of `p0`).
    face: [[f64; 2]; 2],
}

fn sample_loads(run: &FluidRun) -> LoadSample {
    let mesh = &run.semidiscretization().mesh;
    let tracker = &run.embedded().expect("an embedded surface").tracker;
    let surface = &tracker.surface;
    let zp = plate(surface.t_b).0;
    let column: Vec<usize> =
        (0..surface.n_nodes()).filter(|&n| surface.x_b[n][0].abs() < 1e-9).collect();
    assert_eq!(column.len(), 2, "the middle column of the plate's nodes");
    let cuts = &tracker.cuts.cuts;
    // `p* - p0` of one side only: an end is below the plate when its node is.
    let one_side = |below: bool| -> Vec<[f64; 2]> {
        let ps = tracker.p_star.iter().zip(cuts);
        ps.map(|(p, c)| {
            let ends = mesh.edges[c.edge as usize];
            [0, 1].map(|m| {
                let under = mesh.coords[ends[m] as usize][2] < zp;
                if under == below {
                    p[m] - P0
                } else {
                    f64::NAN
                }
            })
        })
        .collect()
    };
    let loads = |algorithm: LoadAlgorithm, p_star: &[[f64; 2]]| {
        let view = LoadView {
            mesh,
            adjacency: &tracker.adjacency,
            surface,
            t: surface.t_b,
            side: &tracker.sides.side,
            cuts,
            p_star,
        };
        let mut out = vec![[0.0; 3]; surface.n_nodes()];
        nodal_loads(algorithm, &view, &mut out).unwrap();
        out
    };
    let (below, above) = (one_side(true), one_side(false));
    let algorithms = [LoadAlgorithm::Reconstructed, LoadAlgorithm::Facets];
    let fz = algorithms.map(|a| loads(a, &tracker.p_star).iter().map(|f| f[2]).sum());
    let face = algorithms.map(|a| {
        [(&below, 1.0), (&above, -1.0)].map(|(p, sign)| {
            let f = loads(a, p);
            sign * column.iter().map(|&n| f[n][2]).sum::<f64>() / (DX * SLAB)
        })
    });
    LoadSample { t: surface.t_b, fz, face }
}

/// Runs the case to `t_end` into `out`, taking the loads at the times `at` on the way: the node
/// positions and primitive states at the end, and the load samples.
fn run(t_end: f64, out: &Path, at: &[f64]) -> (Vec<[f64; 3]>, Vec<[f64; 5]>, Vec<LoadSample>) {
    let overrides = vec![format!("fluid.time.t_end={t_end:e}")];
    let case = Case::load(&case_path(), &overrides).unwrap();
    let text = std::fs::read_to_string(case_path()).unwrap();
    let opts = RunOptions { out: out.to_path_buf(), quiet: true, restart: None, force: false };
    let mut run = FluidRun::open(&case, &text, &opts, Mode::Alone).unwrap();
    let coords = run.semidiscretization().mesh.coords.clone();
    let mut samples = Vec::new();
    for &t in at.iter().filter(|&&t| t < t_end) {
        run.advance_to(t).unwrap();
        samples.push(sample_loads(&run));
    }
    run.advance_to(run.t_end()).unwrap();
    let summary = run.finish().unwrap();
    let (state, _, _) = solver::read_checkpoint(out, summary.nodes).unwrap();
    let eos = Eos::PerfectGas { gamma: 1.4 };
    (coords, state.cons.iter().map(|q| eos.cons_to_prim(q)).collect(), samples)
}

/// Draws `p - p0` at the nodes of the plane `y = y_plane` (one square per node of side `h`) and
/// the plate at height `z_plate`.
fn draw_pressure(
    path: &Path,
    coords: &[[f64; 3]],
    prim: &[[f64; 5]],
    y_plane: f64,
    h: f64,
    z_plate: f64,
    t: f64,
) -> anyhow::Result<f64> {
    let on_plane: Vec<usize> =
        (0..coords.len()).filter(|&i| (coords[i][1] - y_plane).abs() < 1e-9).collect();
    anyhow::ensure!(!on_plane.is_empty(), "no node on the plane y = {y_plane}");
    let scale = on_plane.iter().map(|&i| (prim[i][4] - P0).abs()).fold(0.0, f64::max);
    let root = BitMapBackend::new(path, (820, 760)).into_drawing_area();
    root.fill(&WHITE)?;
    let caption = format!(
        "heaving plate: p - p0 on y = {y_plane} at t = {:.2} ms (±{scale:.0} Pa, blue-red)",
        t * 1e3
    );
    let mut chart = ChartBuilder::on(&root)
        .caption(caption, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(36)
        .y_label_area_size(48)
        .build_cartesian_2d(-1.5..1.5, -1.5..1.5)?;
    chart.configure_mesh().disable_mesh().x_desc("x (m)").y_desc("z (m)").draw()?;
    chart.draw_series(on_plane.iter().map(|&i| {
        let [x, _, z] = coords[i];
        let c = diverging((prim[i][4] - P0) / scale.max(1e-300));
        Rectangle::new([(x - 0.5 * h, z - 0.5 * h), (x + 0.5 * h, z + 0.5 * h)], c.filled())
    }))?;
    chart.draw_series(LineSeries::new([(-0.5, z_plate), (0.5, z_plate)], BLACK.stroke_width(3)))?;
    root.present()?;
    Ok(scale)
}

#[test]
fn heaving_plate_radiates_piston_waves_of_opposite_sign() {
    let dir = tempfile::tempdir().unwrap();
    let t_end: f64 =
        std::env::var("HEAVING_PLATE_END").map_or(1.4e-3, |s| s.parse().expect("a time in s"));
    let out = dir.path().join("run");
    // Before the free edges' diffraction reaches the middle column (|0.5 - Δx| / c ≈ 1.0 ms).
    let at: Vec<f64> = (1..=8).map(|k| 1e-4 * k as f64).collect();
    let (coords, prim, samples) = run(t_end, &out, &at);
    let probes = columns(&out.join("probes.csv"));
    let (t, above, below) = (&probes["time"], &probes["above.p"], &probes["below.p"]);
    let (z_above, z_below) = (0.1, -0.05);
    // Piston theory on the axis before the free edges' diffraction arrives (|x - 0.5| / c ≈ 1.5
    // ms): the plane wave's pressure, within 8% of its largest disturbance.
    let peak = 1.3 * (1.4f64 * P0 / RHO0).sqrt() * A * OMEGA;
    let mut worst = [0.0f64; 2];
    let mut asymmetry = 0.0f64;
    let mut largest = 0.0f64;
    for k in 0..t.len() {
        if t[k] > 1.4e-3 {
            break;
        }
        let exact = [piston_pressure(z_above, t[k], false), piston_pressure(z_below, t[k], true)];
        worst[0] = worst[0].max((above[k] - exact[0]).abs());
        worst[1] = worst[1].max((below[k] - exact[1]).abs());
        asymmetry = asymmetry.max((above[k] - P0 + below[k] - P0).abs());
        largest = largest.max((above[k] - P0).abs());
    }
    println!(
        "{} probe rows; largest p' above {largest:.1} Pa (ρ c w_max = {peak:.1} Pa); against the \
         simple wave: above {:.1} Pa, below {:.1} Pa; largest p'_above + p'_below {asymmetry:.1} Pa",
        t.len(),
        worst[0],
        worst[1]
    );
    assert!(largest > 0.6 * peak, "the wave above the plate is too weak: {largest} Pa");
    assert!(worst[0] < 0.08 * peak && worst[1] < 0.08 * peak, "{worst:?} against {peak}");
    assert!(asymmetry < 0.08 * peak, "sides not opposite: {asymmetry} Pa");
    // Each face's load is its face pressure, with either algorithm (within 8% of ρ c w_max), and
    // the two algorithms' resultants agree.
    let area = 1.0 * SLAB;
    let mut face_error = [[0.0f64; 2]; 2];
    let mut resultant_gap = 0.0f64;
    for s in &samples {
        let exact = [face_pressure(s.t, true) - P0, face_pressure(s.t, false) - P0];
        for (a, err) in face_error.iter_mut().enumerate() {
            for side in 0..2 {
                err[side] = err[side].max((s.face[a][side] - exact[side]).abs());
            }
        }
        resultant_gap = resultant_gap.max((s.fz[0] - s.fz[1]).abs());
        println!(
            "t {:.2} ms: face p' below {:.1} / {:.1} Pa (5.3 / 5.4; simple wave {:.1}), above \
             {:.1} / {:.1} Pa (simple wave {:.1}); fz {:.2} / {:.2} N",
            s.t * 1e3,
            s.face[0][0],
            s.face[1][0],
            exact[0],
            s.face[0][1],
            s.face[1][1],
            exact[1],
            s.fz[0],
            s.fz[1]
        );
    }
    println!(
        "face pressure against the simple wave: Alg. 5.3 {:.1?} Pa, Alg. 5.4 {:.1?} Pa; largest \
         |fz(5.3) - fz(5.4)| {resultant_gap:.3} N (2 ρ c w_max A = {:.1} N)",
        face_error[0],
        face_error[1],
        2.0 * peak * area
    );
    assert_eq!(samples.len(), at.len(), "load samples");
    assert!(face_error.iter().flatten().all(|&e| e < 0.08 * peak), "{face_error:?} vs {peak}");
    assert!(resultant_gap < 0.05 * 2.0 * peak * area, "resultants differ by {resultant_gap} N");
    // The load on the plate opposes its velocity while it accelerates upwards.
    let forces = columns(&out.join("surface_forces.csv"));
    let (tf, fz) = (&forces["time"], &forces["surface.fz"]);
    let mid = (0..tf.len()).filter(|&k| tf[k] > 0.3e-3 && tf[k] < 1.2e-3);
    assert!(mid.clone().count() > 5 && mid.clone().all(|k| fz[k] < 0.0), "the load must resist");
    let png = std::env::var("HEAVING_PLATE_PNG")
        .map_or_else(|_| dir.path().join("pressure.png"), PathBuf::from);
    let scale = draw_pressure(&png, &coords, &prim, -0.025, 0.05, plate(t_end).0, t_end).unwrap();
    println!("pressure picture {} (±{scale:.0} Pa)", png.display());
    assert!(std::fs::metadata(&png).unwrap().len() > 1000);
}
