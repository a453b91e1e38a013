//! 4-node tetrahedron, total Lagrangian with the Saint Venant-Kirchhoff law (exact under
//! rigid rotations of any size; constant strain). Translations only: the rotational freedoms
//! of solid-only nodes carry no stiffness and are held by the assembly.

use nalgebra::{Matrix3, Vector3};

/// Reference data of a tet: volume and shape-function gradients.
#[derive(Debug, Clone)]
pub struct Tet4 {
    pub volume: f64,
    /// `∇N_a` in the reference configuration (rows a = 0..4).
    pub grad: [Vector3<f64>; 4],
    /// Lamé parameters.
    pub lambda: f64,
    pub mu: f64,
}

impl Tet4 {
    pub fn new(x0: &[Vector3<f64>; 4], e: f64, nu: f64) -> Self {
        let m = Matrix3::from_columns(&[x0[1] - x0[0], x0[2] - x0[0], x0[3] - x0[0]]);
        let volume = m.determinant() / 6.0;
        let minv = m.try_inverse().expect("degenerate tetrahedron");
        // N1..3 = rows of M⁻¹ applied to (X - X0); N0 = 1 - Σ
        let g1 = minv.row(0).transpose();
        let g2 = minv.row(1).transpose();
        let g3 = minv.row(2).transpose();
        let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
        let mu = e / (2.0 * (1.0 + nu));
        Tet4 { volume, grad: [-(g1 + g2 + g3), g1, g2, g3], lambda, mu }
    }

    /// Deformation gradient at current positions `x`.
    pub fn deformation_gradient(&self, x: &[Vector3<f64>; 4]) -> Matrix3<f64> {
        let mut f = Matrix3::zeros();
        for a in 0..4 {
            f += x[a] * self.grad[a].transpose();
        }
        f
    }

    /// Second Piola-Kirchhoff stress `S = λ tr(E) I + 2 μ E` at `F`.
    pub fn pk2(&self, f: &Matrix3<f64>) -> Matrix3<f64> {
        let e = 0.5 * (f.transpose() * f - Matrix3::identity());
        Matrix3::identity() * (self.lambda * e.trace()) + 2.0 * self.mu * e
    }

    /// Nodal internal forces `f_a = V0 F S ∇N_a`.
    pub fn force(&self, x: &[Vector3<f64>; 4]) -> [Vector3<f64>; 4] {
        let f = self.deformation_gradient(x);
        let p = f * self.pk2(&f);
        self.grad.map(|g| self.volume * p * g)
    }
}
