//! The sparse solve of Newton iterations on the free dofs of a [`Model`] (DESIGN §6, faer).
//!
//! - `free_dofs`: the free-dof numbering, gather and scatter between full and free vectors.
//! - `scatter`: a stream of entries into compressed columns through a precomputed slot per
//!   entry.
//! - `pattern`: the structurally symmetric pattern (the full 6x6 node blocks of the tangent's
//!   entries, every diagonal entry) made on the first call with its fill-reducing ordering
//!   (AMD on the nodes) and symbolic `LDLᵀ`; later calls redo only the numeric work.
//! - `factor`: `J = c_k K_ff + c_m M_ff` and its factorisation. The corotational tangent (and a
//!   follower load's) is not symmetric away from equilibrium, and replacing it by its
//!   symmetric part would slow Newton several-fold in large rotations, so `J` itself is
//!   solved: its symmetric part `S = ½(J + Jᵀ)` is factored as `LDLᵀ` (supernodal, no
//!   pivoting, on rayon's threads: on the 61k-dof plate of `bench` 6x to 10x faster than
//!   faer's sparse LU, whose COLAMD ordering and partial pivoting make far more fill). Where
//!   `S` has a zero pivot or GMRES stalls, faer's LU with partial pivoting of `J` itself.
//! - `gmres`: `J x = b` right-preconditioned with an `LDLᵀ` to a relative residual of
//!   `SOLVE_TOL`, or to the looser [`forcing`] of an inexact Newton iteration (one step when
//!   the skew part is small against `S`, as in shells and beams).
//! - `tangent`: the matrix as the model emits it, dense element blocks written in place and
//!   loose entries; `scatter` sums them into the slots (no triplet per element entry).
//!
//! [`FreeSolver`] keeps the last `LDLᵀ` and preconditions the GMRES of later matrices with it
//! (the next Newton iterations, the next time or load steps) while that converges within
//! [`REUSE_ITERATIONS`]; a solve that needs more marks the factor stale (the next matrix is
//! factored afresh), and one that does not converge within a GMRES cycle refactors at once.
//! While the kept factor preconditions well, a caller that can form the Jacobian's products
//! itself (`time::implicit`, from differences of its residual) solves without assembling
//! ([`FreeSolver::solve_matrix_free`]), to no less than [`MATRIX_FREE_TOL`].

mod factor;
mod free_dofs;
mod gmres;
mod pattern;
pub mod scatter;
mod tangent;

use std::sync::Arc;

use faer::sparse::SparseColMatRef;
use faer::MatMut;

pub use factor::Factor;
use factor::{Jacobian, Ldlt};
pub use free_dofs::FreeDofs;
use pattern::Pattern;
pub use scatter::{Fingerprint, ScatterMap, SparsePattern};
pub use tangent::{Expansion, Tangent, MAX_EXPANSION};

use crate::model::Model;

/// Relative residual `|b - J x| / |b|` the solve reaches, or else a backward error
/// `|b - J x| / (|J|₁ |x|)` of 1e-14 (what a direct solve of an ill-conditioned matrix gives).
pub const SOLVE_TOL: f64 = 1e-11;

/// Largest relative residual [`forcing`] asks of a Newton iteration's solve.
const FORCING_MAX: f64 = 1e-2;

/// Relative residual of the linear solve of a Newton iteration (inexact Newton, Eisenstat &
/// Walker 1996, their choice 2 with γ = 0.9, α = 2): `η = 0.9 (|r_k| / |r_{k-1}|)²`, at most
/// `FORCING_MAX` (and that on the first iteration, `previous: None`), never below what the
/// Newton `target` needs (`0.1 target / |r_k|`: no solve goes further than a tenth of the
/// tolerance, which would be oversolving) nor below `SOLVE_TOL`. A solve to `η` leaves a linear
/// residual `η |r_k|`; the quadratic part of Newton's error dominates it while `η` follows the
/// observed contraction. Where the residual has not halved, Newton is outside its quadratic
/// range (large rotations) and an inexact step can send it astray: that solve goes to the
/// floor.
pub fn forcing(residual: f64, previous: Option<f64>, target: f64) -> f64 {
    let floor = (0.1 * target / residual).max(SOLVE_TOL);
    let ew = match previous {
        None => FORCING_MAX,
        Some(p) if residual <= 0.5 * p => 0.9 * (residual / p).powi(2),
        Some(_) => return floor,
    };
    ew.min(FORCING_MAX).max(floor)
}

/// The tightest relative residual of [`FreeSolver::solve_matrix_free`]: its products carry
/// the error of a difference quotient.
pub const MATRIX_FREE_TOL: f64 = 1e-5;

