//! Implicit steps with Newton and a sparse solve on the free dofs (`linsolve`: GMRES
//! preconditioned with an `LDLᵀ` factor kept across Newton iterations and steps while it
//! converges within `REUSE_ITERATIONS`, refactored otherwise; each solve only as accurate as
//! Newton's convergence needs, `linsolve::forcing`; a solve that need not go below
//! `MATRIX_FREE_TOL` takes the Jacobian's products from differences of the residual instead
//! of assembling it, `Difference`):
//!
//! - **Newmark, average acceleration** (β = 1/4, γ = 1/2; Newmark 1959): unknown `Δu`,
//!   `a^{n+1} = 4/Δt² (Δu - Δt v^n) - a^n`, `v^{n+1} = v^n + Δt/2 (a^n + a^{n+1})`, residual
//!   `M a^{n+1} + f_int(u^n + Δu) - f_ext^{n+1}`, Jacobian `4/Δt² M + K`.
//! - **Implicit midpoint** (Simo & Tarnow 1992 for its energy behaviour): `v^{n+1} = 2Δu/Δt - v^n`,
//!   residual `M (v^{n+1} - v^n)/Δt + f_int(u^n + Δu/2) - f_ext^{n+1/2}`, Jacobian
//!   `2/Δt² M + ½ K` evaluated at the midpoint. It conserves the energy of linear problems to the
//!   Newton tolerance; the A6 coupling feeds the fluid load `F^{n+1/2}` as `extra`.
//!
//! Both have the discrete frequency `tan(ΩΔt/2) = ωΔt/2` on a linear oscillator.
//!
//! The mass is the model's full mass (`Model::mass_product`, `Model::nondiagonal_mass`: the
//! 6x6 blocks of rigid masters in the current orientation); rotations are treated as in the
//! rest of the model (summed spins), so gyroscopic terms of rigid bodies are not integrated
//! here (central differences integrate them). Rigid slaves follow their masters
//! (`Model::dependent_motion`).

use faer::sparse::Triplet;

use super::{out_of_balance, prescribed_increment, Dynamics};
use crate::linsolve::{forcing, FreeSolver, SolveStats, MATRIX_FREE_TOL, SOLVE_TOL};
use crate::model::{Model, Tangent};

/// Which implicit rule.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImplicitScheme {
    Newmark,
    Midpoint,
}

/// Newton settings of an implicit step.
#[derive(Debug, Clone, Copy)]
pub struct NewtonParams {
    /// Relative tolerance on the free-dof residual: `|r|₂ <= tol · max(|M a|, |f_int|, |f_ext|)`
    /// (max norms), or a residual that has stopped falling within 100 `tol` (the round-off floor).
    pub tol: f64,
    /// Absolute floor of the residual norm (forces), for states at rest.
    pub abs_tol: f64,
    pub max_iter: usize,
    /// Each linear solve goes only as far as Newton's convergence needs (`linsolve::forcing`),
    /// and while the kept factor preconditions well the Jacobian is not assembled: GMRES takes
    /// its products from a difference of residuals (`Difference`). `false`: every solve to
    /// `SOLVE_TOL` on the assembled Jacobian, so that runs whose matrices differ in round-off
    /// (another dof numbering, added dofs) follow the same Newton iterates to round-off.
    pub inexact: bool,
}

/// How far above the tolerance a residual that has stopped falling is accepted as round-off.
const STALL_FACTOR: f64 = 100.0;

impl Default for NewtonParams {
    fn default() -> Self {
        NewtonParams { tol: 1e-10, abs_tol: 1e-12, max_iter: 25, inexact: true }
    }
}

/// Iterations, final residual and linear-solver work of a converged step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepInfo {
    pub iterations: usize,
    pub residual: f64,
    /// Factorisations of the Jacobian in this step (0: all solves reused an earlier factor).
    pub factorisations: usize,
    /// GMRES iterations (preconditioner applications) of this step's solves.
    pub gmres_iterations: usize,
    /// Solves of this step without an assembled Jacobian (`Difference`).
    pub matrix_free_solves: usize,
}

