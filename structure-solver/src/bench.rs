//! `structure-solver bench`: the speed of whole explicit BT4 steps (element updates per second
//! per core, J2 with the plane-stress return at 5 thickness points; natural and shuffled
//! input numbering, each as given and renumbered for locality as the model build does
//! ([`crate::mesh::renumber`]), 1 and 2 threads) and of an implicit
//! Newmark step of a 10k-node MITC4 shell with the time of each piece of a Newton iteration
//! (internal force, tangent, factorisation, solve), printed as JSON (DESIGN §6, §7).

use std::time::Instant;

use rayon::prelude::*;
use serde::Serialize;

use crate::assembly::{Curve, FeModel, Part};
use crate::elements::bt4::{Bt4, Bt4Settings, SimdPath, LANES};
use crate::elements::ShellSection;
use crate::material::{Elastic, J2};
use crate::mesh::generate::rectangle;
use crate::mesh::renumber::{bandwidth_profile, mean_cell_spread, renumber, shuffle_numbering};
use crate::mesh::Mesh;
use crate::time::{Implicit, ImplicitScheme};

/// Bench results.
#[derive(Debug, Serialize)]
pub struct BenchReport {
    pub explicit_bt4: ExplicitBench,
    /// The 3-node shell on the same number of elements.
    pub explicit_blt3: crate::bench_blt3::Blt3Bench,
    pub implicit_newmark: Option<ImplicitBench>,
    /// The factor reused as the GMRES preconditioner, on 1 and 2 threads.
    pub implicit_factor_reuse: crate::bench_implicit::ImplicitReuseBench,
}

#[derive(Debug, Serialize)]
pub struct ExplicitBench {
    pub elements: usize,
    pub steps: usize,
    pub thickness_points: usize,
    pub newton_updates: usize,
    pub lanes: usize,
    /// The instruction set the block loop ran on.
    pub simd_path: &'static str,
    /// State and work arrays per element (double-buffered state, mesh, element node slots and
    /// shared-node rows of the first thread count), without the nodal arrays.
    pub bytes_per_element: f64,
    /// Natural order on the first thread count (1 by default): the headline numbers.
    pub element_updates_per_s_per_core: f64,
    pub plastic_fraction: f64,
    pub runs: Vec<ExplicitRun>,
    /// Element updates per second on 2 threads over 1 thread, natural order.
    pub speedup_2_threads_natural: Option<f64>,
    pub speedup_2_threads_shuffled: Option<f64>,
    /// Natural against shuffled numbering, as given and renumbered.
    pub locality: LocalityBench,
    /// The C reference of the same step (natural order, one thread), measured in this run.
    pub c_reference: CReference,
}

pub use crate::bench_c::{c_reference, CReference};

/// What the locality renumbering does to the bench plate: rates of the first thread count
/// (natural over shuffled numbering, renumbered over as given), and the node-graph profile and
/// mean node-slot spread of an element in each numbering. Renumbered, the natural and the
/// shuffled plate are stored alike, so their ratio shows the noise of the measurement.
#[derive(Debug, Serialize)]
pub struct LocalityBench {
    pub threads: usize,
    pub natural_over_shuffled_as_given: Ratio,
    pub natural_over_shuffled_renumbered: Ratio,
    pub renumbered_over_as_given_natural: Ratio,
    pub renumbered_over_as_given_shuffled: Ratio,
    pub numberings: Vec<NumberingLocality>,
}

/// A ratio of rates per second of wall-clock time and per second of processor time.
#[derive(Debug, Serialize)]
pub struct Ratio {
    pub wall: f64,
    pub cpu: f64,
}

/// The node graph of one numbering of the bench plate.
#[derive(Debug, Serialize)]
pub struct NumberingLocality {
    pub order: &'static str,
    pub renumbered: bool,
    pub bandwidth: usize,
    pub profile: usize,
    pub mean_element_spread: f64,
}

/// One whole explicit step (forces, velocity and position update, stable step), timed.
#[derive(Debug, Serialize)]
pub struct ExplicitRun {
    /// `natural` (row by row) or `shuffled` (a fixed-seed permutation of the node and element
    /// numbering) input.
    pub order: &'static str,
    /// Whether the input was renumbered for locality, as the model build does.
    pub renumbered: bool,
    pub threads: usize,
    /// Share of thickness points yielding in the timed steps.
    pub plastic_fraction: f64,
    pub element_updates_per_s: f64,
    pub element_updates_per_s_per_core: f64,
    pub ns_per_element_update: f64,
    /// Per second of processor time of the process (all threads): the rate the code reaches
    /// on the cores it got, when other work shares the machine (wall-clock rates then fall).
    pub element_updates_per_cpu_s: f64,
}

