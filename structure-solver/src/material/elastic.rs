//! Isotropic linear elasticity (Hooke's law) in 3D and in plane stress.

/// Young's modulus `e`, Poisson's ratio `nu`, mass density `rho`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Elastic {
    pub e: f64,
    pub nu: f64,
    pub rho: f64,
}

impl Elastic {
    /// Shear modulus `G = E / (2 (1 + ν))`.
    pub fn shear_modulus(&self) -> f64 {
        self.e / (2.0 * (1.0 + self.nu))
    }

    /// Bulk modulus `K = E / (3 (1 - 2ν))`.
    pub fn bulk_modulus(&self) -> f64 {
        self.e / (3.0 * (1.0 - 2.0 * self.nu))
    }

    /// Lamé's first parameter `λ = E ν / ((1 + ν)(1 - 2ν))`.
    pub fn lame_lambda(&self) -> f64 {
        self.e * self.nu / ((1.0 + self.nu) * (1.0 - 2.0 * self.nu))
    }

    /// Plate wave speed `c = sqrt(E / (ρ (1 - ν²)))`, the membrane speed of a shell.
    pub fn plate_wave_speed(&self) -> f64 {
        (self.e / (self.rho * (1.0 - self.nu * self.nu))).sqrt()
    }

    /// Dilatational wave speed `c = sqrt((λ + 2G) / ρ)` of a solid.
    pub fn dilatational_wave_speed(&self) -> f64 {
        ((self.lame_lambda() + 2.0 * self.shear_modulus()) / self.rho).sqrt()
    }

    /// 3D stiffness `C` (Voigt, engineering shear).
    pub fn tangent_3d(&self) -> [[f64; 6]; 6] {
        let (l, g) = (self.lame_lambda(), self.shear_modulus());
        let mut c = [[0.0; 6]; 6];
        for (i, row) in c.iter_mut().enumerate().take(3) {
            row[..3].fill(l);
            row[i] += 2.0 * g;
        }
        for (i, row) in c.iter_mut().enumerate().skip(3) {
            row[i] = g;
        }
        c
    }

    /// 3D stress `σ = λ tr(ε) 1 + 2 G ε`.
    pub fn stress_3d(&self, eps: &[f64; 6]) -> [f64; 6] {
        let (l, g) = (self.lame_lambda(), self.shear_modulus());
        let tr = eps[0] + eps[1] + eps[2];
        [
            l * tr + 2.0 * g * eps[0],
            l * tr + 2.0 * g * eps[1],
            l * tr + 2.0 * g * eps[2],
            g * eps[3],
            g * eps[4],
            g * eps[5],
        ]
    }

    /// Strain energy density `W = λ/2 tr(ε)² + G ε:ε`.
    pub fn energy_3d(&self, eps: &[f64; 6]) -> f64 {
        let (l, g) = (self.lame_lambda(), self.shear_modulus());
        let tr = eps[0] + eps[1] + eps[2];
        let normal = eps[0] * eps[0] + eps[1] * eps[1] + eps[2] * eps[2];
        let shear = 0.5 * (eps[3] * eps[3] + eps[4] * eps[4] + eps[5] * eps[5]);
        0.5 * l * tr * tr + g * (normal + shear)
    }

    /// Plane-stress stiffness `E/(1-ν²) [[1, ν, 0], [ν, 1, 0], [0, 0, (1-ν)/2]]`.
    pub fn tangent_plane_stress(&self) -> [[f64; 3]; 3] {
        let d = self.e / (1.0 - self.nu * self.nu);
        [[d, d * self.nu, 0.0], [d * self.nu, d, 0.0], [0.0, 0.0, self.shear_modulus()]]
    }

    /// Plane stress `σ = C_ps ε`.
    pub fn stress_plane_stress(&self, eps: &[f64; 3]) -> [f64; 3] {
        let d = self.e / (1.0 - self.nu * self.nu);
        [
            d * (eps[0] + self.nu * eps[1]),
            d * (eps[1] + self.nu * eps[0]),
            self.shear_modulus() * eps[2],
        ]
    }

    /// Plane-stress energy density `W = ½ ε · C_ps ε`.
    pub fn energy_plane_stress(&self, eps: &[f64; 3]) -> f64 {
        let s = self.stress_plane_stress(eps);
        0.5 * (s[0] * eps[0] + s[1] * eps[1] + s[2] * eps[2])
    }

    /// Thickness strain of plane stress, `ε_zz = -ν/(1-ν) (ε_xx + ε_yy)`.
    pub fn plane_stress_thickness_strain(&self, eps: &[f64; 3]) -> f64 {
        -self.nu / (1.0 - self.nu) * (eps[0] + eps[1])
    }
}
