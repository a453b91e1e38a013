//! Static equilibrium of a `Model`: load-stepped Newton-Raphson with a sparse solve on the
//! free dofs (`linsolve`: GMRES preconditioned with an `LDLᵀ` factor kept across iterations
//! and steps while it converges fast, refactored otherwise) and step cutting, displacement control (Batoz & Dhatt 1979)
//! and cylindrical arc length (Crisfield 1981) for paths with limit points in load.
//! Pseudo-time `t` is the load factor.

use faer::Mat;

use crate::linsolve::{FreeDofs, FreeSolver, SolveStats};
use crate::model::Model;

/// How far above the tolerance a residual that has stopped falling is accepted as round-off.
const STALL_FACTOR: f64 = 100.0;

/// Newton settings.
#[derive(Debug, Clone, Copy)]
pub struct NewtonSettings {
    /// Relative residual tolerance: `|r_free|∞ <= tol · max(|f_ext|∞, |f_int|∞)`; the floor
    /// set by round-off in the internal forces of thin shells is about 1e-8.
    pub tol: f64,
    /// Iterations per step before the step is cut.
    pub max_iter: usize,
    /// Halvings of a step before giving up.
    pub max_cuts: usize,
}

impl Default for NewtonSettings {
    fn default() -> Self {
        NewtonSettings { tol: 1e-6, max_iter: 30, max_cuts: 8 }
    }
}

/// A converged state.
#[derive(Debug, Clone, Copy)]
pub struct Converged {
    /// Load factor (pseudo-time).
    pub t: f64,
    /// Newton iterations of the last (sub)step.
    pub iterations: usize,
    /// Final relative residual.
    pub residual: f64,
    /// Factorisations of the tangent in the last (sub)step (0: its solves all reused an
    /// earlier factor).
    pub factorisations: usize,
    /// GMRES iterations (preconditioner applications) of the last (sub)step's solves.
    pub gmres_iterations: usize,
}

impl Converged {
    fn new(t: f64, iterations: usize, residual: f64, work: SolveStats) -> Self {
        Converged {
            t,
            iterations,
            residual,
            factorisations: work.factorisations,
            gmres_iterations: work.gmres_iterations,
        }
    }
}

#[derive(Debug, thiserror::Error)]
pub enum StaticsError {
    #[error("no convergence from t = {from} to t = {to} after {cuts} step cuts (relative residual {residual:.3e})")]
    NoConvergence { from: f64, to: f64, cuts: usize, residual: f64 },
    #[error("singular tangent: {0}")]
    Singular(String),
    #[error("control dof {0} is constrained or out of range")]
    BadControl(usize),
    #[error("the model has explicit-only parts (BT4 shells) without a tangent: a static solve needs MITC4/DKT shells")]
    NoTangent,
}

/// Solves the model's tangent at `t` on the free dofs for the full vectors `rhs` (one column
/// each), the solutions in free numbering.
fn solve_tangent<const C: usize>(
    model: &mut dyn Model,
    t: f64,
    solver: &mut FreeSolver,
    rhs: [&[f64]; C],
) -> Result<[Vec<f64>; C], StaticsError> {
    let mut trip = crate::model::Tangent::default();
    model.tangent(t, &mut trip);
    let singular = |e: crate::linsolve::FactorError| StaticsError::Singular(e.0);
    solver.assemble(&trip, 1.0, None).map_err(singular)?;
    let fd = &solver.free;
    let mut m = Mat::zeros(fd.len(), rhs.len());
    for (c, v) in rhs.iter().enumerate() {
        for d in 0..v.len() {
            if let Some(i) = fd.index(d) {
                m[(i, c)] = v[d];
            }
        }
    }
    solver.solve_in_place(m.as_mut()).map_err(singular)?;
    Ok(std::array::from_fn(|c| (0..m.nrows()).map(|i| m[(i, c)]).collect()))
}