#[derive(Debug, Serialize)]
pub struct ImplicitBench {
    pub nodes: usize,
    pub dofs: usize,
    pub steps: usize,
    pub newton_iterations: usize,
    pub seconds_per_step: f64,
    pub seconds_per_newton_iteration: f64,
    /// One Newton iteration's pieces at the final configuration.
    pub pieces: IterationPieces,
}

/// Seconds spent in each piece of a Newton iteration (best of three).
#[derive(Debug, Serialize)]
pub struct IterationPieces {
    pub internal_force: f64,
    pub tangent_assembly: f64,
    /// The element tangents alone, on one thread.
    pub element_tangents_one_thread: f64,
    pub factorisation: f64,
    pub solve: f64,
    /// Entries of the tangent's stream (before summing duplicates).
    pub tangent_entries: usize,
}

/// Times each piece of a Newton iteration of `model` at its current configuration.
fn pieces(model: &mut FeModel) -> anyhow::Result<IterationPieces> {
    use crate::linsolve::FreeSolver;
    use crate::model::Model;
    use faer::linalg::solvers::Solve;
    let best = |f: &mut dyn FnMut()| {
        (0..3)
            .map(|_| {
                let t = Instant::now();
                f();
                t.elapsed().as_secs_f64()
            })
            .fold(f64::INFINITY, f64::min)
    };
    let n = model.n_dof();
    let mut fi = vec![0.0; n];
    let internal_force = best(&mut || model.internal_force(&mut fi));
    let mut tangent = crate::model::Tangent::default();
    let tangent_assembly = best(&mut || model.tangent(0.0, &mut tangent));
    let element_tangents_one_thread = best(&mut || {
        let (x, r) = (model.positions(), model.rotations());
        for (i, e) in model.elements().iter().enumerate() {
            let xe: Vec<_> = e.nodes.iter().map(|&n| x[n]).collect();
            let re: Vec<_> = e.nodes.iter().map(|&n| r[n]).collect();
            std::hint::black_box(e.tangent(&xe, &re, model.element_state(i), None));
        }
    });
    let mass = model.lumped_mass().to_vec();
    let mut solver = FreeSolver::new(model);
    // the first factorisation makes the symbolic analysis
    let lu = solver.factor(&tangent, 1.0, Some((1e8, &mass)))?;
    let mut result = Ok(());
    let factorisation = best(&mut || {
        if let Err(e) = solver.factor(&tangent, 1.0, Some((1e8, &mass))) {
            result = Err(e);
        }
    });
    result?;
    let rhs = solver.free.gather(&fi);
    let solve = best(&mut || {
        std::hint::black_box(lu.solve(&rhs));
    });
    Ok(IterationPieces {
        internal_force,
        tangent_assembly,
        element_tangents_one_thread,
        factorisation,
        solve,
        tangent_entries: tangent.len(),
    })
}

pub(crate) fn steel() -> J2 {
    J2 { elastic: Elastic { e: 200e9, nu: 0.3, rho: 7800.0 }, sigma_y: 250e6, h: 1e9 }
}

/// The seed of the bench's shuffled numbering.
const SHUFFLE_SEED: u64 = 0x9e37_79b9_7f4a_7c15;

/// The bench plate: `n x n` quads on the unit square, numbered row by row (natural) or at
/// random (shuffled), as given or renumbered for locality.
pub struct Bt4Plate {
    pub mesh: Mesh,
    pub x0: Vec<[f64; 3]>,
    pub conn: Vec<[u32; 4]>,
}

impl Bt4Plate {
    pub fn new(elements: usize, shuffled: bool, renumbered: bool) -> Bt4Plate {
        let n = (elements as f64).sqrt().ceil().max(1.0) as usize;
        let mut mesh = rectangle(1.0, 1.0, n, n);
        if shuffled {
            mesh = shuffle_numbering(&mesh, SHUFFLE_SEED);
        }
        if renumbered {
            mesh = renumber(mesh);
        }
        let conn: Vec<[u32; 4]> = mesh
            .cells
            .iter()
            .map(|c| [c.nodes[0], c.nodes[1], c.nodes[2], c.nodes[3]].map(|v| v as u32))
            .collect();
        Bt4Plate { x0: mesh.nodes.clone(), conn, mesh }
    }