#[derive(Debug, thiserror::Error)]
pub enum ImplicitError {
    #[error("Newton did not converge in {iterations} iterations from t = {t} (residual {residual:.3e}, reference {reference:.3e})")]
    NoConvergence { t: f64, iterations: usize, residual: f64, reference: f64 },
    #[error("the effective matrix is singular: {0}")]
    Singular(String),
    #[error("the model has explicit-only parts (BT4 shells) without a tangent: implicit steps need MITC4/DKT shells; use central differences")]
    NoTangent,
}

/// An implicit integrator with its free-dof numbering and work arrays.
#[derive(Debug, Clone)]
pub struct Implicit {
    pub scheme: ImplicitScheme,
    pub state: Dynamics,
    pub params: NewtonParams,
    /// Boxed: its kept factor and LU fallback make it large.
    solver: Box<FreeSolver>,
    fi: Vec<f64>,
    r: Vec<f64>,
    du: Vec<f64>,
    delta: Vec<f64>,
    scratch: Vec<f64>,
    /// Acceleration implied by `Δu` and the inertia force `M` times it.
    acc: Vec<f64>,
    inertia: Vec<f64>,
    /// Boxed: five arrays.
    tangent: Box<Tangent>,
    mass_triplets: Vec<Triplet<usize, usize, f64>>,
    /// Boxed: six arrays.
    difference: Box<Difference>,
}

/// The Jacobian's product `J d` without the Jacobian (Jacobian-free Newton-Krylov, Knoll &
/// Keyes 2004, their forward difference): `J d = c_m M d + (g(u) - g(u + h s d)) / h` with
/// `g = f_ext - f_int` the out-of-balance force, `s` the stage at which forces are evaluated,
/// and `h` such that the translations of `h s d` reach `√ε (1 + |u|∞)` (`|u|∞` over
/// translations, a scale of the positions) and its rotations at most `∛ε`. The model holds
/// positions, not displacements, so a translation perturbed by less is only a few digits of a
/// position: in the GMRES vectors of the bench plate the rotations are 1e-3 times larger, and
/// a step of `√ε` on the largest entry left the products 1e-5 off; the rotation bound keeps
/// them at 1e-6 to 1e-7. Where translations lead, the step is `√ε` and the error near 1e-8
/// (test below). It costs one force evaluation where an assembled `J` costs the element
/// tangents and their sum; a solve that must go below `MATRIX_FREE_TOL` assembles.
#[derive(Debug, Clone, Default)]
struct Difference {
    /// `g(u)` at the iterate.
    base: Vec<f64>,
    /// The perturbation `h s d`, then its reverse.
    shift: Vec<f64>,
    fi: Vec<f64>,
    g: Vec<f64>,
    md: Vec<f64>,
    translations: Vec<[f64; 3]>,
    /// A product has moved the model since the flag was cleared.
    moved: bool,
}

impl Difference {
    fn resize(&mut self, n: usize) {
        for w in [&mut self.base, &mut self.shift, &mut self.fi, &mut self.g, &mut self.md] {
            w.resize(n, 0.0);
        }
        self.translations.resize(n / 6, [0.0; 3]);
    }

    /// `|u|∞` over the translations of `model`'s iterate.
    fn scale(&mut self, model: &dyn Model) -> f64 {
        model.displacement(&mut self.translations);
        self.translations.iter().flatten().fold(0.0, |m, x| m.max(x.abs()))
    }

