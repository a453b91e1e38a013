//! Cross-section data of shells and beams (linear elastic, small strain in the corotated frame).

/// An elastic shell section: Young's modulus, Poisson's ratio, density and thickness.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShellSection {
    pub e: f64,
    pub nu: f64,
    pub rho: f64,
    pub h: f64,
}

/// Drilling penalty: nodal rotations about the element normal are tied to the in-plane
/// rotation `ω = ½(∂v/∂x - ∂u/∂y)` of the membrane field at the centroid with stiffness
/// `DRILL_PENALTY · G h A` per node. Small enough not to stiffen the shell measurably
/// (the Sze hemisphere moves by about 0.1% between 1e-5 and 1e-3), large enough to make the
/// drilling freedoms of flat and nearly flat meshes non-singular.
pub const DRILL_PENALTY: f64 = 1e-4;

/// Transverse shear correction factor of Reissner-Mindlin shells.
pub const SHEAR_FACTOR: f64 = 5.0 / 6.0;

impl ShellSection {
    pub fn shear_modulus(&self) -> f64 {
        self.e / (2.0 * (1.0 + self.nu))
    }

    /// Plane-stress membrane stiffness `h C` (Voigt `[xx, yy, xy]`, engineering shear).
    pub fn membrane(&self) -> [[f64; 3]; 3] {
        let c = self.e * self.h / (1.0 - self.nu * self.nu);
        [[c, c * self.nu, 0.0], [c * self.nu, c, 0.0], [0.0, 0.0, c * 0.5 * (1.0 - self.nu)]]
    }

    /// Bending stiffness `h³/12 C`.
    pub fn bending(&self) -> [[f64; 3]; 3] {
        let s = self.h * self.h / 12.0;
        self.membrane().map(|r| r.map(|v| v * s))
    }

    /// Transverse shear stiffness `κ G h`.
    pub fn shear(&self) -> f64 {
        SHEAR_FACTOR * self.shear_modulus() * self.h
    }
}

/// An elastic beam section: moduli, density, area, second moments about local y and z, and
/// the torsion constant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BeamSection {
    pub e: f64,
    pub nu: f64,
    pub rho: f64,
    pub area: f64,
    pub iy: f64,
    pub iz: f64,
    pub j: f64,
}

impl BeamSection {
    /// A solid rectangle `b` (along local y) by `h` (along local z).
    pub fn rectangle(e: f64, nu: f64, rho: f64, b: f64, h: f64) -> Self {
        let (a, c) = (b.max(h), b.min(h));
        let j = a * c.powi(3) * (1.0 / 3.0 - 0.21 * c / a * (1.0 - c.powi(4) / (12.0 * a.powi(4))));
        BeamSection {
            e,
            nu,
            rho,
            area: b * h,
            iy: b * h.powi(3) / 12.0,
            iz: h * b.powi(3) / 12.0,
            j,
        }
    }
}

/// `Bᵀ D B` scaled by `w` added into `k` (B: rows × n, D: rows × rows).
pub(crate) fn add_btdb(
    k: &mut nalgebra::DMatrix<f64>,
    b: &nalgebra::DMatrix<f64>,
    d: &nalgebra::DMatrix<f64>,
    w: f64,
) {
    let db = d * b;
    k.gemm_tr(w, b, &db, 1.0);
}