    /// The node graph's locality in this numbering.
    fn locality(&self, order: &'static str, renumbered: bool) -> NumberingLocality {
        let (bandwidth, profile) = bandwidth_profile(&self.mesh);
        let mean_element_spread = mean_cell_spread(&self.mesh);
        NumberingLocality { order, renumbered, bandwidth, profile, mean_element_spread }
    }

    /// The initial velocity of the bench (`plate_velocity`).
    pub fn velocity(&self) -> Vec<f64> {
        plate_velocity(&self.x0)
    }
}

/// Initial velocity (6 per node) of a bench plate on the unit square: a biaxial stretch at
/// 160/s and a transverse sine at 20 m/s, so the points yield after a few steps and keep
/// yielding.
pub(crate) fn plate_velocity(x0: &[[f64; 3]]) -> Vec<f64> {
    let mut v = vec![0.0; 6 * x0.len()];
    let pi = std::f64::consts::PI;
    for (i, p) in x0.iter().enumerate() {
        v[6 * i] = 160.0 * (p[0] - 0.5);
        v[6 * i + 1] = -40.0 * (p[1] - 0.5);
        v[6 * i + 2] = 20.0 * (pi * p[0]).sin() * (pi * p[1]).sin();
    }
    v
}

/// Free explicit dynamics of a BT4 plate (central difference, no load).
pub struct Bt4Explicit {
    pub bt4: Bt4,
    pub x: Vec<[f64; 3]>,
    pub v: Vec<f64>,
    pub du: Vec<f64>,
    pub f: Vec<f64>,
    pub inv_mass: Vec<f64>,
    pub dt: f64,
}

impl Bt4Explicit {
    pub fn new(plate: &Bt4Plate) -> Bt4Explicit {
        let ne = plate.conn.len();
        let bt4 = Bt4::new(plate.conn.clone(), vec![0.01; ne], steel(), Bt4Settings::default());
        let nn = plate.x0.len();
        let mut mass = vec![0.0; 6 * nn];
        bt4.lumped_mass(&plate.x0, &mut mass);
        let dt = 0.9 * bt4.stable_dt(&plate.x0);
        Bt4Explicit {
            bt4,
            x: plate.x0.clone(),
            v: plate.velocity(),
            du: vec![0.0; 6 * nn],
            f: vec![0.0; 6 * nn],
            inv_mass: mass.iter().map(|m| 1.0 / m).collect(),
            dt,
        }
    }

    /// One whole step: `Δu = dt v`, `x += Δu`, internal forces, commit, `v -= dt f / m`, the
    /// next stable step.
    pub fn step(&mut self) {
        advance_positions(self.dt, &mut self.x, &mut self.du, &self.v, &mut self.f);
        self.bt4.internal_force(&self.x, &self.du, &mut self.f);
        self.bt4.commit();
        update_velocities(self.dt, &mut self.v, &self.f, &self.inv_mass);
        self.dt = 0.9 * self.bt4.stable_dt(&self.x);
    }

    fn plastic(&self) -> Vec<f64> {
        let np = self.bt4.settings.rule.len();
        (0..self.bt4.n_elements())
            .flat_map(|e| (0..np).map(move |p| (e, p)))
            .map(|(e, p)| self.bt4.plastic_strain(e, p))
            .collect()
    }
}

/// The first half of a central-difference step of a free explicit bench: `Δu = dt v` (6 per
/// node), `x += Δu` (translations), and the forces `f` zeroed.
pub(crate) fn advance_positions(
    dt: f64,
    x: &mut [[f64; 3]],
    du: &mut [f64],
    v: &[f64],
    f: &mut [f64],
) {
    (x.par_iter_mut(), du.par_chunks_mut(6), v.par_chunks(6))
        .into_par_iter()
        .with_min_len(4096)
        .for_each(|(x, du, v)| {
            for k in 0..6 {
                du[k] = dt * v[k];
            }
            for k in 0..3 {
                x[k] += du[k];
            }
        });
    f.par_iter_mut().with_min_len(4096).for_each(|f| *f = 0.0);
}

/// The second half: `v -= dt f / m` with the inverse lumped masses.
pub(crate) fn update_velocities(dt: f64, v: &mut [f64], f: &[f64], inv_mass: &[f64]) {
    (v.par_iter_mut(), f.par_iter(), inv_mass.par_iter())
        .into_par_iter()
        .with_min_len(4096)
        .for_each(|(v, f, im)| *v -= dt * f * im);
}

