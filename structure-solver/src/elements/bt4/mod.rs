//! The one-point Belytschko-Lin-Tsay 4-node shell for the explicit hot loop (Belytschko, Lin &
//! Tsay, CMAME 42, 1984; Hallquist, *LS-DYNA Theory Manual*, §6 and §7), with
//!
//! - a corotational frame per element: `ê3 ∥ x31 × x42`, `ê1` along side 1-2 projected on the
//!   plane, `ê2 = ê3 × ê1`;
//! - warping correction by rigid links from the nodes to their projections on that plane
//!   (Belytschko, Wong & Chiang 1992): projected velocities `v̂_P = v̂_I - z_I θ̇̂_I × ê3`, and
//!   the transposed moments `m̂_x += z_I f̂_y`, `m̂_y -= z_I f̂_x`, so rigid motions stay strain
//!   free on warped elements;
//! - Flanagan-Belytschko (IJNME 17, 1981) hourglass control of stiffness type on the membrane,
//!   out-of-plane and rotational modes, `γ_I = ¼ (h_I - (h·x̂) b_xI - (h·ŷ) b_yI)`,
//!   `h = [1, -1, 1, -1]`;
//! - hypoelastic plane-stress update in the corotated frame at `n` thickness points with the
//!   J2 plane-stress return (`newton` Newton updates, then the safeguarded fallback for points
//!   still outside `return_tol`; transverse shear stays elastic, `τ = κ G γ`, κ = 5/6).
//!
//! A step takes the end positions `x^{n+1}` and the increment `Δu` (translations and global
//! rotation increments) of the step: strain increments are computed in the mid-step geometry
//! `x^{n+1} - Δu/2`, where a rigid rotation's chord velocity is a pure spin (no strain), and the
//! nodal forces in the end geometry.
//!
//! Elements are evaluated in blocks of [`LANES`] with the kernel (`kernel`) written once over
//! [`Real`](crate::material::lanes::Real), each operation one across the elements of a block
//! (vector registers on x86-64); the loop (`forces`) runs over threads and picks the vector
//! width at run time. Per-point state lives
//! in flat arrays `[block][point][component][lane]`. State is double-buffered: a step reads the
//! committed state and writes the trial state; `commit` swaps them. Each element has its own
//! material (an index into the part's list), so a block may mix materials.

mod forces;
mod kernel;
mod step_bound;

pub use forces::{SimdPath, BLOCKS_PER_TASK};

use super::section::RotaryInertia;
use crate::elements::add_node_masses;
use crate::material::{ThicknessRule, J2};
use kernel::{frame, Constants};
use step_bound::BoundConstants;

/// Elements per block.
pub const LANES: usize = 8;

/// Stress components per thickness point: `[σxx, σyy, σxy, σyz, σzx]`.
pub const N_STRESS: usize = 5;
/// Hourglass stresses per element: membrane x, y, out-of-plane w, rotations x, y.
pub const N_HOURGLASS: usize = 5;

/// Settings of a BT4 part.
#[derive(Debug, Clone, PartialEq)]
pub struct Bt4Settings {
    pub rule: ThicknessRule,
    /// Hourglass coefficient `r` (membrane, out-of-plane and rotational alike).
    pub hourglass: f64,
    /// Plain Newton updates of the plane-stress return.
    pub newton: usize,
    /// Tolerance of the plane-stress return, `|f| <= tol κ²`: points still outside it after
    /// `newton` updates continue with the safeguarded fallback (0: exactly `newton` updates).
    pub return_tol: f64,
    /// Lumping of rotary inertia.
    pub rotary: RotaryInertia,
}

impl Default for Bt4Settings {
    fn default() -> Self {
        Bt4Settings {
            rule: ThicknessRule::gauss(5),
            hourglass: 0.05,
            newton: 3,
            return_tol: 1e-10,
            rotary: RotaryInertia::Scaled,
        }
    }
}

/// Per-point and per-element state of a part, in block layout.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Bt4State {
    /// `[block][point][component][lane]`.
    pub stress: Vec<f64>,
    /// Equivalent plastic strain, `[block][point][lane]`.
    pub alpha: Vec<f64>,
    /// Hourglass stresses, `[block][mode][lane]`.
    pub hourglass: Vec<f64>,
}

/// A part that cannot be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Bt4Error {
    #[error("BT4 part: {field} has {got} entries, expected one per element ({expected})")]
    Length { field: &'static str, got: usize, expected: usize },
    #[error("BT4 part: element {element} has material {index}, expected an index below {n}")]
    MaterialIndex { element: usize, index: usize, n: usize },
    #[error("BT4 part: the list of materials is empty")]
    NoMaterial,
    #[error("BT4 part: more than {max} materials", max = u16::MAX as usize + 1)]
    TooManyMaterials,
}