    /// `out = J d` (above) at the iterate whose out-of-balance force is `self.base`; the model
    /// is moved there and back (its trial material state is then that of the perturbed point).
    fn product(
        &mut self,
        model: &mut dyn Model,
        (t, extra): (f64, Option<&[f64]>),
        (cm, stage, u_max): (f64, f64, f64),
        d: &[f64],
        out: &mut [f64],
    ) {
        let (mut d_t, mut d_r) = (0.0f64, 0.0f64);
        for (i, x) in d.iter().enumerate() {
            if i % 6 < 3 {
                d_t = d_t.max(x.abs());
            } else {
                d_r = d_r.max(x.abs());
            }
        }
        if d_t == 0.0 && d_r == 0.0 {
            out.fill(0.0);
            return;
        }
        let h = (f64::EPSILON.sqrt() * (1.0 + u_max) / d_t).min(f64::EPSILON.cbrt() / d_r) / stage;
        for (s, &di) in self.shift.iter_mut().zip(d) {
            *s = h * stage * di;
        }
        model.apply_increment(&self.shift);
        self.moved = true;
        out_of_balance(model, t, extra, &mut self.fi, &mut self.g);
        for s in &mut self.shift {
            *s = -*s;
        }
        model.apply_increment(&self.shift);
        model.mass_product(d, &mut self.md);
        for i in 0..out.len() {
            out[i] = cm * self.md[i] + (self.base[i] - self.g[i]) / h;
        }
    }
}

impl Implicit {
    /// Starts at `t0` with velocity `v0`; `a^0` from the out-of-balance force (with `extra`).
    pub fn new(
        model: &mut dyn Model,
        scheme: ImplicitScheme,
        t0: f64,
        v0: Vec<f64>,
        extra: Option<&[f64]>,
    ) -> Self {
        let n = model.n_dof();
        assert_eq!(v0.len(), n, "initial velocity has the wrong length");
        let mut s = Self::resume(model, scheme, Dynamics { t: t0, v: v0, a: vec![0.0; n] });
        out_of_balance(model, t0, extra, &mut s.fi, &mut s.r);
        model.apply_inverse_mass(&s.r, &mut s.state.a);
        model.dependent_motion(&mut s.state.v, &mut s.state.a);
        s
    }

    /// Resumes from a checkpointed state.
    pub fn resume(model: &dyn Model, scheme: ImplicitScheme, state: Dynamics) -> Self {
        let n = model.n_dof();
        Implicit {
            scheme,
            state,
            params: NewtonParams::default(),
            solver: Box::new(FreeSolver::new(model)),
            fi: vec![0.0; n],
            r: vec![0.0; n],
            du: vec![0.0; n],
            delta: vec![0.0; n],
            scratch: vec![0.0; n],
            acc: vec![0.0; n],
            inertia: vec![0.0; n],
            tangent: Box::default(),
            mass_triplets: Vec::new(),
            difference: {
                let mut d = Box::<Difference>::default();
                d.resize(n);
                d
            },
        }
    }

    /// Follows a change of `model`'s topology made after the last step, nodes appended
    /// whose velocity `state` holds already (`Dynamics::push_nodes`, `Dynamics::copy_nodes`):
    /// the work arrays grow to the model's dofs, the new dofs take the acceleration of the
    /// changed model at the current time (with `extra`; the others keep theirs) and the
    /// solver takes the new free-dof numbering.
    pub fn follow_topology(
        &mut self,
        model: &mut dyn Model,
        extra: Option<&[f64]>,
    ) -> Result<(), super::ResizeError> {
        let n = self.state.fits(model)?;
        let first = self.fi.len();
        for w in [
            &mut self.fi,
            &mut self.r,
            &mut self.du,
            &mut self.delta,
            &mut self.scratch,
            &mut self.acc,
            &mut self.inertia,
        ] {
            w.resize(n, 0.0);
        }
        self.difference.resize(n);
        let work = [&mut self.fi[..], &mut self.r[..], &mut self.scratch[..]];
        super::added_accelerations(model, (self.state.t, extra), first, work, &mut self.state.a);
        self.solver.sync(model);
        Ok(())
    }

