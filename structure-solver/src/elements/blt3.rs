//! The one-point corotational 3-node shell for the explicit loop, of the Belytschko-Lin-Tsay
//! class (the C0 triangle of Belytschko, Stolarski & Carpenter, IJNME 20, 1984; LS-DYNA shell
//! type 4): linear displacements and rotations in a corotated frame (`strain::frame`), constant
//! membrane strain and curvature at the centroid, transverse shear assumed as in MITC3 (edge
//! tying, `strain::rows`; its centroid value and its linear part, the latter the only one
//! that removes the zero-energy mode a one-point shear leaves), lumped mass with the scaled
//! rotary inertia of `RotaryInertia`, no drilling stiffness (as `bt4`).
//!
//! The step follows `bt4`: the end positions `x^{n+1}` and the increment `Δu` (translations
//! and global rotation increments) of the step; strain increments in the mid-step geometry
//! `x^{n+1} - Δu/2` (where a rigid rotation's chord is a pure spin), the hypoelastic
//! plane-stress update at the points of a [`ThicknessRule`] with the J2 plane-stress return
//! (`J2::return_plane_stress`: `newton` Newton updates, then the safeguarded fallback for
//! points still outside `return_tol`, as `bt4`), the elastic transverse shear as resultants
//! (`κ G h`), and the nodal forces `A Bᵀ s` in the end geometry (`kernel`). Stresses live in
//! the element frame, so a rigid rotation carries them unchanged. State is double-buffered:
//! a step reads the committed state and writes the trial state; `commit` swaps them. The loop
//! (`forces`) runs over threads, bitwise independent of their number. Each element has its
//! own material (an index into the part's list).

mod forces;
mod kernel;
mod strain;

pub use strain::{frame, rows, Frame, Rows, N_DOF};

use rayon::prelude::*;

use super::add_node_masses;
use super::section::RotaryInertia;
use crate::material::{ThicknessRule, J2};
use kernel::max_frequency_squared;

/// Stress components per thickness point: `[σxx, σyy, σxy]`.
pub const N_STRESS: usize = 3;
/// Shear resultants per element: `[Qxz, Qyz]` at the centroid and that of the linear part.
pub const N_SHEAR: usize = 3;

/// Settings of a BLT3 part.
#[derive(Debug, Clone, PartialEq)]
pub struct Blt3Settings {
    pub rule: ThicknessRule,
    /// Plain Newton updates of the plane-stress return.
    pub newton: usize,
    /// Tolerance of the plane-stress return, `|f| <= tol κ²`: points still outside it after
    /// `newton` updates continue with the safeguarded fallback (0: exactly `newton` updates).
    pub return_tol: f64,
    /// Lumping of rotary inertia.
    pub rotary: RotaryInertia,
}

impl Default for Blt3Settings {
    fn default() -> Self {
        Blt3Settings {
            rule: ThicknessRule::gauss(5),
            newton: 3,
            return_tol: 1e-10,
            rotary: RotaryInertia::Scaled,
        }
    }
}

/// Per-point and per-element state of a part.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Blt3State {
    /// `[element][point][component]`.
    pub stress: Vec<f64>,
    /// Equivalent plastic strain, `[element][point]`.
    pub alpha: Vec<f64>,
    /// Transverse shear resultants, `[element][N_SHEAR]`.
    pub shear: Vec<f64>,
}

/// A part of BLT3 shells: connectivity, thickness and material per element.
#[derive(Debug, Clone)]
pub struct Blt3 {
    pub conn: Vec<[u32; 3]>,
    pub thickness: Vec<f64>,
    pub settings: Blt3Settings,
    materials: Vec<J2>,
    /// Index into `materials` per element.
    material_of: Vec<u16>,
    committed: Blt3State,
    trial: Blt3State,
    work: forces::Work,
    /// Each element's step bound and characteristic length at the reference configuration
    /// (`set_reference`).
    reference: Vec<[f64; 2]>,
}

/// Why a part cannot be built.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum Blt3Error {
    #[error("{conn} triangles but {thickness} thicknesses: one thickness per element")]
    Thickness { conn: usize, thickness: usize },
    #[error("element {element}: thickness {h} must be positive and finite")]
    BadThickness { element: usize, h: f64 },
    #[error("{conn} triangles but {got} material indices: one per element")]
    MaterialCount { conn: usize, got: usize },
    #[error("element {element} has material {index}, expected an index below {n}")]
    MaterialIndex { element: usize, index: usize, n: usize },
    #[error("the list of materials is empty")]
    NoMaterial,
    #[error("more than {max} materials", max = u16::MAX as usize + 1)]
    TooManyMaterials,
}

impl Blt3 {
    /// A part of one material; `thickness` per element.
    pub fn new(
        conn: Vec<[u32; 3]>,
        thickness: Vec<f64>,
        material: J2,
        settings: Blt3Settings,
    ) -> Result<Self, Blt3Error> {
        let ne = conn.len();
        Self::with_materials(conn, thickness, vec![material], vec![0; ne], settings)
    }

