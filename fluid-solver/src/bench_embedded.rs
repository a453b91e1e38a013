//! `fluid-solver bench --embedded`: the cost of the embedded boundary (DESIGN §5.1 "Each step")
//! on the bench's tet box, beside the single-material RK2 step of [`crate::bench`]:
//! - a closed capped cylinder (`cylinder`, 100 x 50 facets + caps = 10,200 triangles) tracked by
//!   Alg. 4.2 and by Alg. 4.1, and an open tilted plate (200 x 100 quads = 40,000 triangles) by
//!   Alg. 4.2, each translated by 0.3 cells per step: seconds of `Tracker::advance` and of its
//!   parts (refit, intersect, swept nodes, sides), of `fill_changed`, and the tracking share
//!   `(advance + fill) / (advance + fill + RK2 step)`;
//! - the wall fluxes (Alg. 5.1, `add_wall_fluxes`) over every cut edge of the cylinder, one
//!   thread: nanoseconds per cut edge and the share of one single-material residual;
//! - bytes per node of the embedded state (tracker arrays, surface, hierarchy, the per-node
//!   material index the wall fluxes read and the cut mask the fill reads).

use crate::bench::{median, BenchReport};
use crate::embedded::adjacency::NodeEdges;
use crate::embedded::bvh::Bvh;
use crate::embedded::fill::fill_changed;
use crate::embedded::generate::{cylinder, plate};
use crate::embedded::intersect::{collision, projection, Intersections, SurfaceAt};
use crate::embedded::riemann_fs::{add_wall_fluxes, WallFluxView, WallMaterial};
use crate::embedded::status::{swept_nodes, update_sides};
use crate::embedded::tracker::{Seed, Tracker};
use crate::embedded::Surface;
use crate::eos::Eos;
use crate::flux::FluxScheme;
use crate::mesh::blocks::Window;
use crate::mesh::boxmesh::{BoxCells, BoxSpec};
use crate::mesh::Mesh;
use crate::reconstruct::limiter::Limiter;
use crate::riemann::PressureCutoff;
use interface_protocol::case::Tracking;
use serde::Serialize;
use std::collections::BTreeMap;
use std::time::Instant;

/// Translation per step, in fluid cells.
const SHIFT_CELLS: f64 = 0.3;

/// One case at one thread count (medians over the timed steps).
#[derive(Debug, Clone, Serialize)]
pub struct TrackingMeasurement {
    pub threads: usize,
    /// `Tracker::advance` as a whole.
    pub advance_seconds: f64,
    /// Its parts, timed one by one on a second tracker given the same motion: `refit` (surface
    /// advance + hierarchy refit), `intersect` (Alg. 4.1 or 4.2), `swept_nodes`, `update_sides`.
    pub advance_split_seconds: BTreeMap<String, f64>,
    /// The cut mask and `fill_changed` for the nodes that changed.
    pub fill_seconds: f64,
    /// One single-material RK2 step on the same mesh (from the bench row).
    pub rk2_step_seconds: f64,
    /// `(advance + fill) / (advance + fill + rk2_step)`.
    pub tracking_share: f64,
}

/// One surface and algorithm.
#[derive(Debug, Clone, Serialize)]
pub struct TrackingCase {
    pub name: &'static str,
    pub tracking: &'static str,
    pub triangles: usize,
    pub surface_nodes: usize,
    /// At the last step.
    pub cut_edges: usize,
    pub occluded_nodes: usize,
    /// Means over the timed steps.
    pub swept_nodes_per_step: f64,
    pub changed_nodes_per_step: f64,
    pub measurements: Vec<TrackingMeasurement>,
}

