//! `structure-solver bench`: the speed of the explicit BT4 kernel (element updates per second
//! on one core, J2 with the plane-stress return at 5 thickness points) and of an implicit
//! Newmark step of a 10k-node MITC4 shell with the time of each piece of a Newton iteration
//! (internal force, tangent, factorisation, solve), printed as JSON (DESIGN §6, §7).

use std::time::Instant;

use serde::Serialize;

use crate::assembly::{Curve, FeModel, Part};
use crate::elements::bt4::{Bt4, Bt4Settings, LANES};
use crate::elements::ShellSection;
use crate::material::{Elastic, J2};
use crate::mesh::generate::rectangle;
use crate::time::{Implicit, ImplicitScheme};

/// Bench results.
#[derive(Debug, Serialize)]
pub struct BenchReport {
    pub explicit_bt4: ExplicitBench,
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
    /// Share of thickness points yielding in the timed steps.
    pub plastic_fraction: f64,
    pub element_updates_per_s_per_core: f64,
    pub ns_per_element_update: f64,
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
    /// Triplets of the assembled tangent (before summing duplicates).
    pub tangent_triplets: usize,
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
    let mut triplets = Vec::new();
    let tangent_assembly = best(&mut || model.tangent(0.0, &mut triplets));
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
    let lu = solver.factor(&triplets, 1.0, Some((1e8, &mass)))?;
    let mut result = Ok(());
    let factorisation = best(&mut || {
        if let Err(e) = solver.factor(&triplets, 1.0, Some((1e8, &mass))) {
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
        tangent_triplets: triplets.len(),
    })
}

fn steel() -> J2 {
    J2 { elastic: Elastic { e: 200e9, nu: 0.3, rho: 7800.0 }, sigma_y: 250e6, h: 1e9 }
}

/// Times the BT4 kernel alone on a `n x n` plate stretched and bent past yield at every step.
pub fn explicit(n: usize, steps: usize) -> ExplicitBench {
    let mesh = rectangle(1.0, 1.0, n, n);
    let conn: Vec<[u32; 4]> = mesh
        .cells
        .iter()
        .map(|c| [c.nodes[0], c.nodes[1], c.nodes[2], c.nodes[3]].map(|v| v as u32))
        .collect();
    let ne = conn.len();
    let settings = Bt4Settings::default();
    let (np, newton) = (settings.rule.len(), settings.newton);
    let mut bt4 = Bt4::new(conn, vec![0.01; ne], steel(), settings);
    let mut x: Vec<[f64; 3]> = mesh.nodes.clone();
    let mut du = vec![0.0; 6 * x.len()];
    let mut f = vec![0.0; 6 * x.len()];
    // Biaxial stretch 2e-4 per step and a curvature increment: every point yields after a few
    // steps and keeps yielding.
    let mut step = |bt4: &mut Bt4, x: &mut Vec<[f64; 3]>| {
        for (i, p) in x.iter_mut().enumerate() {
            let (dx, dy) = (2e-4 * p[0], -0.5e-4 * p[1]);
            p[0] += dx;
            p[1] += dy;
            du[6 * i] = dx;
            du[6 * i + 1] = dy;
            du[6 * i + 4] = 0.05 * p[0] * 1e-3;
        }
        f.fill(0.0);
        bt4.internal_force(x, &du, &mut f);
        bt4.commit();
    };
    for _ in 0..20 {
        step(&mut bt4, &mut x);
    }
    let alpha0: Vec<f64> = (0..ne)
        .flat_map(|e| (0..np).map(move |p| (e, p)))
        .map(|(e, p)| bt4.plastic_strain(e, p))
        .collect();
    let t0 = Instant::now();
    for _ in 0..steps {
        step(&mut bt4, &mut x);
    }
    let secs = t0.elapsed().as_secs_f64();
    let mut plastic = 0usize;
    for e in 0..ne {
        for p in 0..np {
            if bt4.plastic_strain(e, p) > alpha0[e * np + p] {
                plastic += 1;
            }
        }
    }
    let updates = (ne * steps) as f64;
    ExplicitBench {
        elements: ne,
        steps,
        thickness_points: np,
        newton_updates: newton,
        lanes: LANES,
        plastic_fraction: plastic as f64 / (ne * np) as f64,
        element_updates_per_s_per_core: updates / secs,
        ns_per_element_update: 1e9 * secs / updates,
    }
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
pub fn run(quick: bool) -> anyhow::Result<BenchReport> {
    let (n, steps) = if quick { (20, 5) } else { (100, 200) };
    let explicit = explicit(n, steps);
    let implicit = if quick { implicit(10, 2)? } else { implicit(100, 3)? };
    Ok(BenchReport {
        explicit_bt4: explicit,
        implicit_newmark: Some(implicit),
        implicit_factor_reuse: crate::bench_implicit::run(quick)?,
    })
}
