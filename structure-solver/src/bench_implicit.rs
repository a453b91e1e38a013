//! `structure-solver bench`, the implicit row: Newmark steps of the clamped 100 x 100 MITC4
//! plate (10,201 nodes, 61,206 dofs, 59,196 free) under a suddenly applied pressure, on one
//! and on two rayon threads, with the factor reused as the GMRES preconditioner
//! (`linsolve::FreeSolver`) and, on two threads, refactored at every Newton iteration for
//! comparison: seconds per Newton iteration, factorisations and GMRES iterations (DESIGN §6).

use std::time::Instant;

use serde::Serialize;

use crate::assembly::{Curve, FeModel, Part};
use crate::elements::ShellSection;
use crate::linsolve::FreeSolver;
use crate::mesh::generate::rectangle;
use crate::model::Model;
use crate::time::{Implicit, ImplicitScheme};

/// Step of the bench: 1/20 of the plate's first period (≈ 2 ms), so the response is dynamic
/// and the steps differ.
const DT: f64 = 1e-4;

/// The implicit row of the bench.
#[derive(Debug, Serialize)]
pub struct ImplicitReuseBench {
    pub nodes: usize,
    pub dofs: usize,
    pub dt: f64,
    /// Newton tolerance (relative residual).
    pub newton_tol: f64,
    pub runs: Vec<ImplicitRun>,
    /// Largest difference of the final displacements between the runs, relative to the
    /// largest displacement.
    pub max_relative_difference: f64,
}

/// Timed steps on `threads` threads; `reuse`: the kept factor preconditions later solves.
#[derive(Debug, Serialize)]
pub struct ImplicitRun {
    pub threads: usize,
    pub reuse: bool,
    /// Seconds of the first step (the pattern, ordering and symbolic analysis included),
    /// not in the figures below.
    pub seconds_first_step: f64,
    pub steps: usize,
    pub newton_iterations: usize,
    pub factorisations: usize,
    pub gmres_iterations: usize,
    /// Newton iterations whose solve took the Jacobian's products from differences of the
    /// residual instead of assembling it.
    pub matrix_free_solves: usize,
    pub seconds_per_step: f64,
    pub seconds_per_newton_iteration: f64,
    /// Processor time of the process (all threads) per Newton iteration: on a machine shared
    /// with other work, the single-thread figure bounds the wall time an idle machine gives.
    pub cpu_seconds_per_newton_iteration: f64,
    /// Largest displacement magnitude at the end.
    pub max_displacement: f64,
    /// One Newton iteration's linear-algebra pieces at the final configuration.
    pub pieces: Pieces,
}

/// Seconds of the pieces of a Newton iteration (best of two), at the final configuration.
#[derive(Debug, Serialize)]
pub struct Pieces {
    /// `Model::tangent`: the element blocks.
    pub tangent: f64,
    /// The blocks into the matrix through the scatter map (`FreeSolver::assemble`).
    pub assemble: f64,
    /// A fresh `LDLᵀ` of the symmetric part (`FreeSolver::factor`).
    pub factorisation: f64,
    /// A solve of the internal force vector preconditioned with the factor of this matrix,
    /// and its GMRES iterations.
    pub solve: f64,
    pub solve_gmres_iterations: usize,
}

/// The clamped `n x n` MITC4 steel plate, 1 m square and 10 mm thick, under 1e5 Pa.
fn plate(n: usize) -> anyhow::Result<FeModel> {
    let mesh = rectangle(1.0, 1.0, n, n);
    let section = ShellSection { e: 200e9, nu: 0.3, rho: 7800.0, h: 0.01 };
    let mut model = FeModel::new(&mesh, |_| Part::Shell(section))?;
    let edge = mesh.nodes_where(|p| p[0] == 0.0 || p[0] == 1.0 || p[1] == 0.0 || p[1] == 1.0);
    model.fix(&edge, [true; 6]);
    let cells: Vec<usize> = (0..mesh.cells.len()).collect();
    model.pressure(&cells, 1e5, Curve::Constant);
    Ok(model)
}

/// Processor seconds of this process so far (`/proc/self/stat` utime + stime, in the
/// kernel's fixed 100 Hz `USER_HZ`); 0 where that file is missing.
fn cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else { return 0.0 };
    // fields after the parenthesised command name; utime and stime are fields 14 and 15
    let rest = stat.rsplit_once(')').map_or("", |(_, r)| r);
    let f: Vec<f64> =
        rest.split_whitespace().skip(11).take(2).filter_map(|v| v.parse().ok()).collect();
    f.iter().sum::<f64>() / 100.0
}

/// Best of two timings of `f`.
fn best_of_two(mut f: impl FnMut() -> anyhow::Result<()>) -> anyhow::Result<f64> {
    let mut best = f64::INFINITY;
    for _ in 0..2 {
        let t = Instant::now();
        f()?;
        best = best.min(t.elapsed().as_secs_f64());
    }
    Ok(best)
}