    /// `false`: factor the Jacobian at every Newton iteration instead of reusing the last
    /// factor as the GMRES preconditioner (the reference the reuse is checked against).
    pub fn set_factor_reuse(&mut self, reuse: bool) {
        self.solver.set_reuse(reuse);
    }

    /// Drops the kept factor, so that the next step starts as a resumed integrator does: call
    /// it at each checkpoint to make a run restarted from there reproduce the run bit for bit.
    pub fn forget_factor(&mut self) {
        self.solver.forget_factor();
    }

    /// Factorisations and GMRES iterations since the integrator was made.
    pub fn solve_stats(&self) -> SolveStats {
        self.solver.stats()
    }

    /// Mass and stiffness factors of the Jacobian, and the stage at which forces are evaluated
    /// (fraction of `Δu` applied to the model, load time offset).
    fn coefficients(&self, dt: f64) -> (f64, f64, f64) {
        match self.scheme {
            ImplicitScheme::Newmark => (4.0 / (dt * dt), 1.0, 1.0),
            ImplicitScheme::Midpoint => (2.0 / (dt * dt), 0.5, 0.5),
        }
    }

    /// Inertia force `M · (acceleration implied by Δu)` into `self.inertia`.
    fn inertia(&mut self, model: &dyn Model, dt: f64) {
        for i in 0..self.acc.len() {
            let (v0, a0, du) = (self.state.v[i], self.state.a[i], self.du[i]);
            self.acc[i] = match self.scheme {
                ImplicitScheme::Newmark => 4.0 / (dt * dt) * (du - dt * v0) - a0,
                ImplicitScheme::Midpoint => 2.0 * (du / dt - v0) / dt,
            };
        }
        model.mass_product(&self.acc, &mut self.inertia);
    }