/// Residual `f_ext - f_int` at `t` (returned: its max norm on the free dofs) and the
/// reference magnitude `max(|f_ext|∞, |f_int|∞)` over all dofs (reactions included).
fn residual(model: &mut dyn Model, t: f64, fd: &FreeDofs, r: &mut [f64]) -> (f64, f64) {
    let n = r.len();
    let mut fi = vec![0.0; n];
    model.internal_force(&mut fi);
    model.external_force(t, r);
    let (mut rn, mut en, mut inn) = (0.0f64, 0.0f64, 0.0f64);
    for d in 0..n {
        en = en.max(r[d].abs());
        inn = inn.max(fi[d].abs());
        r[d] -= fi[d];
        if fd.index(d).is_some() {
            rn = rn.max(r[d].abs());
        }
    }
    (rn, en.max(inn).max(1e-300))
}

/// Load-stepped Newton: advances from the model's committed state through the load factors
/// `targets` (increasing), calling `on_step` after each converged target. Each step starts
/// from the last converged state (a secant predictor built from summed spins made Newton
/// slower in large rotations); a step that fails is halved, up to `max_cuts` times.
pub fn load_steps(
    model: &mut dyn Model,
    targets: &[f64],
    s: &NewtonSettings,
    mut on_step: impl FnMut(&mut dyn Model, Converged),
) -> Result<Vec<Converged>, StaticsError> {
    if !model.has_tangent() {
        return Err(StaticsError::NoTangent);
    }
    let mut solver = FreeSolver::new(model);
    let n = model.n_dof();
    let mut applied = vec![0.0; n];
    let mut t_now = 0.0;
    let mut out = Vec::new();
    for &target in targets {
        let mut h = target - t_now;
        let mut cuts = 0;
        let eps = 1e-14 * target.abs().max(1.0);
        while t_now < target - eps {
            let t = (t_now + h).min(target);
            match newton(model, t, &mut solver, &mut applied, s) {
                Ok(c) => {
                    model.commit();
                    t_now = t;
                    if t >= target - eps {
                        out.push(c);
                        on_step(&mut *model, c);
                    }
                }
                Err(res) => {
                    model.revert();
                    cuts += 1;
                    if cuts > s.max_cuts {
                        return Err(StaticsError::NoConvergence {
                            from: t_now,
                            to: target,
                            cuts,
                            residual: res,
                        });
                    }
                    h *= 0.5;
                }
            }
        }
    }
    Ok(out)
}

/// Newton iterations at load factor `t`; `applied` tracks the constrained dofs' totals
/// (restored on failure). Returns the relative residual on failure.
fn newton(
    model: &mut dyn Model,
    t: f64,
    solver: &mut FreeSolver,
    applied: &mut [f64],
    s: &NewtonSettings,
) -> Result<Converged, f64> {
    solver.sync(model);
    let work = solver.stats();
    let n = applied.len();
    let saved = applied.to_vec();
    let mut presc = applied.to_vec();
    model.prescribed(t, &mut presc);
    let mut du = vec![0.0; n];
    let cons = model.constrained().to_vec();
    for d in 0..n {
        if cons[d] {
            du[d] = presc[d] - applied[d];
            applied[d] = presc[d];
        }
    }
    model.apply_increment(&du);
    let mut r = vec![0.0; n];
    let (mut last, mut prev) = (f64::INFINITY, f64::INFINITY);
    for it in 0..=s.max_iter {
        let (rn, scale) = residual(model, t, &solver.free, &mut r);
        last = rn / scale;
        if !last.is_finite() {
            break;
        }
        // A residual that no longer halves has reached the round-off floor of the forces
        // (small loads on stiff shells): accepted within `STALL_FACTOR` x the tolerance.
        let stalled = rn > 0.5 * prev && last <= STALL_FACTOR * s.tol;
        prev = rn;
        if last <= s.tol || stalled {
            return Ok(Converged::new(t, it, last, solver.stats().since(&work)));
        }
        if it == s.max_iter {
            break;
        }
        let Ok([step]) = solve_tangent(model, t, solver, [&r]) else { break };
        du.fill(0.0);
        solver.free.scatter_values(&step, &mut du);
        if du.iter().any(|v| !v.is_finite()) {
            break;
        }
        model.apply_increment(&du);
    }
    applied.copy_from_slice(&saved);
    Err(last)
}

