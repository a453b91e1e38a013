//! `fluid-solver bench --embedded`: the cost of the embedded boundary (DESIGN §5.1 "Each step")
//! on the bench's tet box, beside the single-material RK2 step of [`crate::bench`], in the same
//! run and on the same flow (its perfect gas, state and far field):
//! - a closed capped cylinder (`cylinder`, 100 x 50 facets + caps = 10,200 triangles) tracked by
//!   Alg. 4.2 and by Alg. 4.1, and a thin wing, an open tilted plate (200 x 100 quads = 40,000
//!   triangles), by Alg. 4.2, each translated along x at Mach 0.5 of the free stream (a fast
//!   structure; the report gives the cells it crosses per step):
//!   whole steps of [`EmbeddedRun::step`] (CFL step, tracking, filling the uncovered nodes, the
//!   step's view with its masked gradient, the two RK2 stages with the wall fluxes, `p*` and the
//!   loads), their node-steps/s/core and its ratio to that of the single-material step, timed
//!   once after each of them (interleaved: a shared machine's load falls on both), the tracking
//!   share of the step, and the split of the tracking into its parts (timed one by one on a
//!   second tracker given the same motion, and checked against the run's), with the passes over
//!   the whole mesh they replace (the intersection of every edge, a new step view);
//! - the wall fluxes (Alg. 5.1, `add_wall_fluxes`) over every cut edge of the cylinder, one
//!   thread: nanoseconds per cut edge and the share of one single-material residual;
//! - bytes per node of the embedded state (the tracker after the cylinder's Alg. 4.2 run: its
//!   arrays, the hierarchy over the mesh nodes and the pairs its near part keeps; surface,
//!   surface hierarchy, the step view and the per-node material index the wall fluxes read);
//! - the load average of the machine before and after (the machine may be shared: compare the
//!   ratios, which are measured side by side).

use crate::bench::{median, single_material, BenchReport, FREE_STREAM};
use crate::embedded::advance::EmbeddedRun;
use crate::embedded::case::Prescribed;
use crate::embedded::fill::fill_changed;
use crate::embedded::generate::{cylinder, plate};
use crate::embedded::intersect::{collision, projection, SurfaceAt};
use crate::embedded::motion::RigidMotion;
use crate::embedded::riemann_fs::{add_wall_fluxes, WallFluxView, WallMaterial};
use crate::embedded::status::swept_nodes_near;
use crate::embedded::step::EmbeddedStep;
use crate::embedded::swept::Swept;
use crate::embedded::tracker::{Seed, Tracker};
use crate::embedded::Surface;
use crate::eos::Eos;
use crate::flux::FluxScheme;
use crate::mesh::blocks::Window;
use crate::mesh::boxmesh::{BoxCells, BoxSpec};
use crate::mesh::Mesh;
use crate::reconstruct::limiter::Limiter;
use crate::riemann::PressureCutoff;
use crate::semidiscretization::Semidiscretization;
use crate::state::{State, Workspace};
use crate::time::cfl::stable_time_step;
use crate::time::{rk2_step, TimeStepping};
use interface_protocol::case::{InterfaceTreatment, LoadAlgorithm, Motion, Tracking};
use serde::Serialize;
use std::collections::BTreeMap;
use std::time::Instant;

/// Surface speed over the free stream's sound speed.
const SURFACE_MACH: f64 = 0.5;
/// Courant number of the embedded steps (the single-material row's).
const CFL: f64 = 0.9;