/// The wall fluxes of the cylinder (Alg. 4.2 cuts), one thread.
#[derive(Debug, Clone, Serialize)]
pub struct WallFluxCost {
    pub cut_edges: usize,
    pub ns_per_cut_edge: f64,
    /// Seconds of all wall fluxes.
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
    pub shift_cells_per_step: f64,
    pub steps: usize,
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

/// Runs the embedded rows on the bench's box of about `nodes` nodes for `steps` steps, beside
/// the single-material `fluid` row measured on it (its thread counts are reused).
pub fn run(nodes: usize, steps: usize, fluid: &BenchReport) -> anyhow::Result<EmbeddedReport> {
    anyhow::ensure!(steps > 0, "--steps must be at least 1");
    let n = ((nodes as f64).cbrt().round() as usize).max(3) - 1;
    let mesh = Mesh::build(BoxSpec::uniform([0.0; 3], [1.0; 3], [n, n, n], BoxCells::Tet).raw()?)?;
    anyhow::ensure!(
        mesh.n_nodes() == fluid.nodes,
        "embedded bench on another mesh than the fluid row"
    );
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
            name: "tilted plate",
            tracking: Tracking::Collision,
            surface: Surface::new(&wing.elements, wing.x.clone(), 0)?,
            seeds: vec![outside],
        },
    ];
    let prim: Vec<[f64; 5]> = mesh
        .coords
        .iter()
        .map(|x| {
            let s = (6.0 * x[0]).sin() * (5.0 * x[1]).cos() * (4.0 * x[2] + 1.0).sin();
            [1.0 + 0.2 * s, 0.3 + 0.1 * s, 0.1, 0.05 * s, 1.0 + 0.3 * s]
        })
        .collect();
    let mut cases = Vec::new();
    for spec in &specs {
        let mut case = None;
        let mut measurements = Vec::new();
        for m in &fluid.measurements {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(m.threads).build()?;
            let (c, t) = pool.install(|| track(&mesh, spec, steps, h, &prim))?;
            let tracking = t.advance_seconds + t.fill_seconds;
            measurements.push(TrackingMeasurement {
                threads: m.threads,
                rk2_step_seconds: m.seconds_per_step,
                tracking_share: tracking / (tracking + m.seconds_per_step),
                ..t
            });
            case = Some(c);
        }
        let mut case = case.ok_or_else(|| anyhow::anyhow!("no thread count measured"))?;
        case.measurements = measurements;
        cases.push(case);
    }
    // Wall fluxes and memory on the cylinder by Alg. 4.2 at rest.
    let spec = &specs[0];
    let tracker = Tracker::new(&mesh, spec.surface.clone(), spec.tracking, &spec.seeds)?;
    let wall_fluxes = wall_flux_cost(&mesh, &tracker, &prim, fluid)?;
    let mut split = BTreeMap::new();
    let s = &tracker.surface;
    let surface_bytes = std::mem::size_of_val(&s.triangles[..])
        + std::mem::size_of_val(&s.element_of[..])
        + std::mem::size_of_val(&s.phi[..])
        + 4 * std::mem::size_of_val(&s.x_a[..]);
    split.insert("tracker".to_string(), tracker.memory_bytes());
    split.insert("surface".to_string(), surface_bytes);
    split.insert("bvh".to_string(), tracker.bvh.memory_bytes());
    split.insert("material".to_string(), mesh.n_nodes());
    split.insert("cut_mask".to_string(), mesh.n_edges());
    let per_node = |b: usize| b as f64 / mesh.n_nodes() as f64;
    let bytes_per_node = per_node(split.values().sum());
    Ok(EmbeddedReport {
        nodes: mesh.n_nodes(),
        cell_size: h,
        shift_cells_per_step: SHIFT_CELLS,
        steps,
        cases,
        wall_fluxes,
        bytes_per_node_split: split.into_iter().map(|(k, v)| (k, per_node(v))).collect(),
        bytes_per_node,
        bytes_per_node_with_fluid: bytes_per_node + fluid.bytes_per_node,
    })
}