    /// Advances one step of `dt` with the extra load `extra` (held over the step; for the
    /// midpoint rule it is the load at `t + dt/2`). On failure the model is reverted.
    pub fn step(
        &mut self,
        model: &mut dyn Model,
        dt: f64,
        extra: Option<&[f64]>,
    ) -> Result<StepInfo, ImplicitError> {
        if !model.has_tangent() {
            return Err(ImplicitError::NoTangent);
        }
        self.solver.sync(model);
        let work = self.solver.stats();
        let n = model.n_dof();
        let t0 = self.state.t;
        let (cm, ck, stage) = self.coefficients(dt);
        let t_load = t0 + stage * dt;
        // Predictor: constant acceleration; prescribed dofs follow their history.
        prescribed_increment(model, t0, dt, &mut self.scratch, &mut self.du);
        let constrained = model.constrained().to_vec();
        for i in 0..n {
            if !constrained[i] {
                self.du[i] = dt * self.state.v[i] + 0.5 * dt * dt * self.state.a[i];
            }
        }
        for i in 0..n {
            self.delta[i] = stage * self.du[i];
        }
        model.apply_increment(&self.delta);
        let mass = model.lumped_mass().to_vec();
        let mut last = (f64::INFINITY, 0.0);
        for it in 0..=self.params.max_iter {
            out_of_balance(model, t_load, extra, &mut self.fi, &mut self.r);
            self.inertia(model, dt);
            let (mut rn, mut reference) = (0.0, 0.0f64);
            for i in 0..n {
                if constrained[i] {
                    continue;
                }
                let inertia = self.inertia[i];
                reference = reference
                    .max(inertia.abs())
                    .max(self.fi[i].abs())
                    .max((self.r[i] + self.fi[i]).abs());
                self.r[i] -= inertia;
                rn += self.r[i] * self.r[i];
            }
            let rn = rn.sqrt();
            // Newton has reached the round-off floor of the forces when a further iteration no
            // longer halves the residual: accept that floor within `STALL_FACTOR` x the tolerance.
            let stalled = rn > 0.5 * last.0 && rn <= STALL_FACTOR * self.params.tol * reference;
            let previous = (it > 0).then_some(last.0);
            last = (rn, reference);
            if rn <= self.params.tol * reference || rn <= self.params.abs_tol || stalled {
                self.finish(model, dt, stage);
                let work = self.solver.stats().since(&work);
                return Ok(StepInfo {
                    iterations: it,
                    residual: rn / reference.max(1e-300),
                    factorisations: work.factorisations,
                    gmres_iterations: work.gmres_iterations,
                    matrix_free_solves: work.matrix_free_solves,
                });
            }
            if it == self.params.max_iter {
                break;
            }
            // J δ = r (r = -residual), J = cm M + ck K on the free dofs: from differences of
            // the residual while the kept factor preconditions well, else assembled
            let mut sol = self.solver.free.gather(&self.r);
            let target = (self.params.tol * reference).max(self.params.abs_tol);
            let eta = if self.params.inexact { forcing(rn, previous, target) } else { SOLVE_TOL };
            let free_of_matrix = self.params.inexact && eta >= MATRIX_FREE_TOL && {
                let diff = &mut self.difference;
                for i in 0..n {
                    diff.base[i] = self.r[i] + self.inertia[i];
                }
                let u_max = diff.scale(model);
                diff.moved = false;
                let mut product = |d: &[f64], out: &mut [f64]| {
                    diff.product(&mut *model, (t_load, extra), (cm, stage, u_max), d, out)
                };
                let rhs = sol.col_as_slice_mut(0);
                match self.solver.solve_matrix_free(&mut product, rhs, eta) {
                    Ok(done) => {
                        if !done && self.difference.moved {
                            // the trial material state back at the iterate for its tangent
                            self.difference.fi.fill(0.0);
                            model.internal_force(&mut self.difference.fi);
                        }
                        done
                    }
                    Err(e) => {
                        model.revert();
                        return Err(ImplicitError::Singular(e.0));
                    }
                }
            };
            if !free_of_matrix {
                model.tangent(t_load, &mut self.tangent);
                model.nondiagonal_mass(&mut self.mass_triplets);
                let scale = cm / ck;
                self.tangent.entries.extend(
                    self.mass_triplets.iter().map(|e| Triplet::new(e.row, e.col, scale * e.val)),
                );
                let solved = self
                    .solver
                    .assemble(&self.tangent, ck, Some((cm, &mass)))
                    .and_then(|()| self.solver.solve_in_place_to(sol.as_mut(), eta));
                if let Err(e) = solved {
                    model.revert();
                    return Err(ImplicitError::Singular(e.0));
                }
            }
            for (i, &c) in constrained.iter().enumerate() {
                let d = if c { 0.0 } else { sol[(self.solver.free.index(i).expect("free"), 0)] };
                self.du[i] += d;
                self.delta[i] = stage * d;
            }
            model.apply_increment(&self.delta);
        }
        model.revert();
        Err(ImplicitError::NoConvergence {
            t: t0,
            iterations: self.params.max_iter,
            residual: last.0,
            reference: last.1,
        })
    }