/// GMRES iterations (preconditioner applications) a kept factor may take on one right-hand
/// side before the next solve refactors.
pub const REUSE_ITERATIONS: usize = 8;

/// The matrix could not be assembled or factored.
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct FactorError(pub String);

/// Work counters of a [`FreeSolver`] since its creation.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SolveStats {
    /// Numeric factorisations (`LDLᵀ`, or LU where it had a zero pivot).
    pub factorisations: usize,
    /// GMRES iterations: applications of an `LDLᵀ` preconditioner.
    pub gmres_iterations: usize,
    /// Right-hand sides solved.
    pub solves: usize,
    /// Of those, solved without an assembled matrix ([`FreeSolver::solve_matrix_free`]).
    pub matrix_free_solves: usize,
}

impl SolveStats {
    /// The work done since `earlier`.
    pub fn since(&self, earlier: &SolveStats) -> SolveStats {
        SolveStats {
            factorisations: self.factorisations - earlier.factorisations,
            gmres_iterations: self.gmres_iterations - earlier.gmres_iterations,
            solves: self.solves - earlier.solves,
            matrix_free_solves: self.matrix_free_solves - earlier.matrix_free_solves,
        }
    }
}

/// The free-dof matrix `c_k K_ff + c_m diag(m)_ff` of a model's tangent triplets: its
/// pattern, the scatter map of the model's triplet stream, and the factor it keeps.
#[derive(Debug)]
pub struct FreeSolver {
    pub free: FreeDofs,
    pattern: Option<Arc<Pattern>>,
    map: Option<Arc<ScatterMap>>,
    /// The model's topology epoch the map was checked against.
    epoch: u64,
    /// The topology changed: the next assembly compares the stream's full fingerprint.
    recheck: bool,
    /// The matrix of the last `assemble`, with the preconditioner it has used.
    current: Option<Factor>,
    /// The last factorisation, reused while it preconditions well.
    kept: Option<Arc<Ldlt>>,
    /// The kept factor needed more than `REUSE_ITERATIONS`: refactor at the next solve.
    stale: bool,
    reuse: bool,
    stats: SolveStats,
}

impl Clone for FreeSolver {
    /// The same numbering, pattern, map and kept factor; no current matrix.
    fn clone(&self) -> Self {
        FreeSolver {
            free: self.free.clone(),
            pattern: self.pattern.clone(),
            map: self.map.clone(),
            epoch: self.epoch,
            recheck: self.recheck,
            current: None,
            kept: self.kept.clone(),
            stale: self.stale,
            reuse: self.reuse,
            stats: self.stats,
        }
    }
}

impl FreeSolver {
    /// A solver of `model`'s free dofs, reusing factors.
    pub fn new(model: &dyn Model) -> Self {
        FreeSolver {
            free: FreeDofs::new(model),
            pattern: None,
            map: None,
            epoch: model.topology_epoch(),
            recheck: false,
            current: None,
            kept: None,
            stale: false,
            reuse: true,
            stats: SolveStats::default(),
        }
    }

    /// `false`: [`Self::solve_in_place`] factors every matrix (the reference reuse is checked
    /// against).
    pub fn set_reuse(&mut self, reuse: bool) {
        self.reuse = reuse;
    }

    /// Work done so far.
    pub fn stats(&self) -> SolveStats {
        self.stats
    }

    /// Drops the kept factor and the current matrix: the next solve factors afresh, as a
    /// solver made anew would (a run restarted from a checkpoint of this state).
    pub fn forget_factor(&mut self) {
        self.kept = None;
        self.current = None;
        self.stale = false;
    }

    /// Follows a change of `model`'s topology (its `topology_epoch`): a new free-dof numbering
    /// starts over; the same numbering keeps the pattern, and the next assembly checks the
    /// full fingerprint of the triplet stream before reusing the map.
    pub fn sync(&mut self, model: &dyn Model) {
        let epoch = model.topology_epoch();
        if epoch == self.epoch {
            return;
        }
        self.epoch = epoch;
        let free = FreeDofs::new(model);
        if free != self.free {
            *self = FreeSolver { reuse: self.reuse, stats: self.stats, ..FreeSolver::new(model) };
        } else {
            self.recheck = true;
        }
    }