/// One case at one thread count (means over the timed steps).
#[derive(Debug, Clone, Serialize)]
pub struct TrackingMeasurement {
    pub threads: usize,
    /// One whole step with the surface ([`EmbeddedRun::step`]).
    pub step_seconds: f64,
    pub node_steps_per_second_per_core: f64,
    /// This row's node-steps/s/core over the single-material step's at this thread count:
    /// `single_material_step_seconds / step_seconds`.
    pub ratio_to_single_material: f64,
    /// The single-material RK2 step of the bench row on the same box, one after each step of
    /// this row in the same pool (interleaved, so a change of load on a shared machine falls on
    /// both alike), mean over the same steps.
    pub single_material_step_seconds: f64,
    /// The step's tracking: advance, fill, step view (`EmbeddedRun::tracking_s`).
    pub tracking_seconds: f64,
    /// `tracking_seconds / step_seconds`.
    pub tracking_share: f64,
    /// `p*` and the nodal loads at the end of the step.
    pub loads_seconds: f64,
    /// The parts of the tracking: `refit` (surface advance + hierarchy refit), `near` (the mesh
    /// nodes and edges the swept boxes reach), `intersect` (Alg. 4.1 or 4.2 over them),
    /// `swept_nodes`, `update_sides`, `fill` (`fill_changed`), `step_update` (the
    /// step view and its masked gradient, updated).
    pub tracking_split_seconds: BTreeMap<String, f64>,
    /// At the last step: `intersect` over every node and edge, and `step_new` (the step view and
    /// its gradient built anew), the passes the split's `near` + `intersect` and `step_update`
    /// replace (same results, checked).
    pub full_pass_seconds: BTreeMap<String, f64>,
}

/// One surface and algorithm.
#[derive(Debug, Clone, Serialize)]
pub struct TrackingCase {
    pub name: &'static str,
    pub tracking: &'static str,
    pub triangles: usize,
    pub surface_nodes: usize,
    /// Surface speed (Mach 0.5 of the free stream; `shift_cells_per_step` cells a CFL step).
    pub speed: f64,
    /// At the last step.
    pub cut_edges: usize,
    pub occluded_nodes: usize,
    pub inactive_nodes: usize,
    /// Means over the timed steps.
    pub near_nodes_per_step: f64,
    pub near_edges_per_step: f64,
    pub swept_nodes_per_step: f64,
    pub changed_nodes_per_step: f64,
    /// Rebuilds of the kept node-triangle pairs ([`crate::embedded::intersect::NearSkin`]) over
    /// the timed steps.
    pub skin_rebuilds: usize,
    /// Memory of the run's tracker after the last step, the kept pairs of the near part with it.
    pub tracker_bytes: usize,
    pub measurements: Vec<TrackingMeasurement>,
}

/// The wall fluxes of the cylinder (Alg. 4.2 cuts), one thread.
#[derive(Debug, Clone, Serialize)]
pub struct WallFluxCost {
    pub cut_edges: usize,
    pub ns_per_cut_edge: f64,
    /// Seconds of all wall fluxes of one residual.
    pub seconds: f64,
    /// Primitives + gradients + fluxes and boundary of the bench row, one thread.
    pub residual_seconds: f64,
    pub share_of_residual: f64,
}

/// The `embedded` part of the bench report.
#[derive(Debug, Clone, Serialize)]
pub struct EmbeddedReport {
    pub nodes: usize,
    pub cell_size: f64,
    /// The surfaces' speed over the free stream's sound speed.
    pub surface_mach: f64,
    /// The cells the surfaces cross in one CFL step of the initial flow.
    pub shift_cells_per_step: f64,
    pub steps: usize,
    /// `/proc/loadavg` (1, 5, 15 minutes) before and after the embedded rows.
    pub load_average_before: Option<[f64; 3]>,
    pub load_average_after: Option<[f64; 3]>,
    pub cases: Vec<TrackingCase>,
    pub wall_fluxes: WallFluxCost,
    /// Bytes per node of each part of the embedded state of the cylinder (Alg. 4.2).
    pub bytes_per_node_split: BTreeMap<String, f64>,
    pub bytes_per_node: f64,
    /// The bench's single-material bytes per node plus the embedded state.
    pub bytes_per_node_with_fluid: f64,
}