/// Displacement control: the loads scale with the load factor `λ` (external force linear in
/// `t`, `f_ext(λ) = λ f_ext(1)` at the current configuration), and dof `control` is driven
/// through the values `targets`; returns the converged `λ` at each. Prescribed dofs must be
/// fixed (zero).
pub fn displacement_control(
    model: &mut dyn Model,
    control: usize,
    targets: &[f64],
    s: &NewtonSettings,
    mut on_step: impl FnMut(&mut dyn Model, Converged),
) -> Result<Vec<Converged>, StaticsError> {
    if !model.has_tangent() {
        return Err(StaticsError::NoTangent);
    }
    let mut solver = FreeSolver::new(model);
    let fd = solver.free.clone();
    let n = model.n_dof();
    let Some(c) = fd.index(control) else {
        return Err(StaticsError::BadControl(control));
    };
    let mut lambda = 0.0;
    let mut uc = 0.0;
    let mut out = Vec::new();
    let mut r = vec![0.0; n];
    let mut fref = vec![0.0; n];
    let mut du = vec![0.0; n];
    for &target in targets {
        let mut ok = false;
        let mut last = f64::INFINITY;
        let work = solver.stats();
        for it in 0..=s.max_iter {
            let (rn, scale) = residual(model, lambda, &fd, &mut r);
            last = rn / scale;
            if last <= s.tol && (uc - target).abs() <= 1e-12 * target.abs().max(1e-30) {
                let conv = Converged::new(lambda, it, last, solver.stats().since(&work));
                model.commit();
                out.push(conv);
                on_step(&mut *model, conv);
                ok = true;
                break;
            }
            if it == s.max_iter || !last.is_finite() {
                break;
            }
            model.external_force(1.0, &mut fref);
            let [a, b] = solve_tangent(model, lambda, &mut solver, [&r, &fref])?;
            let dl = (target - uc - a[c]) / b[c];
            let step: Vec<f64> = a.iter().zip(&b).map(|(a, b)| a + dl * b).collect();
            du.fill(0.0);
            fd.scatter_values(&step, &mut du);
            model.apply_increment(&du);
            lambda += dl;
            uc += du[control];
        }
        if !ok {
            return Err(StaticsError::NoConvergence {
                from: uc,
                to: target,
                cuts: 0,
                residual: last,
            });
        }
    }
    Ok(out)
}

/// Settings of the arc-length path following.
#[derive(Debug, Clone, Copy)]
pub struct ArcLengthSettings {
    /// Residual tolerance and iterations per step; `max_cuts` halvings of the arc length of a
    /// step that fails.
    pub newton: NewtonSettings,
    /// Arc length of the first step: the norm of the free-dof increment of a step.
    pub initial: f64,
    /// Bounds of the arc length.
    pub min: f64,
    pub max: f64,
    /// The arc length of the next step is scaled by `√(desired / used)` iterations (Crisfield
    /// 1991, §9.5), within `[min, max]`.
    pub desired_iterations: usize,
    /// Steps taken at most.
    pub max_steps: usize,
    /// Load factor of the model's committed state (0 from the unloaded state; the last `t`
    /// of a `load_steps` run to continue from it).
    pub start: f64,
}