    /// Makes the pattern and scatter map fit the stream `k`: the map is kept when the
    /// stream passes its spot check (its full fingerprint after a topology change), the
    /// pattern when it holds every entry.
    fn fit(&mut self, k: &Tangent) -> Result<(), FactorError> {
        let free = &self.free;
        let index = |t: usize| {
            let (i, j) = k.index(t);
            Some((free.index(i)?, free.index(j)?))
        };
        if let (Some(p), Some(m)) = (&self.pattern, &self.map) {
            let same = if self.recheck {
                Fingerprint::of_tangent(k) == m.fingerprint()
            } else {
                m.spot_check(&p.col_ptr, &p.row_idx, k.len(), index)
            };
            self.recheck = false;
            if same {
                return Ok(());
            }
            let fp = Fingerprint::of_tangent(k);
            if let Ok(m) = ScatterMap::onto(&p.col_ptr, &p.row_idx, k.len(), index, fp) {
                self.map = Some(Arc::new(m));
                return Ok(());
            }
        }
        let p = Pattern::covering(free, k, self.pattern.as_deref()).map_err(FactorError)?;
        let fp = Fingerprint::of_tangent(k);
        let m = ScatterMap::onto(&p.col_ptr, &p.row_idx, k.len(), index, fp)?;
        self.map = Some(Arc::new(m));
        self.pattern = Some(Arc::new(p));
        self.kept = None;
        self.current = None;
        Ok(())
    }

    /// `J = ck K_ff + cm diag(mass)_ff` (`mass: None` for a static tangent) from the full
    /// stream `k` (entries on constrained dofs dropped, duplicates summed in order).
    fn jacobian(
        &mut self,
        k: &Tangent,
        ck: f64,
        mass: Option<(f64, &[f64])>,
    ) -> Result<Jacobian, FactorError> {
        self.fit(k)?;
        let (Some(pattern), Some(map)) = (&self.pattern, &self.map) else {
            return Err(FactorError("no matrix pattern".into()));
        };
        let mut a = pattern.take_any(pattern.nnz()); // every slot written
        map.scatter_with(|t| ck * k.value(t), &mut a);
        if let Some((cm, m)) = mass {
            for (d, &mi) in m.iter().enumerate() {
                if let Some(i) = self.free.index(d) {
                    a[pattern.diag[i]] += cm * mi;
                }
            }
        }
        Jacobian::new(Arc::clone(pattern), a)
    }

    /// Assembles `J` (as [`Self::factor`]) for the next [`Self::solve_in_place`], without
    /// factoring it.
    pub fn assemble(
        &mut self,
        k: &Tangent,
        ck: f64,
        mass: Option<(f64, &[f64])>,
    ) -> Result<(), FactorError> {
        self.current = None;
        self.current = Some(Factor::new(self.jacobian(k, ck, mass)?));
        Ok(())
    }

