//! 4-node tetrahedron, total Lagrangian: Green-Lagrange strain into the material (elastic:
//! Saint Venant-Kirchhoff; J2: the 3D radial return of `material::j2` on `E`, a small-strain
//! law in the rotated frame), second Piola-Kirchhoff stress out (exact under rigid rotations
//! of any size; constant strain). Translations only: the rotational freedoms of solid-only
//! nodes carry no stiffness and are held by the assembly.

use nalgebra::{Matrix3, Vector3};

use crate::material::j2::J2State3d;
use crate::material::J2;

/// Reference data of a tet: volume and shape-function gradients.
#[derive(Debug, Clone)]
pub struct Tet4 {
    pub volume: f64,
    /// `∇N_a` in the reference configuration (rows a = 0..4).
    pub grad: [Vector3<f64>; 4],
    /// The material (elastic is J2 with an infinite yield stress).
    pub material: J2,
}

impl Tet4 {
    pub fn new(x0: &[Vector3<f64>; 4], material: J2) -> Self {
        let m = Matrix3::from_columns(&[x0[1] - x0[0], x0[2] - x0[0], x0[3] - x0[0]]);
        let volume = m.determinant() / 6.0;
        let minv = m.try_inverse().expect("degenerate tetrahedron");
        // N1..3 = rows of M⁻¹ applied to (X - X0); N0 = 1 - Σ
        let g1 = minv.row(0).transpose();
        let g2 = minv.row(1).transpose();
        let g3 = minv.row(2).transpose();
        Tet4 { volume, grad: [-(g1 + g2 + g3), g1, g2, g3], material }
    }

    /// Deformation gradient at current positions `x`.
    pub fn deformation_gradient(&self, x: &[Vector3<f64>; 4]) -> Matrix3<f64> {
        let mut f = Matrix3::zeros();
        for a in 0..4 {
            f += x[a] * self.grad[a].transpose();
        }
        f
    }

    /// Second Piola-Kirchhoff stress at `F` from the committed `state`, and the trial state.
    pub fn pk2(&self, f: &Matrix3<f64>, state: &J2State3d) -> (Matrix3<f64>, J2State3d) {
        let e = 0.5 * (f.transpose() * f - Matrix3::identity());
        let eps =
            [e[(0, 0)], e[(1, 1)], e[(2, 2)], 2.0 * e[(0, 1)], 2.0 * e[(1, 2)], 2.0 * e[(2, 0)]];
        let (s, trial, _) = self.material.update_3d(&eps, state);
        let m = Matrix3::new(s[0], s[3], s[5], s[3], s[1], s[4], s[5], s[4], s[2]);
        (m, trial)
    }

    /// Von Mises stress of the Cauchy stress `σ = F S Fᵀ / det F` at current positions `x`
    /// with the committed `state`.
    pub fn von_mises(&self, x: &[Vector3<f64>; 4], state: &J2State3d) -> f64 {
        let f = self.deformation_gradient(x);
        let (s, _) = self.pk2(&f, state);
        let sigma = f * s * f.transpose() / f.determinant();
        let dev = sigma - Matrix3::identity() * (sigma.trace() / 3.0);
        // scaled by the largest component against overflow
        let scale = dev.amax();
        if scale == 0.0 || !scale.is_finite() {
            return scale;
        }
        let n = dev / scale;
        scale * (1.5 * n.component_mul(&n).sum()).sqrt()
    }

    /// Nodal internal forces `f_a = V0 F S ∇N_a` and the trial material state.
    pub fn force(
        &self,
        x: &[Vector3<f64>; 4],
        state: &J2State3d,
    ) -> ([Vector3<f64>; 4], J2State3d) {
        let f = self.deformation_gradient(x);
        let (s, trial) = self.pk2(&f, state);
        let p = f * s;
        (self.grad.map(|g| self.volume * p * g), trial)
    }
}