/// Times the pieces of a Newton iteration of `model` at its configuration (Newmark's
/// Jacobian `K + 4/Δt² M`).
fn pieces(model: &mut FeModel) -> anyhow::Result<Pieces> {
    let mass = model.lumped_mass().to_vec();
    let cm = 4.0 / (DT * DT);
    let mut trip = crate::model::Tangent::default();
    let tangent = best_of_two(|| {
        model.tangent(0.0, &mut trip);
        Ok(())
    })?;
    let mut solver = FreeSolver::new(model);
    solver.assemble(&trip, 1.0, Some((cm, &mass)))?; // the pattern and the map
    let assemble = best_of_two(|| Ok(solver.assemble(&trip, 1.0, Some((cm, &mass)))?))?;
    let factorisation =
        best_of_two(|| Ok(solver.factor(&trip, 1.0, Some((cm, &mass))).map(drop)?))?;
    let mut fi = vec![0.0; model.n_dof()];
    model.internal_force(&mut fi);
    // the factor of this matrix kept, then solves of it through the reuse path
    solver.assemble(&trip, 1.0, Some((cm, &mass)))?;
    solver.solve_in_place(solver.free.gather(&fi).as_mut())?;
    let mut b = solver.free.gather(&fi);
    let before = solver.stats();
    let solve = best_of_two(|| {
        b = solver.free.gather(&fi);
        Ok(solver.solve_in_place(b.as_mut())?)
    })?;
    let its = solver.stats().since(&before).gmres_iterations / 2;
    Ok(Pieces { tangent, assemble, factorisation, solve, solve_gmres_iterations: its })
}

/// One warm-up step and `steps` timed Newmark steps of `plate(n)` in a pool of `threads`.
fn run_one(
    n: usize,
    steps: usize,
    threads: usize,
    reuse: bool,
    tol: f64,
) -> anyhow::Result<(ImplicitRun, Vec<[f64; 3]>)> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build()?;
    pool.install(|| {
        let mut model = plate(n)?;
        let n_dof = model.n_dof();
        let mut im =
            Implicit::new(&mut model, ImplicitScheme::Newmark, 0.0, vec![0.0; n_dof], None);
        im.params.tol = tol;
        im.set_factor_reuse(reuse);
        let t0 = Instant::now();
        im.step(&mut model, DT, None)?;
        let first = t0.elapsed().as_secs_f64();
        let (mut its, mut fact, mut gmres, mut free) = (0, 0, 0, 0);
        let cpu0 = cpu_seconds();
        let t0 = Instant::now();
        for _ in 0..steps {
            let info = im.step(&mut model, DT, None)?;
            its += info.iterations;
            fact += info.factorisations;
            gmres += info.gmres_iterations;
            free += info.matrix_free_solves;
        }
        let secs = t0.elapsed().as_secs_f64();
        let cpu = cpu_seconds() - cpu0;
        let mut u = vec![[0.0; 3]; model.n_nodes()];
        model.displacement(&mut u);
        let umax =
            u.iter().map(|p| p.iter().map(|x| x * x).sum::<f64>().sqrt()).fold(0.0, f64::max);
        let run = ImplicitRun {
            threads,
            reuse,
            seconds_first_step: first,
            steps,
            newton_iterations: its,
            factorisations: fact,
            gmres_iterations: gmres,
            matrix_free_solves: free,
            seconds_per_step: secs / steps as f64,
            seconds_per_newton_iteration: secs / its.max(1) as f64,
            cpu_seconds_per_newton_iteration: cpu / its.max(1) as f64,
            max_displacement: umax,
            pieces: pieces(&mut model)?,
        };
        Ok((run, u))
    })
}

/// The row: reuse on 1 and 2 threads, refactoring every iteration on 2; `quick` shrinks the
/// plate (a smoke test, not a measurement).
pub fn run(quick: bool) -> anyhow::Result<ImplicitReuseBench> {
    let (n, steps) = if quick { (10, 2) } else { (100, 5) };
    let tol = 1e-8;
    let mut runs = Vec::new();
    let mut displacements = Vec::new();
    for (threads, reuse) in [(1, true), (2, true), (2, false)] {
        let (r, u) = run_one(n, steps, threads, reuse, tol)?;
        runs.push(r);
        displacements.push(u);
    }
    let umax = runs.iter().map(|r| r.max_displacement).fold(0.0, f64::max).max(1e-300);
    let diff = displacements[1..]
        .iter()
        .flat_map(|u| u.iter().zip(&displacements[0]))
        .flat_map(|(a, b)| (0..3).map(move |k| (a[k] - b[k]).abs()))
        .fold(0.0, f64::max);
    Ok(ImplicitReuseBench {
        nodes: (n + 1) * (n + 1),
        dofs: 6 * (n + 1) * (n + 1),
        dt: DT,
        newton_tol: tol,
        runs,
        max_relative_difference: diff / umax,
    })
}