    /// The matrix of the last [`Self::assemble`] on its pattern (free-dof numbers).
    pub fn matrix(&self) -> Option<SparseColMatRef<'_, usize, f64>> {
        self.current.as_ref().map(|f| f.jacobian().matrix())
    }

    /// Solves `J x = b` in place for each column of `rhs`, `J` of the last
    /// [`Self::assemble`]: GMRES preconditioned with the kept factor while it converges within
    /// a cycle (one that needs more than `REUSE_ITERATIONS` is replaced at the next solve),
    /// else with a new factorisation of `J`, which is kept.
    pub fn solve_in_place(&mut self, rhs: MatMut<'_, f64>) -> Result<(), FactorError> {
        self.solve_in_place_to(rhs, SOLVE_TOL)
    }

    /// [`Self::solve_in_place`] to the relative residual `tol` (at least `SOLVE_TOL`; a
    /// Newton iteration's [`forcing`]).
    pub fn solve_in_place_to(
        &mut self,
        mut rhs: MatMut<'_, f64>,
        tol: f64,
    ) -> Result<(), FactorError> {
        let tol = tol.max(SOLVE_TOL);
        let Some(f) = self.current.as_mut() else {
            return Err(FactorError("no matrix assembled before the solve".into()));
        };
        let n = rhs.nrows();
        if n != f.jacobian().pattern.n {
            return Err(FactorError(format!(
                "right-hand side of {n} rows for {} free dofs",
                f.jacobian().pattern.n
            )));
        }
        for c in 0..rhs.ncols() {
            let b: Vec<f64> = (0..n).map(|i| rhs[(i, c)]).collect();
            let mut x = None;
            let kept = self.kept.as_ref().filter(|m| m.is_on(&f.jacobian().pattern));
            if let (false, true, false, Some(kept)) = (f.is_fresh(), self.reuse, self.stale, kept) {
                f.reuse(Arc::clone(kept));
                let out = f.solve_vec(&b, false, tol)?;
                self.stats.gmres_iterations += out.iterations;
                self.stale = out.iterations > REUSE_ITERATIONS || out.x.is_none();
                x = out.x;
            }
            let x = match x {
                Some(x) => x,
                None => {
                    if !f.is_fresh() {
                        f.refactor()?;
                        self.stats.factorisations += 1;
                        self.kept = f.fresh_ldlt().cloned();
                        self.stale = false;
                    }
                    let out = f.solve_vec(&b, false, tol)?;
                    self.stats.gmres_iterations += out.iterations;
                    out.x.ok_or_else(|| {
                        FactorError("the solve of the free-dof matrix did not converge".into())
                    })?
                }
            };
            self.stats.solves += 1;
            for (i, xi) in x.into_iter().enumerate() {
                rhs[(i, c)] = xi;
            }
        }
        Ok(())
    }

    /// Solves `J x = b` in place (`rhs`: `b` in free numbering) for a `J` known only through
    /// its products with full dof vectors, `product(d, out)`: `out = J d` (`d` zero on the
    /// constrained dofs; its constrained entries are ignored), by one GMRES cycle
    /// preconditioned with the kept factor, to the relative residual `tol` (at least
    /// `SOLVE_TOL`). `Ok(false)` leaves `rhs` alone when there is no kept factor to use (none
    /// yet, not reusing, stale, or the topology changed since the last assembly) or the cycle
    /// did not converge (the factor is then stale): [`Self::assemble`] and
    /// [`Self::solve_in_place_to`] refactor.
    pub fn solve_matrix_free(
        &mut self,
        product: &mut dyn FnMut(&[f64], &mut [f64]),
        rhs: &mut [f64],
        tol: f64,
    ) -> Result<bool, FactorError> {
        let (Some(pattern), Some(kept)) = (&self.pattern, &self.kept) else {
            return Ok(false);
        };
        if !self.reuse || self.stale || self.recheck || !kept.is_on(pattern) {
            return Ok(false);
        }
        if rhs.len() != pattern.n {
            return Err(FactorError(format!(
                "right-hand side of {} rows for {} free dofs",
                rhs.len(),
                pattern.n
            )));
        }
        let n = self.free.n_dof();
        let mut op = FullProduct {
            free: &self.free,
            product,
            d: vec![0.0; n],
            jd: vec![0.0; n],
            norm1: kept.norm1,
        };
        let one = gmres::Limits { restart: factor::FRESH.restart, cycles: 1 };
        let out = gmres::solve(&mut op, kept, rhs, one, tol.max(MATRIX_FREE_TOL));
        self.stats.gmres_iterations += out.iterations;
        self.stale = out.iterations > REUSE_ITERATIONS || out.x.is_none();
        let Some(x) = out.x else {
            return Ok(false);
        };
        self.stats.solves += 1;
        self.stats.matrix_free_solves += 1;
        rhs.copy_from_slice(&x);
        Ok(true)
    }

    /// Assembles and factors `J` (as [`Self::assemble`]) and returns the factorisation, which
    /// solves through faer's `Solve`; the kept factor is left alone.
    pub fn factor(
        &mut self,
        k: &Tangent,
        ck: f64,
        mass: Option<(f64, &[f64])>,
    ) -> Result<Factor, FactorError> {
        let mut f = Factor::new(self.jacobian(k, ck, mass)?);
        f.refactor()?;
        self.stats.factorisations += 1;
        Ok(f)
    }
}

/// A free-dof operator from a product on full dof vectors.
struct FullProduct<'a> {
    free: &'a FreeDofs,
    product: &'a mut dyn FnMut(&[f64], &mut [f64]),
    d: Vec<f64>,
    jd: Vec<f64>,
    norm1: f64,
}

impl gmres::Operator for FullProduct<'_> {
    fn apply(&mut self, x: &[f64], y: &mut [f64]) {
        self.d.fill(0.0);
        self.free.scatter_values(x, &mut self.d);
        (self.product)(&self.d, &mut self.jd);
        self.free.gather_values(&self.jd, y);
    }

    /// Nearly: the kept factor's `S` approximates `J`, so GMRES starts from `S⁻¹ b`.
    fn symmetric(&self) -> bool {
        true
    }

    fn norm1(&self) -> f64 {
        self.norm1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn forcing_follows_the_contraction_between_its_bounds() {
        let target = 1e-8;
        // first iteration far from the tolerance: the loosest solve
        assert_eq!(forcing(1.0, None, target), FORCING_MAX);
        // quadratic contraction: 0.9 (r_k / r_{k-1})²
        assert!((forcing(1e-3, Some(1e-1), target) - 0.9e-4).abs() < 1e-18);
        // near the tolerance: a tenth of the target, no further
        assert!((forcing(1e-6, Some(1e-3), target) - 1e-3).abs() < 1e-15);
        // a residual that did not halve: to the floor
        assert!((forcing(0.6, Some(1.0), target) - (0.1 * target / 0.6)).abs() < 1e-20);
        assert_eq!(forcing(1e9, Some(1e9), target), SOLVE_TOL);
    }
}