    /// A part of several materials: element `e` is of `materials[material_of[e]]`.
    pub fn with_materials(
        conn: Vec<[u32; 3]>,
        thickness: Vec<f64>,
        materials: Vec<J2>,
        material_of: Vec<u16>,
        settings: Blt3Settings,
    ) -> Result<Self, Blt3Error> {
        let ne = conn.len();
        if thickness.len() != ne {
            return Err(Blt3Error::Thickness { conn: ne, thickness: thickness.len() });
        }
        if material_of.len() != ne {
            return Err(Blt3Error::MaterialCount { conn: ne, got: material_of.len() });
        }
        if let Some((element, &h)) =
            thickness.iter().enumerate().find(|(_, h)| !(h.is_finite() && **h > 0.0))
        {
            return Err(Blt3Error::BadThickness { element, h });
        }
        if materials.is_empty() {
            return Err(Blt3Error::NoMaterial);
        }
        if materials.len() > u16::MAX as usize + 1 {
            return Err(Blt3Error::TooManyMaterials);
        }
        if let Some((element, &m)) =
            material_of.iter().enumerate().find(|&(_, &m)| m as usize >= materials.len())
        {
            return Err(Blt3Error::MaterialIndex {
                element,
                index: m as usize,
                n: materials.len(),
            });
        }
        let np = settings.rule.len();
        let state = Blt3State {
            stress: vec![0.0; ne * np * N_STRESS],
            alpha: vec![0.0; ne * np],
            shear: vec![0.0; ne * N_SHEAR],
        };
        Ok(Blt3 {
            conn,
            thickness,
            settings,
            materials,
            material_of,
            committed: state.clone(),
            trial: state,
            work: forces::Work::default(),
            reference: Vec::new(),
        })
    }

    pub fn n_elements(&self) -> usize {
        self.conn.len()
    }

    /// The material of element `e`.
    pub fn material(&self, e: usize) -> &J2 {
        &self.materials[self.material_of[e] as usize]
    }

    /// The materials of the part.
    pub fn materials(&self) -> &[J2] {
        &self.materials
    }
    /// Committed state (for checkpoints).
    pub fn state(&self) -> &Blt3State {
        &self.committed
    }

    /// Restores a committed state of a part of the same size.
    pub fn set_state(&mut self, s: Blt3State) -> Result<(), String> {
        let c = &self.committed;
        if (s.stress.len(), s.alpha.len(), s.shear.len())
            != (c.stress.len(), c.alpha.len(), c.shear.len())
        {
            return Err("a BLT3 state of another mesh or thickness rule".into());
        }
        self.trial = s.clone();
        self.committed = s;
        Ok(())
    }

    /// Accepts the trial state.
    pub fn commit(&mut self) {
        std::mem::swap(&mut self.committed, &mut self.trial);
    }

    /// Appends a copy of element `e` on the nodes `conn` with its thickness, material and full
    /// committed state (stress and plastic strain at every point, shear resultants), as the
    /// phantom-node copies of a cracking shell need (thesis §3.5); the reference step bounds are
    /// recomputed by the next [`Blt3::set_reference`]. Returns the copy's index, `None` if `e`
    /// is not an element of the part.
    pub fn push_copy(&mut self, e: usize, conn: [u32; 3]) -> Option<usize> {
        if e >= self.conn.len() {
            return None;
        }
        let np = self.settings.rule.len();
        self.conn.push(conn);
        self.thickness.push(self.thickness[e]);
        self.material_of.push(self.material_of[e]);
        let c = &mut self.committed;
        c.stress.extend_from_within(e * np * N_STRESS..(e + 1) * np * N_STRESS);
        c.alpha.extend_from_within(e * np..(e + 1) * np);
        c.shear.extend_from_within(e * N_SHEAR..(e + 1) * N_SHEAR);
        self.trial.clone_from(&self.committed);
        self.work = forces::Work::default();
        Some(self.conn.len() - 1)
    }

    /// Committed stress `[σxx, σyy, σxy]` of element `e` at thickness point `p`, in the
    /// element frame.
    pub fn stress(&self, e: usize, p: usize) -> [f64; N_STRESS] {
        let i = (e * self.settings.rule.len() + p) * N_STRESS;
        std::array::from_fn(|c| self.committed.stress[i + c])
    }

    /// Sets the committed (and trial) stress of element `e` at point `p` (prestress).
    pub fn set_stress(&mut self, e: usize, p: usize, s: [f64; N_STRESS]) {
        let i = (e * self.settings.rule.len() + p) * N_STRESS;
        self.committed.stress[i..i + N_STRESS].copy_from_slice(&s);
        self.trial.stress[i..i + N_STRESS].copy_from_slice(&s);
    }

    /// Committed transverse shear resultants of element `e`.
    pub fn shear(&self, e: usize) -> [f64; N_SHEAR] {
        std::array::from_fn(|c| self.committed.shear[e * N_SHEAR + c])
    }