/// Processor time of the process (all threads) around `f`, with its wall-clock seconds.
pub(crate) fn timed(f: impl FnOnce()) -> (f64, f64) {
    let (t0, c0) = (Instant::now(), process_cpu_seconds());
    f();
    (t0.elapsed().as_secs_f64(), process_cpu_seconds() - c0)
}

/// Times whole explicit steps of BT4 + J2 (5 points, plane-stress return) on a plate of about
/// `elements` elements, natural and shuffled order, on each thread count.
pub fn explicit(elements: usize, steps: usize, threads: &[usize]) -> anyhow::Result<ExplicitBench> {
    anyhow::ensure!(elements > 0 && steps > 0, "--elements and the steps must be positive");
    anyhow::ensure!(
        !threads.is_empty() && threads.iter().all(|&t| t > 0),
        "--threads must list thread counts of at least 1, e.g. 1,2"
    );
    let mut runs = Vec::new();
    let mut numberings = Vec::new();
    let mut info = None;
    let mut rust_end: Option<Vec<[f64; 3]>> = None;
    const WARMUP: usize = 20;
    let inputs = [("natural", false), ("shuffled", true)];
    for ((order, shuffled), renumbered) in inputs.into_iter().flat_map(|o| [(o, false), (o, true)])
    {
        let plate = Bt4Plate::new(elements, shuffled, renumbered);
        numberings.push(plate.locality(order, renumbered));
        for &t in threads {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(t).build()?;
            let mut sim = Bt4Explicit::new(&plate);
            let (rate, cpu_rate, plastic) = pool.install(|| {
                for _ in 0..WARMUP {
                    sim.step();
                }
                let alpha0 = sim.plastic();
                let (t0, c0) = (Instant::now(), process_cpu_seconds());
                for _ in 0..steps {
                    sim.step();
                }
                let secs = t0.elapsed().as_secs_f64();
                let cpu = process_cpu_seconds() - c0;
                let alpha = sim.plastic();
                let yielding = alpha.iter().zip(&alpha0).filter(|(a, b)| a > b).count();
                let updates = (sim.bt4.n_elements() * steps) as f64;
                (updates / secs, updates / cpu, yielding as f64 / alpha.len() as f64)
            });
            if !shuffled && !renumbered && rust_end.is_none() {
                rust_end = Some(sim.x.clone());
            }
            let s = &sim.bt4.settings;
            info.get_or_insert((
                sim.bt4.n_elements(),
                s.rule.len(),
                s.newton,
                sim.bt4.bytes_per_element(),
            ));
            runs.push(ExplicitRun {
                order,
                renumbered,
                threads: t,
                plastic_fraction: plastic,
                element_updates_per_s: rate,
                element_updates_per_s_per_core: rate / t as f64,
                ns_per_element_update: 1e9 / rate,
                element_updates_per_cpu_s: cpu_rate,
            });
        }
    }
    let (ne, np, newton, bytes) = info.expect("one run at least");
    let natural = Bt4Plate::new(elements, false, false);
    let c_reference = match c_reference(&natural, WARMUP, steps) {
        Ok((secs, cpu, x_c)) => {
            let rate = (ne * steps) as f64 / secs;
            let cpu_rate = (ne * steps) as f64 / cpu;
            let x_r = rust_end.expect("a natural run");
            let scale = x_r.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
            let diff = x_r
                .iter()
                .flatten()
                .zip(x_c.iter().flatten())
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            CReference {
                unavailable: None,
                element_updates_per_s: Some(rate),
                element_updates_per_cpu_s: Some(cpu_rate),
                rust_over_c: Some(runs[0].element_updates_per_s_per_core / rate),
                rust_over_c_cpu: Some(runs[0].element_updates_per_cpu_s / cpu_rate),
                position_difference: Some(diff / scale),
            }
        }
        Err(e) => CReference {
            unavailable: Some(format!("{e:#}")),
            element_updates_per_s: None,
            element_updates_per_cpu_s: None,
            rust_over_c: None,
            rust_over_c_cpu: None,
            position_difference: None,
        },
    };
    let find = |order: &str, renumbered: bool, t: usize| {
        runs.iter().find(|r| r.order == order && r.renumbered == renumbered && r.threads == t)
    };
    let rate = |order: &str, renumbered: bool, t: usize| {
        find(order, renumbered, t).map(|r| r.element_updates_per_s)
    };
    let speedup =
        |order: &str| rate(order, false, 1).zip(rate(order, false, 2)).map(|(a, b)| b / a);
    let t0 = threads[0];
    let ratio = |a: (&str, bool), b: (&str, bool)| match (find(a.0, a.1, t0), find(b.0, b.1, t0)) {
        (Some(a), Some(b)) => Ratio {
            wall: a.element_updates_per_s / b.element_updates_per_s,
            cpu: a.element_updates_per_cpu_s / b.element_updates_per_cpu_s,
        },
        _ => Ratio { wall: f64::NAN, cpu: f64::NAN },
    };
    let locality = LocalityBench {
        threads: t0,
        natural_over_shuffled_as_given: ratio(("natural", false), ("shuffled", false)),
        natural_over_shuffled_renumbered: ratio(("natural", true), ("shuffled", true)),
        renumbered_over_as_given_natural: ratio(("natural", true), ("natural", false)),
        renumbered_over_as_given_shuffled: ratio(("shuffled", true), ("shuffled", false)),
        numberings,
    };
    Ok(ExplicitBench {
        elements: ne,
        steps,
        thickness_points: np,
        newton_updates: newton,
        lanes: LANES,
        simd_path: SimdPath::detected().name(),
        bytes_per_element: bytes,
        element_updates_per_s_per_core: runs[0].element_updates_per_s_per_core,
        plastic_fraction: runs[0].plastic_fraction,
        speedup_2_threads_natural: speedup("natural"),
        speedup_2_threads_shuffled: speedup("shuffled"),
        locality,
        runs,
        c_reference,
    })
}

