//! Natural frequencies: the lowest eigenpairs of `K φ = ω² M φ` at the initial configuration
//! (lumped `M`), by subspace iteration (Bathe 1996, §11.6) with a sparse LU of `K` on the
//! free dofs (`linsolve`).

use faer::linalg::solvers::Solve;
use faer::sparse::Triplet;
use faer::Mat;
use nalgebra::DMatrix;

use crate::linsolve::FreeSolver;
use crate::model::Model;

#[derive(Debug, thiserror::Error)]
pub enum ModalError {
    #[error("singular stiffness: {0}")]
    Singular(String),
    #[error("subspace iteration did not converge in {0} iterations")]
    NoConvergence(usize),
    #[error("the model has explicit-only parts (BT4 shells) without a stiffness: frequencies need MITC4/DKT shells")]
    NoTangent,
}

/// The `n` lowest circular frequencies `ω` (rad/s) of the model's free dofs.
pub fn lowest_frequencies(model: &mut dyn Model, n: usize) -> Result<Vec<f64>, ModalError> {
    if !model.has_tangent() {
        return Err(ModalError::NoTangent);
    }
    let mut solver = FreeSolver::new(model);
    let nf = solver.free.len();
    let mass = solver.free.gather(model.lumped_mass());
    let mass: Vec<f64> = (0..nf).map(|i| mass[(i, 0)]).collect();
    let mut trip = crate::model::Tangent::default();
    model.tangent(0.0, &mut trip);
    // the symmetric part ½(K + Kᵀ)
    let sym: Vec<Triplet<usize, usize, f64>> = trip
        .triplets()
        .flat_map(|e| {
            [Triplet::new(e.row, e.col, 0.5 * e.val), Triplet::new(e.col, e.row, 0.5 * e.val)]
        })
        .collect();
    let lu = solver.factor(&sym.into(), 1.0, None).map_err(|e| ModalError::Singular(e.0))?;
    let p = (2 * n).max(n + 8).min(nf);
    // deterministic start vectors
    let mut x = Mat::from_fn(nf, p, |i, j| {
        let h =
            ((i as u64 + 1).wrapping_mul(2654435761) ^ (j as u64 + 7).wrapping_mul(40503)) % 1000;
        h as f64 / 1000.0 - 0.5 + if i % p == j { 1.0 } else { 0.0 }
    });
    let mut last = vec![0.0; n];
    for it in 0..200 {
        // Y = K⁻¹ M X
        let mut y = Mat::from_fn(nf, p, |i, j| mass[i] * x[(i, j)]);
        let mx = y.clone();
        lu.solve_in_place(y.as_mut());
        // K_r = Yᵀ K Y = Yᵀ M X, M_r = Yᵀ M Y
        let kr =
            DMatrix::from_fn(p, p, |a, b| (0..nf).map(|i| y[(i, a)] * mx[(i, b)]).sum::<f64>());
        let mr = DMatrix::from_fn(p, p, |a, b| {
            (0..nf).map(|i| y[(i, a)] * mass[i] * y[(i, b)]).sum::<f64>()
        });
        let kr = 0.5 * (&kr + kr.transpose());
        let mr = 0.5 * (&mr + mr.transpose());
        let l =
            mr.clone().cholesky().ok_or_else(|| ModalError::Singular("subspace mass".into()))?.l();
        let linv = l.try_inverse().ok_or_else(|| ModalError::Singular("subspace mass".into()))?;
        let s = &linv * kr * linv.transpose();
        let eig = s.symmetric_eigen();
        let mut order: Vec<usize> = (0..p).collect();
        order.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
        let phi = linv.transpose() * &eig.eigenvectors;
        x = Mat::from_fn(nf, p, |i, j| (0..p).map(|a| y[(i, a)] * phi[(a, order[j])]).sum::<f64>());
        let lam: Vec<f64> = order[..n].iter().map(|&a| eig.eigenvalues[a]).collect();
        let done = lam.iter().zip(&last).all(|(a, b)| (a - b).abs() <= 1e-10 * a.abs());
        last = lam;
        if done && it > 2 {
            return Ok(last.iter().map(|l| l.max(0.0).sqrt()).collect());
        }
    }
    Err(ModalError::NoConvergence(200))
}