/// Cylindrical arc length (Crisfield 1981, Comput. Struct. 13:55; *Non-linear Finite Element
/// Analysis of Solids and Structures* 1991, §9.3): load factor `λ` and displacements advance
/// together with `|Δu|₂ = Δl` on the free dofs, the load scaling as in
/// [`displacement_control`] (`f_ext(λ)` linear in `t`; prescribed dofs fixed). The predictor
/// is the tangent solution `δu_t = K⁻¹ f_ext(1)` with the sign of its product with the previous
/// step's increment (it turns at limit points, where `det K` changes sign); each corrector
/// solves `K δu_r = r`, `K δu_t = f_ext(1)` and the constraint's quadratic for `δλ`, taking the
/// root whose increment makes the smaller angle with the step's increment so far. A step that
/// fails (no real root, no convergence) is retried with half the arc length. `on_step` sees each
/// converged state (its `t` is `λ`) and returns `false` to stop.
pub fn arc_length(
    model: &mut dyn Model,
    s: &ArcLengthSettings,
    mut on_step: impl FnMut(&mut dyn Model, Converged) -> bool,
) -> Result<Vec<Converged>, StaticsError> {
    if !model.has_tangent() {
        return Err(StaticsError::NoTangent);
    }
    let mut solver = FreeSolver::new(model);
    let mut lambda = s.start;
    let mut dl = s.initial;
    let mut previous: Option<Vec<f64>> = None;
    let mut out = Vec::new();
    for _ in 0..s.max_steps {
        let mut cuts = 0;
        let (c, inc) = loop {
            match arc_step(model, &mut solver, lambda, dl, previous.as_deref(), &s.newton) {
                Ok(done) => break done,
                Err(res) => {
                    model.revert();
                    cuts += 1;
                    if cuts > s.newton.max_cuts || dl * 0.5 < s.min {
                        return Err(StaticsError::NoConvergence {
                            from: lambda,
                            to: lambda,
                            cuts,
                            residual: res,
                        });
                    }
                    dl *= 0.5;
                }
            }
        };
        model.commit();
        lambda = c.t;
        previous = Some(inc);
        out.push(c);
        if !on_step(&mut *model, c) {
            break;
        }
        let ratio = s.desired_iterations.max(1) as f64 / c.iterations.max(1) as f64;
        dl = (dl * ratio.sqrt()).clamp(s.min, s.max);
    }
    Ok(out)
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// One arc-length step of length `dl` from the committed state at `lambda`; returns the
/// converged state and the step's free-dof increment, or the relative residual on failure.
fn arc_step(
    model: &mut dyn Model,
    solver: &mut FreeSolver,
    lambda: f64,
    dl: f64,
    previous: Option<&[f64]>,
    s: &NewtonSettings,
) -> Result<(Converged, Vec<f64>), f64> {
    solver.sync(model);
    let work = solver.stats();
    let n = model.n_dof();
    let fd = solver.free.clone();
    let (mut r, mut fref, mut du) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    // predictor
    model.external_force(1.0, &mut fref);
    let [ut] = solve_tangent(model, lambda, solver, [&fref]).map_err(|_| f64::INFINITY)?;
    let norm = dot(&ut, &ut).sqrt();
    if !(norm.is_finite() && norm > 0.0) {
        return Err(f64::INFINITY);
    }
    let sign = match previous {
        Some(p) if dot(p, &ut) < 0.0 => -1.0,
        _ => 1.0,
    };
    let mut dlam = sign * dl / norm;
    let mut inc: Vec<f64> = ut.iter().map(|v| dlam * v).collect();
    fd.scatter_values(&inc, &mut du);
    model.apply_increment(&du);
    let mut last = f64::INFINITY;
    for it in 0..=s.max_iter {
        let (rn, scale) = residual(model, lambda + dlam, &fd, &mut r);
        last = rn / scale;
        if !last.is_finite() {
            break;
        }
        if last <= s.tol {
            let work = solver.stats().since(&work);
            return Ok((Converged::new(lambda + dlam, it, last, work), inc));
        }
        if it == s.max_iter {
            break;
        }
        model.external_force(1.0, &mut fref);
        let Ok([ur, ut]) = solve_tangent(model, lambda + dlam, solver, [&r, &fref]) else {
            break;
        };
        // |inc + ur + δλ ut|² = dl²
        let w: Vec<f64> = inc.iter().zip(&ur).map(|(x, y)| x + y).collect();
        let (qa, qb, qc) = (dot(&ut, &ut), 2.0 * dot(&ut, &w), dot(&w, &w) - dl * dl);
        let disc = qb * qb - 4.0 * qa * qc;
        if !(disc >= 0.0 && qa > 0.0) {
            break;
        }
        let q = -0.5 * (qb + qb.signum() * disc.sqrt());
        let roots = [q / qa, if q != 0.0 { qc / q } else { q / qa }];
        let angle = |d: f64| dot(&inc, &w) + d * dot(&inc, &ut);
        let dlm = if angle(roots[0]) >= angle(roots[1]) { roots[0] } else { roots[1] };
        let step: Vec<f64> = w.iter().zip(&ut).map(|(w, t)| w + dlm * t).collect();
        du.fill(0.0);
        let delta: Vec<f64> = step.iter().zip(&inc).map(|(s, i)| s - i).collect();
        fd.scatter_values(&delta, &mut du);
        if du.iter().any(|v| !v.is_finite()) {
            break;
        }
        model.apply_increment(&du);
        inc = step;
        dlam += dlm;
    }
    Err(last)
}