/// A surface to track: its triangles' source, the algorithm and the seeds.
struct CaseSpec {
    name: &'static str,
    tracking: Tracking,
    surface: Surface,
    seeds: Vec<Seed>,
}

/// The machine's load average, where `/proc/loadavg` tells it.
fn load_average() -> Option<[f64; 3]> {
    let text = std::fs::read_to_string("/proc/loadavg").ok()?;
    let mut it = text.split_whitespace().map(|w| w.parse::<f64>().ok());
    Some([it.next()??, it.next()??, it.next()??])
}

/// Runs the embedded rows on the bench's box of about `nodes` nodes for `steps` steps, beside
/// the single-material `fluid` row measured on it (its thread counts are reused).
pub fn run(nodes: usize, steps: usize, fluid: &BenchReport) -> anyhow::Result<EmbeddedReport> {
    anyhow::ensure!(steps > 0, "--steps must be at least 1");
    let load_average_before = load_average();
    let n = ((nodes as f64).cbrt().round() as usize).max(3) - 1;
    let mesh = Mesh::build(BoxSpec::uniform([0.0; 3], [1.0; 3], [n, n, n], BoxCells::Tet).raw()?)?;
    anyhow::ensure!(
        mesh.n_nodes() == fluid.nodes,
        "embedded bench on another mesh than the fluid row"
    );
    let (semi, initial) = single_material(mesh)?;
    let mesh = &semi.mesh;
    let h = 1.0 / n as f64;
    let outside = Seed { point: [0.02; 3], fluid: true };
    let cyl = cylinder([0.4, 0.5, 0.2], [0.4, 0.5, 0.8], 0.2, [100, 50], true);
    let wing = plate([0.2, 0.3, 0.35], [0.6, 0.0, 0.15], [0.0, 0.4, 0.1], [200, 100]);
    let inside = Seed { point: [0.4, 0.5, 0.5], fluid: false };
    let specs = [
        CaseSpec {
            name: "cylinder",
            tracking: Tracking::Collision,
            surface: Surface::new(&cyl.elements, cyl.x.clone(), 0)?,
            seeds: vec![outside, inside],
        },
        CaseSpec {
            name: "cylinder",
            tracking: Tracking::Projection,
            surface: Surface::new(&cyl.elements, cyl.x.clone(), 0)?,
            seeds: vec![outside, inside],
        },
        CaseSpec {
            name: "thin wing (tilted plate)",
            tracking: Tracking::Collision,
            surface: Surface::new(&wing.elements, wing.x.clone(), 0)?,
            seeds: vec![outside],
        },
    ];
    let mut ws = Workspace::new(mesh.n_nodes());
    let dt0 = CFL * stable_time_step(&semi, &initial.cons, &mut ws)?;
    let [rho, .., p] = FREE_STREAM;
    let speed = SURFACE_MACH * semi.eos_at(0).sound_speed(rho, p);
    let shift_cells_per_step = speed * dt0 / h;
    let dir = std::env::temp_dir().join(format!("fiver-bench-embedded-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    let mut cases = Vec::new();
    for spec in &specs {
        let mut case = None;
        let mut measurements = Vec::new();
        for m in &fluid.measurements {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(m.threads).build()?;
            let (c, t) = pool.install(|| track(&semi, &initial, spec, steps, speed, &dir))?;
            measurements.push(t);
            case = Some(c);
        }
        let mut case = case.ok_or_else(|| anyhow::anyhow!("no thread count measured"))?;
        case.measurements = measurements;
        cases.push(case);
    }
    std::fs::remove_dir_all(&dir)?;
    // Wall fluxes and memory on the cylinder by Alg. 4.2 at rest.
    let spec = &specs[0];
    let tracker = Tracker::new(mesh, spec.surface.clone(), spec.tracking, &spec.seeds)?;
    let prim: Vec<[f64; 5]> = initial.cons.iter().map(|w| semi.eos[0].cons_to_prim(w)).collect();
    let wall_fluxes = wall_flux_cost(mesh, &tracker, &prim, fluid)?;
    let step = EmbeddedStep::new(&semi, &tracker, None, InterfaceTreatment::default());
    let mut split = BTreeMap::new();
    let s = &tracker.surface;
    let surface_bytes = std::mem::size_of_val(&s.triangles[..])
        + std::mem::size_of_val(&s.element_of[..])
        + std::mem::size_of_val(&s.phi[..])
        + std::mem::size_of_val(&s.open_part[..])
        + s.edges.memory_bytes()
        + 4 * std::mem::size_of_val(&s.x_a[..]);
    // The tracker after the cylinder's run (Alg. 4.2): with the pairs its near part keeps.
    split.insert("tracker".to_string(), cases[0].tracker_bytes);
    split.insert("surface".to_string(), surface_bytes);
    split.insert("bvh".to_string(), tracker.bvh.memory_bytes());
    split.insert("step_view".to_string(), step.memory_bytes());
    split.insert("material".to_string(), mesh.n_nodes());
    let per_node = |b: usize| b as f64 / mesh.n_nodes() as f64;
    let bytes_per_node = per_node(split.values().sum());
    Ok(EmbeddedReport {
        nodes: mesh.n_nodes(),
        cell_size: h,
        shift_cells_per_step,
        surface_mach: SURFACE_MACH,
        steps,
        load_average_before,
        load_average_after: load_average(),
        cases,
        wall_fluxes,
        bytes_per_node_split: split.into_iter().map(|(k, v)| (k, per_node(v))).collect(),
        bytes_per_node,
        bytes_per_node_with_fluid: bytes_per_node + fluid.bytes_per_node,
    })
}

/// Runs one case through `1 + steps` whole steps (the first untimed) in the current pool, the
/// surface translated along x at `speed`, with a second tracker advanced part by part beside.
fn track(
    semi: &Semidiscretization,
    initial: &State,
    spec: &CaseSpec,
    steps: usize,
    speed: f64,
    dir: &std::path::Path,
) -> anyhow::Result<(TrackingCase, TrackingMeasurement)> {
    let mesh = &semi.mesh;
    let velocity = [speed, 0.0, 0.0];
    let mut surface = spec.surface.clone();
    surface.v_a = vec![velocity; surface.n_nodes()];
    surface.v_b.clone_from(&surface.v_a);
    let tracker = Tracker::new(mesh, surface, spec.tracking, &spec.seeds)?;
    let mut parts = tracker.clone();
    let mut parts_step = EmbeddedStep::new(semi, &parts, None, InterfaceTreatment::default());
    let prescribed = Prescribed {
        tracker,
        motion: Some(RigidMotion::new(Motion::Translation { velocity })),
        reference: spec.surface.x_b.clone(),
        loads: LoadAlgorithm::Reconstructed,
        interface: InterfaceTreatment::default(),
    };
    let mut run = EmbeddedRun::new(prescribed, None, dir)?;
    // The run's own operator (a run may change the material layout; this one does not).
    let mut run_semi = semi.clone();
    let mut state = initial.clone();
    let mut ws = Workspace::new(mesh.n_nodes());
    // The single-material steps interleaved with the run's.
    let (mut single_state, mut single_ws) = (initial.clone(), Workspace::new(mesh.n_nodes()));
    let single_stepping = TimeStepping::Global { cfl: CFL };
    let mut t = 0.0;
    let mut per_step: BTreeMap<&str, Vec<f64>> = BTreeMap::new();
    let mut split: BTreeMap<String, Vec<f64>> = BTreeMap::new();
    let mut full = BTreeMap::new();
    let mut counts = [0usize; 4];
    let mut rebuilds_before_timing = 0;
    for k in 0..=steps {
        let timed = k > 0;
        if k == 1 {
            rebuilds_before_timing = run.tracker.near_skin.rebuilds;
        }
        let (tracking0, loads0) = (run.tracking_s, run.loads_s);
        let start = Instant::now();
        let dt = run.step(&mut run_semi, &mut state, &mut ws, CFL, t, f64::INFINITY, None)?;
        let step_seconds = start.elapsed().as_secs_f64();
        t += dt;
        let start = Instant::now();
        rk2_step(semi, &mut single_state, &mut single_ws, single_stepping, 1.0)?;
        let single_seconds = start.elapsed().as_secs_f64();
        if timed {
            per_step.entry("single").or_default().push(single_seconds);
            per_step.entry("step").or_default().push(step_seconds);
            per_step.entry("tracking").or_default().push(run.tracking_s - tracking0);
            per_step.entry("loads").or_default().push(run.loads_s - loads0);
        }
        // The same motion, part by part.
        let (x_b, v_b) = run.kinematics.sample(t);
        let was_active = parts.active.clone();
        let mut lap = Instant::now();
        let mut stamp = |name: &str, lap: &mut Instant| {
            if timed {
                split.entry(name.to_string()).or_default().push(lap.elapsed().as_secs_f64());
            }
            *lap = Instant::now();
        };
        parts.surface.advance(t, &x_b, &v_b);
        parts.bvh.update(&parts.surface);
        stamp("refit", &mut lap);
        let near = parts.near(mesh);
        stamp("near", &mut lap);
        let cuts = parts.cuts_near(mesh, &near)?;
        stamp("intersect", &mut lap);
        let swept = swept_nodes_near(mesh, &parts.surface, &parts.bvh, &near);
        stamp("swept_nodes", &mut lap);
        let changes = parts.move_sides(mesh, cuts, &swept, &near);
        stamp("update_sides", &mut lap);
        let moved = Swept::new(mesh, &parts, &changes, &was_active);
        let filled = fill_changed(&moved, &ws.prim, |_, _| true, true)?;
        std::hint::black_box(filled);
        stamp("fill", &mut lap);
        parts_step.update(semi, &parts);
        stamp("step_update", &mut lap);
        let tracker = &run.tracker;
        anyhow::ensure!(
            parts.cuts == tracker.cuts && parts.sides == tracker.sides,
            "{} ({:?}), step {k}: the parts disagree with the run's tracker",
            spec.name,
            spec.tracking
        );
        if timed {
            for (c, v) in counts.iter_mut().zip([
                near.nodes.len(),
                near.edges(mesh, &parts.adjacency).len(),
                swept.len(),
                changes.len(),
            ]) {
                *c += v;
            }
        }
        if k == steps {
            let start = Instant::now();
            let at = SurfaceAt::at_end(&parts.surface, &parts.bvh)?;
            let every = match spec.tracking {
                Tracking::Collision => collision(mesh, &parts.adjacency, at),
                Tracking::Projection => projection(mesh, &parts.adjacency, at),
            };
            full.insert("intersect".to_string(), start.elapsed().as_secs_f64());
            let start = Instant::now();
            let fresh = EmbeddedStep::new(semi, &parts, None, InterfaceTreatment::default());
            full.insert("step_new".to_string(), start.elapsed().as_secs_f64());
            anyhow::ensure!(
                every == parts.cuts && fresh == parts_step,
                "{} ({:?}): the passes over the surface's part of the mesh disagree with the \
                 passes over the whole mesh",
                spec.name,
                spec.tracking
            );
        }
    }
    let tracker = &run.tracker;
    let mean = |c: usize| c as f64 / steps as f64;
    let case = TrackingCase {
        name: spec.name,
        tracking: match spec.tracking {
            Tracking::Collision => "Alg. 4.2 (collision)",
            Tracking::Projection => "Alg. 4.1 (projection)",
        },
        triangles: tracker.surface.triangles.len(),
        surface_nodes: tracker.surface.n_nodes(),
        speed,
        cut_edges: tracker.cuts.cuts.len(),
        occluded_nodes: tracker.cuts.occluded.iter().filter(|o| **o).count(),
        inactive_nodes: tracker.active.iter().filter(|a| !**a).count(),
        near_nodes_per_step: mean(counts[0]),
        near_edges_per_step: mean(counts[1]),
        swept_nodes_per_step: mean(counts[2]),
        changed_nodes_per_step: mean(counts[3]),
        skin_rebuilds: tracker.near_skin.rebuilds - rebuilds_before_timing,
        tracker_bytes: tracker.memory_bytes(),
        measurements: Vec::new(),
    };
    // Means, not medians: the kept pairs of the tracking rebuild on some steps only.
    let mut mean_of = |k: &str| {
        let v = per_step.remove(k).unwrap_or_default();
        v.iter().sum::<f64>() / v.len().max(1) as f64
    };
    let (step, tracking, loads) = (mean_of("step"), mean_of("tracking"), mean_of("loads"));
    let single = mean_of("single");
    let threads = rayon::current_num_threads();
    let m = TrackingMeasurement {
        threads,
        step_seconds: step,
        node_steps_per_second_per_core: mesh.n_nodes() as f64 / step / threads as f64,
        ratio_to_single_material: single / step,
        single_material_step_seconds: single,
        tracking_seconds: tracking,
        tracking_share: tracking / step,
        loads_seconds: loads,
        tracking_split_seconds: split
            .into_iter()
            .map(|(k, v)| (k, v.iter().sum::<f64>() / v.len().max(1) as f64))
            .collect(),
        full_pass_seconds: full,
    };
    Ok((case, m))
}

/// Alg. 5.1 over every cut edge of `tracker`, one thread, median of 5.
fn wall_flux_cost(
    mesh: &Mesh,
    tracker: &Tracker,
    prim: &[[f64; 5]],
    fluid: &BenchReport,
) -> anyhow::Result<WallFluxCost> {
    let materials =
        [WallMaterial { eos: Eos::PerfectGas { gamma: 1.4 }, cutoff: PressureCutoff::OFF }];
    let material = vec![0u8; mesh.n_nodes()];
    // The second-order interface (the default) with the gradients of the uniform bench state.
    let grad = vec![[[0.0; 3]; 5]; mesh.n_nodes()];
    let view = WallFluxView {
        mesh,
        surface: &tracker.surface,
        t: tracker.surface.t_b,
        scheme: FluxScheme::Roe,
        active: &tracker.active,
        material: &material,
        materials: &materials,
        prim,
        grad: Some(&grad),
        limiter: Limiter::VanAlbada,
    };
    let cuts = &tracker.cuts.cuts;
    anyhow::ensure!(!cuts.is_empty(), "the cylinder cuts no edge of the bench box");
    let mut r = vec![[0.0; 5]; mesh.n_nodes()];
    let mut p_star = vec![[0.0; 2]; cuts.len()];
    let mut times = Vec::new();
    for _ in 0..5 {
        let start = Instant::now();
        add_wall_fluxes(&view, cuts, &mut Window::new(0, &mut r), &mut p_star)?;
        times.push(start.elapsed().as_secs_f64());
    }
    let seconds = median(times);
    let one = fluid
        .measurements
        .iter()
        .find(|m| m.threads == 1)
        .ok_or_else(|| anyhow::anyhow!("the wall flux share needs the 1-thread bench row"))?;
    let residual_seconds = ["primitives", "gradients", "fluxes_and_boundary"]
        .iter()
        .map(|k| one.residual_split_seconds.get(*k).copied().unwrap_or(0.0))
        .sum::<f64>();
    Ok(WallFluxCost {
        cut_edges: cuts.len(),
        ns_per_cut_edge: seconds / cuts.len() as f64 * 1e9,
        seconds,
        residual_seconds,
        share_of_residual: seconds / residual_seconds,
    })
}