/// Processor time of this process (user + system, all threads) from `/proc/self/stat`, in
/// seconds (ticks of 1/100 s); 0 where there is no `/proc`.
fn process_cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else {
        return 0.0;
    };
    // Fields after the command name (which may hold spaces) start at the state, field 3.
    let rest = stat.rsplit_once(')').map_or("", |(_, r)| r);
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| f.get(i).and_then(|v| v.parse::<f64>().ok()).unwrap_or(0.0);
    // utime and stime are fields 14 and 15: 11 and 12 after the state.
    (ticks(11) + ticks(12)) / 100.0
}

/// Times Newmark steps of a clamped `n x n` MITC4 plate under a suddenly applied pressure.
pub fn implicit(n: usize, steps: usize) -> anyhow::Result<ImplicitBench> {
    let mesh = rectangle(1.0, 1.0, n, n);
    let section = ShellSection { e: 200e9, nu: 0.3, rho: 7800.0, h: 0.01 };
    let mut model = FeModel::new(&mesh, |_| Part::Shell(section))?;
    let edge = mesh.nodes_where(|p| p[0] == 0.0 || p[0] == 1.0 || p[1] == 0.0 || p[1] == 1.0);
    model.fix(&edge, [true; 6]);
    let cells: Vec<usize> = (0..mesh.cells.len()).collect();
    model.pressure(&cells, 1e5, Curve::Constant);
    let nodes = mesh.nodes.len();
    let mut im =
        Implicit::new(&mut model, ImplicitScheme::Newmark, 0.0, vec![0.0; 6 * nodes], None);
    im.params.tol = 1e-6;
    let t0 = Instant::now();
    let mut its = 0;
    for _ in 0..steps {
        its += im.step(&mut model, 1e-4, None)?.iterations.max(1);
    }
    let secs = t0.elapsed().as_secs_f64();
    let pieces = pieces(&mut model)?;
    Ok(ImplicitBench {
        nodes,
        dofs: 6 * nodes,
        steps,
        newton_iterations: its,
        seconds_per_step: secs / steps as f64,
        seconds_per_newton_iteration: secs / its as f64,
        pieces,
    })
}

/// Runs both benches; `quick` shrinks them (tests).
pub fn run(quick: bool, elements: usize, threads: &[usize]) -> anyhow::Result<BenchReport> {
    let explicit =
        if quick { explicit(400, 5, threads)? } else { explicit(elements, 100, threads)? };
    let blt3 = if quick {
        crate::bench_blt3::run(400, 5, threads)?
    } else {
        crate::bench_blt3::run(elements, 100, threads)?
    };
    let implicit = if quick { implicit(10, 2)? } else { implicit(100, 3)? };
    Ok(BenchReport {
        explicit_bt4: explicit,
        explicit_blt3: blt3,
        implicit_newmark: Some(implicit),
        implicit_factor_reuse: crate::bench_implicit::run(quick)?,
    })
}