    /// Committed equivalent plastic strain of element `e` at point `p`.
    pub fn plastic_strain(&self, e: usize, p: usize) -> f64 {
        self.committed.alpha[e * self.settings.rule.len() + p]
    }

    /// Adds the lumped mass (`ρ h A / 3` per node) and rotary inertia to a 6-per-node vector.
    pub fn lumped_mass(&self, x: &[[f64; 3]], mass: &mut [f64]) {
        for (e, (c, &h)) in self.conn.iter().zip(&self.thickness).enumerate() {
            let rho = self.material(e).elastic.rho;
            let a = frame(&c.map(|n| x[n as usize])).area;
            let m = rho * h * a / 3.0;
            let i = self.settings.rotary.of_node(m, h, a);
            add_node_masses(mass, c, m, i);
        }
    }

    /// The element estimate of the critical step, `2 / ω_max` with `ω_max²` bounded by the
    /// largest Gershgorin row sum of the element's `M^-1/2 K M^-1/2` (its elastic stiffness,
    /// `A Bᵀ D B` with `D` the membrane `h C`, bending `h³/12 C` and shear `κ G h` moduli, in the
    /// corotated frame, where the nodal masses are isotropic): a true upper bound of the
    /// element's eigenvalues, which bound the assembled ones (Irons 1970), for any shape and
    /// rotary inertia; `tests/blt3_dynamics.rs` measures how close it is.
    pub fn stable_dt(&self, x: &[[f64; 3]]) -> f64 {
        (0..self.conn.len())
            .into_par_iter()
            .with_min_len(1024)
            .map(|e| self.element_stable_dt(e, x))
            .reduce(|| f64::INFINITY, f64::min)
    }

    fn element_stable_dt(&self, e: usize, x: &[[f64; 3]]) -> f64 {
        let f = frame(&self.conn[e].map(|n| x[n as usize]));
        let w2 = max_frequency_squared(self.material(e), &self.settings, &f, self.thickness[e]);
        2.0 / w2.sqrt()
    }

    /// Takes `x` as the reference configuration of [`Blt3::scaled_stable_dt`]: each element's
    /// [`Blt3::stable_dt`] bound and characteristic length there (call again when the rotary
    /// inertia changes).
    pub fn set_reference(&mut self, x: &[[f64; 3]]) {
        self.reference = (0..self.conn.len())
            .into_par_iter()
            .with_min_len(1024)
            .map(|e| [self.element_stable_dt(e, x), altitude(&self.conn[e].map(|n| x[n as usize]))])
            .collect();
    }

    /// The element bound of the critical step at `x`, scaled from the reference one
    /// (`set_reference`) by how each element's characteristic length `L = 2A / max side`
    /// changed, `ρ = L(x)/L(X)`: `dt_e min(ρ, ρ²)` (bending frequencies go as `1/L²`,
    /// membrane ones as `1/L`), so a shrinking or flattening element shortens the step
    /// without the Gershgorin sum every step.
    pub fn scaled_stable_dt(&self, x: &[[f64; 3]]) -> f64 {
        assert_eq!(self.reference.len(), self.conn.len(), "set_reference before the step bound");
        (0..self.conn.len())
            .into_par_iter()
            .with_min_len(1024)
            .map(|e| {
                let [dt, l0] = self.reference[e];
                let rho = altitude(&self.conn[e].map(|n| x[n as usize])) / l0;
                dt * rho.min(rho * rho)
            })
            .reduce(|| f64::INFINITY, f64::min)
    }

    /// Bytes of state and work arrays per element (double-buffered state, connectivity,
    /// thickness, material index, reference bound, element node slots and shared-node rows).
    pub fn bytes_per_element(&self) -> f64 {
        let s = &self.committed;
        let state = 2 * 8 * (s.stress.len() + s.alpha.len() + s.shear.len());
        let mesh = 12 * self.conn.len() + 8 * self.thickness.len() + 2 * self.material_of.len();
        let bytes = state + mesh + 16 * self.reference.len() + self.work.bytes();
        bytes as f64 / self.conn.len().max(1) as f64
    }

    /// Adds the internal forces (6 per node, global frame) of the step with end positions
    /// `x_end` and increment `du` (6 per node) to `f`, writing the trial state. Runs over the
    /// threads of the current rayon pool; the result does not depend on their number.
    pub fn internal_force(&mut self, x_end: &[[f64; 3]], du: &[f64], f: &mut [f64]) {
        assert!(du.len() >= 6 * x_end.len() && f.len() >= 6 * x_end.len(), "6 dofs per node");
        self.threaded_force(x_end, du, f);
    }
}

/// The characteristic length of a triangle, its smallest altitude `2A / max side`.
fn altitude(x: &[[f64; 3]; 3]) -> f64 {
    let d = |i: usize, j: usize| {
        ((x[i][0] - x[j][0]).powi(2) + (x[i][1] - x[j][1]).powi(2) + (x[i][2] - x[j][2]).powi(2))
            .sqrt()
    };
    2.0 * frame(x).area / d(0, 1).max(d(1, 2)).max(d(2, 0))
}