/// Tracks one case through `1 + steps` translations (the first untimed) in the current pool.
fn track(
    mesh: &Mesh,
    spec: &CaseSpec,
    steps: usize,
    h: f64,
    prim: &[[f64; 5]],
) -> anyhow::Result<(TrackingCase, TrackingMeasurement)> {
    let mut tracker = Tracker::new(mesh, spec.surface.clone(), spec.tracking, &spec.seeds)?;
    // A second tracker given the same motion, advanced part by part.
    let mut parts = tracker.clone();
    let x0 = spec.surface.x_b.clone();
    let shift = SHIFT_CELLS * h;
    let v = vec![[shift, 0.0, 0.0]; x0.len()];
    let (mut advance, mut fill) = (Vec::new(), Vec::new());
    let mut split: BTreeMap<String, Vec<f64>> = BTreeMap::new();
    let (mut swept_total, mut changed_total) = (0usize, 0usize);
    for k in 0..=steps {
        let t_b = (k + 1) as f64;
        let x_b: Vec<[f64; 3]> = x0.iter().map(|p| [p[0] + shift * t_b, p[1], p[2]]).collect();
        let was_active = tracker.active.clone();
        let start = Instant::now();
        let changes = tracker.advance(mesh, t_b, &x_b, &v)?;
        let t_advance = start.elapsed().as_secs_f64();
        let start = Instant::now();
        let cut = tracker.cuts.cut_mask(mesh.n_edges());
        let filled = fill_changed(
            mesh,
            &tracker.adjacency,
            &changes,
            &tracker.sides,
            &was_active,
            &cut,
            prim,
            |_, _| true,
            true,
        )?;
        let t_fill = start.elapsed().as_secs_f64();
        std::hint::black_box(filled);

        let timed = k > 0;
        let mut lap = Instant::now();
        let mut stamp = |name: &str, lap: &mut Instant| {
            if timed {
                split.entry(name.to_string()).or_default().push(lap.elapsed().as_secs_f64());
            }
            *lap = Instant::now();
        };
        parts.surface.advance(t_b, &x_b, &v);
        parts.bvh.update(&parts.surface);
        stamp("refit", &mut lap);
        let cuts = intersect(mesh, &parts.adjacency, &parts.surface, &parts.bvh, spec.tracking)?;
        stamp("intersect", &mut lap);
        let swept = swept_nodes(mesh, &parts.surface, &parts.bvh);
        stamp("swept_nodes", &mut lap);
        let (sides, part_changes) =
            update_sides(mesh, &parts.adjacency, &parts.sides, &cuts, &swept);
        stamp("update_sides", &mut lap);
        anyhow::ensure!(
            cuts == tracker.cuts && sides == tracker.sides && part_changes == changes,
            "{} ({:?}), step {k}: the parts disagree with Tracker::advance",
            spec.name,
            spec.tracking
        );
        parts.cuts = cuts;
        parts.sides = sides;
        if timed {
            advance.push(t_advance);
            fill.push(t_fill);
            swept_total += swept.len();
            changed_total += changes.len();
        }
    }
    let case = TrackingCase {
        name: spec.name,
        tracking: match spec.tracking {
            Tracking::Collision => "Alg. 4.2 (collision)",
            Tracking::Projection => "Alg. 4.1 (projection)",
        },
        triangles: tracker.surface.triangles.len(),
        surface_nodes: tracker.surface.n_nodes(),
        cut_edges: tracker.cuts.cuts.len(),
        occluded_nodes: tracker.cuts.occluded.iter().filter(|o| **o).count(),
        swept_nodes_per_step: swept_total as f64 / steps as f64,
        changed_nodes_per_step: changed_total as f64 / steps as f64,
        measurements: Vec::new(),
    };
    let m = TrackingMeasurement {
        threads: rayon::current_num_threads(),
        advance_seconds: median(advance),
        advance_split_seconds: split.into_iter().map(|(k, v)| (k, median(v))).collect(),
        fill_seconds: median(fill),
        rk2_step_seconds: f64::NAN,
        tracking_share: f64::NAN,
    };
    Ok((case, m))
}

/// The cut edges by the case's algorithm (as [`Tracker::advance`] computes them).
fn intersect(
    mesh: &Mesh,
    adjacency: &NodeEdges,
    surface: &Surface,
    bvh: &Bvh,
    tracking: Tracking,
) -> anyhow::Result<Intersections> {
    let at = SurfaceAt::at_end(surface, bvh)?;
    Ok(match tracking {
        Tracking::Collision => collision(mesh, adjacency, at),
        Tracking::Projection => projection(mesh, adjacency, at),
    })
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
