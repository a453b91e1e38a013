//! Cross-section data of shells and beams (small strain in the corotated frame): elastic
//! sections, the J2 yield of shells and beams, and the fibre return of beams.

/// An elastic shell section: Young's modulus, Poisson's ratio, density and thickness.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShellSection {
    pub e: f64,
    pub nu: f64,
    pub rho: f64,
    pub h: f64,
}

/// J2 yield of a shell section (linear isotropic hardening, `hardening` the plastic modulus
/// `H` of `material::j2`), integrated at `points` Gauss-Legendre points through the thickness
/// (>= 8 for the fully plastic moment; 5 reach `Σ wᵢ|ζᵢ|` = 0.945 of it).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShellYield {
    pub sigma_y: f64,
    pub hardening: f64,
    pub points: usize,
}

/// Drilling penalty: nodal rotations about the element normal are tied to the in-plane
/// rotation `ω = ½(∂v/∂x - ∂u/∂y)` of the membrane field at the centroid with stiffness
/// `DRILL_PENALTY · G h A` per node. Small enough not to stiffen the shell measurably
/// (the Sze hemisphere moves by about 0.1% between 1e-5 and 1e-3), large enough to make the
/// drilling freedoms of flat and nearly flat meshes non-singular.
pub const DRILL_PENALTY: f64 = 1e-4;

/// Rotary inertia of shell nodes: physical, `I = m h²/12` (frequency tests and implicit runs),
/// or scaled for explicit steps, `I = m (h² + A)/12` (Key & Beisinger 1971; Belytschko, Lin &
/// Tsay 1984), so that the Mindlin rotational modes do not set `Δt ∝ h`; `m` is the node's
/// share of the element mass, `A` the element area.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RotaryInertia {
    Physical,
    Scaled,
}

impl RotaryInertia {
    /// Rotary inertia of a node of translational mass `m` of a shell of thickness `h` and
    /// element area `area`.
    pub fn of_node(self, m: f64, h: f64, area: f64) -> f64 {
        match self {
            RotaryInertia::Physical => m * h * h / 12.0,
            RotaryInertia::Scaled => m * (h * h + area) / 12.0,
        }
    }

    /// The area `A` added to `h²` (0 for the physical inertia).
    pub fn added_area(self, area: f64) -> f64 {
        match self {
            RotaryInertia::Physical => 0.0,
            RotaryInertia::Scaled => area,
        }
    }
}

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

/// J2 yield of a beam section, integrated over fibres (`beam::FibreBeam`): linear isotropic
/// hardening with `hardening` the plastic modulus `H` of `material::j2` (uniaxial
/// `σ = σy + E H/(E+H) (ε - σy/E)`), `points` x `points` Gauss-Legendre fibres over the section
/// (>= 8 through the depth for the fully plastic moment; 5 reach `Σ wᵢ|ξᵢ|` = 0.945 of it).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BeamYield {
    pub sigma_y: f64,
    pub hardening: f64,
    pub points: usize,
}

/// State of one fibre: plastic strain and equivalent plastic strain.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct FibreState {
    pub eps_p: f64,
    pub alpha: f64,
}

impl BeamYield {
    /// The uniaxial J2 return of a fibre of modulus `e` at total strain `eps` from the
    /// committed `state` (Simo & Hughes 1998, Box 1.4, exact for linear hardening):
    /// `σ_tr = E (ε - εp)`, `f = |σ_tr| - (σy + H α)`; if `f > 0`, `Δγ = f / (E + H)`,
    /// `σ = σ_tr - E Δγ sign σ_tr`. Returns the stress, the new state and the tangent
    /// (`E`, or `E H / (E + H)` when yielding).
    pub fn fibre(&self, e: f64, eps: f64, state: &FibreState) -> (f64, FibreState, f64) {
        let trial = e * (eps - state.eps_p);
        let f = trial.abs() - (self.sigma_y + self.hardening * state.alpha);
        if f <= 0.0 {
            return (trial, *state, e);
        }
        let dg = f / (e + self.hardening);
        let sign = trial.signum();
        let next = FibreState { eps_p: state.eps_p + dg * sign, alpha: state.alpha + dg };
        (trial - e * dg * sign, next, e * self.hardening / (e + self.hardening))
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

/// Adds the drilling penalty `½ DRILL_PENALTY G h A Σᵢ (θzᵢ - ω)²` to the local stiffness `k`
/// (6 dofs per node); `omega` is the row of `ω = ½(∂v/∂x - ∂u/∂y)` at the centroid over the
/// element dofs.
pub(crate) fn add_drilling_penalty(
    k: &mut nalgebra::DMatrix<f64>,
    omega: &[f64],
    sec: &ShellSection,
    area: f64,
) {
    let kd = DRILL_PENALTY * sec.shear_modulus() * sec.h * area;
    let n = omega.len();
    for i in 0..n / 6 {
        let mut r: Vec<f64> = omega.iter().map(|v| -v).collect();
        r[6 * i + 5] += 1.0;
        let rv = nalgebra::DMatrix::from_row_slice(1, n, &r);
        k.gemm_tr(kd, &rv, &rv, 1.0);
    }
}
