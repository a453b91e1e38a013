//! Constitutive laws of the structure (DESIGN §6): linear elastic and J2 plasticity with linear
//! isotropic hardening, and the through-thickness quadrature of shells.
//!
//! Conventions: 3D stress and strain in Voigt order `[xx, yy, zz, xy, yz, zx]`, plane stress
//! `[xx, yy, xy]`; strains carry engineering shear (`γ_xy = 2 ε_xy`), so `σ · ε` is the work.
//! Tangents map engineering strain to stress.

pub mod elastic;
pub mod j2;
pub mod lanes;
#[cfg(target_arch = "x86_64")]
pub(crate) mod lanes_x86;
pub mod thickness;

pub use elastic::Elastic;
pub use j2::{
    return_plane_stress_with, J2State3d, J2StatePlane, PlaneStressConstants, PlaneStressReturn,
    Return3d, J2,
};
pub use thickness::ThicknessRule;

/// A shell or solid material as read from a case: elastic, or J2 when a yield stress is given.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Material {
    Elastic(Elastic),
    J2(J2),
}

impl Material {
    /// The elastic part.
    pub fn elastic(&self) -> Elastic {
        match self {
            Material::Elastic(e) => *e,
            Material::J2(j) => j.elastic,
        }
    }

    /// The J2 law; an elastic material is J2 with an infinite yield stress.
    pub fn as_j2(&self) -> J2 {
        match self {
            Material::Elastic(e) => J2 { elastic: *e, sigma_y: f64::INFINITY, h: 0.0 },
            Material::J2(j) => *j,
        }
    }
}