/// A part of BT4 shells: connectivity (in storage order), thickness and material per element.
#[derive(Debug, Clone)]
pub struct Bt4 {
    pub conn: Vec<[u32; 4]>,
    pub thickness: Vec<f64>,
    pub settings: Bt4Settings,
    materials: Vec<J2>,
    /// Index into `materials` per element.
    material_of: Vec<u16>,
    constants: Vec<Constants<f64>>,
    bounds: Vec<BoundConstants<f64>>,
    committed: Bt4State,
    trial: Bt4State,
    work: forces::Work,
}

impl Bt4 {
    /// A part of one material; `thickness` per element.
    pub fn new(
        conn: Vec<[u32; 4]>,
        thickness: Vec<f64>,
        material: J2,
        settings: Bt4Settings,
    ) -> Self {
        assert_eq!(conn.len(), thickness.len(), "one thickness per element");
        let ne = conn.len();
        Self::with_materials(conn, thickness, vec![material], vec![0; ne], settings)
            .expect("one material, every element on it")
    }

    /// A part of several materials: element `e` is of `materials[material_of[e]]`.
    pub fn with_materials(
        conn: Vec<[u32; 4]>,
        thickness: Vec<f64>,
        materials: Vec<J2>,
        material_of: Vec<u16>,
        settings: Bt4Settings,
    ) -> Result<Self, Bt4Error> {
        let ne = conn.len();
        for (field, got) in [("thickness", thickness.len()), ("material_of", material_of.len())] {
            if got != ne {
                return Err(Bt4Error::Length { field, got, expected: ne });
            }
        }
        if materials.is_empty() {
            return Err(Bt4Error::NoMaterial);
        }
        if materials.len() > u16::MAX as usize + 1 {
            return Err(Bt4Error::TooManyMaterials);
        }
        if let Some((element, &m)) =
            material_of.iter().enumerate().find(|&(_, &m)| m as usize >= materials.len())
        {
            return Err(Bt4Error::MaterialIndex { element, index: m as usize, n: materials.len() });
        }
        let nb = ne.div_ceil(LANES);
        let np = settings.rule.len();
        let state = Bt4State {
            stress: vec![0.0; nb * np * N_STRESS * LANES],
            alpha: vec![0.0; nb * np * LANES],
            hourglass: vec![0.0; nb * N_HOURGLASS * LANES],
        };
        Ok(Bt4 {
            conn,
            thickness,
            settings,
            constants: materials.iter().map(Constants::of).collect(),
            bounds: materials.iter().map(BoundConstants::of).collect(),
            materials,
            material_of,
            committed: state.clone(),
            trial: state,
            work: forces::Work::default(),
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
    pub fn state(&self) -> &Bt4State {
        &self.committed
    }

    /// Restores a committed state.
    pub fn set_state(&mut self, s: Bt4State) {
        assert_eq!(s.stress.len(), self.committed.stress.len(), "state of another part");
        self.trial = s.clone();
        self.committed = s;
    }

    /// Accepts the trial state.
    pub fn commit(&mut self) {
        std::mem::swap(&mut self.committed, &mut self.trial);
    }

    /// Committed stress `[σxx, σyy, σxy, σyz, σzx]` of element `e` at thickness point `p`, in the
    /// corotated frame.
    pub fn stress(&self, e: usize, p: usize) -> [f64; N_STRESS] {
        let np = self.settings.rule.len();
        let (b, l) = (e / LANES, e % LANES);
        std::array::from_fn(|c| self.committed.stress[((b * np + p) * N_STRESS + c) * LANES + l])
    }

    /// Sets the committed (and trial) stress of element `e` at point `p` (prestress).
    pub fn set_stress(&mut self, e: usize, p: usize, s: [f64; N_STRESS]) {
        let np = self.settings.rule.len();
        let (b, l) = (e / LANES, e % LANES);
        for (c, v) in s.iter().enumerate() {
            let i = ((b * np + p) * N_STRESS + c) * LANES + l;
            self.committed.stress[i] = *v;
            self.trial.stress[i] = *v;
        }
    }

    /// Committed equivalent plastic strain of element `e` at point `p`.
    pub fn plastic_strain(&self, e: usize, p: usize) -> f64 {
        let np = self.settings.rule.len();
        self.committed.alpha[((e / LANES) * np + p) * LANES + e % LANES]
    }

    /// Appends a copy of element `e` on the nodes `conn` with its thickness, material and
    /// full committed state (stresses, equivalent plastic strain and hourglass stresses at
    /// every point, copied into the trial state too): a phantom element of the phantom-node
    /// formulation (thesis §3.5, Fig. 3.2). A new block of zero state is opened when the last
    /// one is full; the node chunks are rebuilt at the next force. Returns the new
    /// element's index, or `None` when `e` is not an element of the part.
    pub fn push_copy(&mut self, e: usize, conn: [u32; 4]) -> Option<usize> {
        if e >= self.conn.len() {
            return None;
        }
        let new = self.conn.len();
        let (thickness, material) = (self.thickness[e], self.material_of[e]);
        self.conn.push(conn);
        self.thickness.push(thickness);
        self.material_of.push(material);
        let np = self.settings.rule.len();
        let nb = self.conn.len().div_ceil(LANES);
        for s in [&mut self.committed, &mut self.trial] {
            s.stress.resize(nb * np * N_STRESS * LANES, 0.0);
            s.alpha.resize(nb * np * LANES, 0.0);
            s.hourglass.resize(nb * N_HOURGLASS * LANES, 0.0);
        }
        let lane = |e: usize, rows: usize, r: usize| ((e / LANES) * rows + r) * LANES + e % LANES;
        let c = &mut self.committed;
        for r in 0..np * N_STRESS {
            c.stress[lane(new, np * N_STRESS, r)] = c.stress[lane(e, np * N_STRESS, r)];
        }
        for r in 0..np {
            c.alpha[lane(new, np, r)] = c.alpha[lane(e, np, r)];
        }
        for r in 0..N_HOURGLASS {
            c.hourglass[lane(new, N_HOURGLASS, r)] = c.hourglass[lane(e, N_HOURGLASS, r)];
        }
        self.trial.clone_from(&self.committed);
        self.work = forces::Work::default();
        Some(new)
    }

    /// Committed hourglass stresses of element `e` (membrane x, y, out-of-plane, rotations x,
    /// y).
    pub fn hourglass(&self, e: usize) -> [f64; N_HOURGLASS] {
        let (b, l) = (e / LANES, e % LANES);
        std::array::from_fn(|m| self.committed.hourglass[(b * N_HOURGLASS + m) * LANES + l])
    }

    /// Bytes of state and work arrays per element (double-buffered state, connectivity,
    /// thickness, material index, element node slots and shared-node rows).
    pub fn bytes_per_element(&self) -> f64 {
        let s = &self.committed;
        let state = 2 * 8 * (s.stress.len() + s.alpha.len() + s.hourglass.len());
        let mesh = 16 * self.conn.len() + 8 * self.thickness.len() + 2 * self.material_of.len();
        (state + mesh + self.work.bytes()) as f64 / self.conn.len().max(1) as f64
    }

    /// Adds the lumped mass (`ρ h A / 4` per node) and rotary inertia to a 6-per-node vector.
    pub fn lumped_mass(&self, x: &[[f64; 3]], mass: &mut [f64]) {
        for (e, (c, &h)) in self.conn.iter().zip(&self.thickness).enumerate() {
            let rho = self.material(e).elastic.rho;
            let xe = c.map(|n| x[n as usize]);
            let a = frame(&xe).area;
            let m = rho * h * a / 4.0;
            let i = self.settings.rotary.of_node(m, h, a);
            add_node_masses(mass, c, m, i);
        }
    }

    /// The element estimate of the critical step: the smaller of the membrane bound
    /// `L_e / c`, `L_e = A / max(diagonal)`, `c` the plate wave speed (Hallquist uses
    /// `A / max(side)`; the diagonal leaves room for the hourglass stiffness), and the rotational
    /// bound `2/ω_r`, `ω_r² = (12 κ G + 4 E h²/A) / (ρ (h² + a))` of the transverse-shear and
    /// bending modes of a node's rotary inertia `m (h² + a)/12` (`a = A` when scaled, else 0).
    /// Blocks of [`LANES`] elements on the widest vector unit, over the threads of the current
    /// pool.
    pub fn stable_dt(&self, x: &[[f64; 3]]) -> f64 {
        step_bound::stable_dt(SimdPath::detected(), &self.view(), &self.bounds, x)
            .expect("the detected path is supported")
    }

    /// The parts the kernels read.
    fn view(&self) -> forces::Bt4View<'_> {
        forces::Bt4View {
            conn: &self.conn,
            thickness: &self.thickness,
            constants: &self.constants,
            material_of: &self.material_of,
            settings: &self.settings,
        }
    }

    /// Adds the internal forces (6 per node, global frame) of the step with end positions
    /// `x_end` and increment `du` (6 per node) to `f`, writing the trial state. Runs over the
    /// threads of the current rayon pool with the widest vector unit the processor has; the
    /// result does not depend on either.
    pub fn internal_force(&mut self, x_end: &[[f64; 3]], du: &[f64], f: &mut [f64]) {
        self.internal_force_on(SimdPath::detected(), x_end, du, f)
            .expect("the detected path is supported");
    }

    /// [`Bt4::internal_force`] on a given instruction set; `None` (and nothing done) when the
    /// processor lacks it.
    pub fn internal_force_on(
        &mut self,
        path: SimdPath,
        x_end: &[[f64; 3]],
        du: &[f64],
        f: &mut [f64],
    ) -> Option<()> {
        assert!(du.len() >= 6 * x_end.len() && f.len() >= 6 * x_end.len(), "6 dofs per node");
        let view = forces::Bt4View {
            conn: &self.conn,
            thickness: &self.thickness,
            constants: &self.constants,
            material_of: &self.material_of,
            settings: &self.settings,
        };
        let state = (&self.committed, &mut self.trial);
        forces::internal_force(path, &view, state, &mut self.work, x_end, du, f)
    }
}