    /// Updates velocity and acceleration from the converged `Δu`, moves the model to the end of
    /// the step (midpoint: the second half of `Δu`) and commits.
    fn finish(&mut self, model: &mut dyn Model, dt: f64, stage: f64) {
        let n = self.du.len();
        for i in 0..n {
            let (v0, a0, du) = (self.state.v[i], self.state.a[i], self.du[i]);
            let (v1, a1) = match self.scheme {
                ImplicitScheme::Newmark => {
                    let a1 = 4.0 / (dt * dt) * (du - dt * v0) - a0;
                    (v0 + 0.5 * dt * (a0 + a1), a1)
                }
                ImplicitScheme::Midpoint => {
                    let v1 = 2.0 * du / dt - v0;
                    (v1, (v1 - v0) / dt)
                }
            };
            self.state.v[i] = v1;
            self.state.a[i] = a1;
        }
        if stage < 1.0 {
            for i in 0..n {
                self.delta[i] = (1.0 - stage) * self.du[i];
            }
            model.apply_increment(&self.delta);
            // Material state at the end configuration.
            self.fi.fill(0.0);
            model.internal_force(&mut self.fi);
        }
        model.dependent_motion(&mut self.state.v, &mut self.state.a);
        model.commit();
        self.state.t += dt;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::assembly::{FeModel, Part};
    use crate::elements::ShellSection;
    use crate::mesh::generate::rectangle;

    /// The difference product against the assembled `c_m M d + s K d` of a clamped MITC4
    /// plate bent well past its thickness (membrane and bending coupled), on a direction with
    /// translations and rotations alike: within 2e-7 of `|J d|` (seen: 4e-8) for the
    /// stiffness alone (`c_m = 0`), at the end and at the midpoint stage, and with a Newmark
    /// mass term.
    #[test]
    fn the_difference_product_is_the_assembled_jacobians() {
        let mesh = rectangle(1.0, 1.0, 6, 6);
        let section = ShellSection { e: 200e9, nu: 0.3, rho: 7800.0, h: 0.01 };
        let mut model = FeModel::new(&mesh, |_| Part::Shell(section)).unwrap();
        let edge = mesh.nodes_where(|q| q[0] == 0.0 || q[0] == 1.0 || q[1] == 0.0 || q[1] == 1.0);
        model.fix(&edge, [true; 6]);
        let n = model.n_dof();
        let constrained = model.constrained().to_vec();
        // a bump of 3 thicknesses with its slopes, and a little twist
        let mut bump = vec![0.0; n];
        for (a, x) in mesh.nodes.iter().enumerate() {
            if constrained[6 * a] {
                continue;
            }
            let (s, c) = (std::f64::consts::PI, 0.03);
            let (sx, sy) = ((s * x[0]).sin(), (s * x[1]).sin());
            bump[6 * a + 2] = c * sx * sy;
            bump[6 * a + 3] = c * s * sx * (s * x[1]).cos();
            bump[6 * a + 4] = -c * s * (s * x[0]).cos() * sy;
            bump[6 * a + 5] = 0.01 * x[0] * x[1];
        }
        model.apply_increment(&bump);
        let d: Vec<f64> =
            (0..n).map(|i| if constrained[i] { 0.0 } else { (1.7 * i as f64).sin() }).collect();
        let (mut tangent, mut kd) = (Tangent::default(), vec![0.0; n]);
        let mut md = vec![0.0; n];
        model.mass_product(&d, &mut md);
        let mut diff = Difference::default();
        diff.resize(n);
        let (mut fi, mut g) = (vec![0.0; n], vec![0.0; n]);
        for (cm, stage) in [(0.0, 1.0), (0.0, 0.5), (4.0 / (2e-4f64).powi(2), 1.0)] {
            // the forces at the stage point, as `Implicit::step` has them
            let half: Vec<f64> = bump.iter().map(|b| (stage - 1.0) * b).collect();
            model.apply_increment(&half);
            model.tangent(0.0, &mut tangent);
            kd.fill(0.0);
            for t in tangent.triplets() {
                kd[t.row] += t.val * d[t.col];
            }
            out_of_balance(&mut model, 0.0, None, &mut fi, &mut g);
            diff.base.copy_from_slice(&g);
            let u_max = diff.scale(&model);
            let mut jd = vec![0.0; n];
            diff.product(&mut model, (0.0, None), (cm, stage, u_max), &d, &mut jd);
            let (mut err, mut norm) = (0.0, 0.0);
            for i in (0..n).filter(|&i| !constrained[i]) {
                let exact = cm * md[i] + stage * kd[i];
                err += (jd[i] - exact).powi(2);
                norm += exact * exact;
            }
            let rel = (err / norm).sqrt();
            assert!(rel < 2e-7, "c_m {cm}, stage {stage}: relative error {rel:.2e}");
            let back: Vec<f64> = half.iter().map(|b| -b).collect();
            model.apply_increment(&back);
        }
    }
}
