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
//! (`J2::return_plane_stress`, at most `newton` updates), the elastic transverse shear as
//! resultants (`κ G h`), and the nodal forces `A Bᵀ s` in the end geometry. Stresses live in
//! the element frame, so a rigid rotation carries them unchanged. State is double-buffered:
//! a step reads the committed state and writes the trial state; `commit` swaps them.

mod strain;

pub use strain::{frame, rows, Frame, Rows, N_DOF};

use super::add_node_masses;
use super::section::{RotaryInertia, SHEAR_FACTOR};
use crate::material::{ThicknessRule, J2};
use strain::{apply, dot};

/// Stress components per thickness point: `[σxx, σyy, σxy]`.
pub const N_STRESS: usize = 3;
/// Shear resultants per element: `[Qxz, Qyz]` at the centroid and that of the linear part.
pub const N_SHEAR: usize = 3;

/// Settings of a BLT3 part.
#[derive(Debug, Clone, PartialEq)]
pub struct Blt3Settings {
    pub rule: ThicknessRule,
    /// Newton updates of the plane-stress return.
    pub newton: usize,
    /// Lumping of rotary inertia.
    pub rotary: RotaryInertia,
}

impl Default for Blt3Settings {
    fn default() -> Self {
        Blt3Settings { rule: ThicknessRule::gauss(5), newton: 3, rotary: RotaryInertia::Scaled }
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

/// A part of BLT3 shells: connectivity, thickness per element, one material.
#[derive(Debug, Clone)]
pub struct Blt3 {
    pub conn: Vec<[u32; 3]>,
    pub thickness: Vec<f64>,
    pub material: J2,
    pub settings: Blt3Settings,
    committed: Blt3State,
    trial: Blt3State,
}

/// Why a part cannot be built.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum Blt3Error {
    #[error("{conn} triangles but {thickness} thicknesses: one thickness per element")]
    Thickness { conn: usize, thickness: usize },
    #[error("element {element}: thickness {h} must be positive and finite")]
    BadThickness { element: usize, h: f64 },
}

impl Blt3 {
    /// A part; `thickness` per element.
    pub fn new(
        conn: Vec<[u32; 3]>,
        thickness: Vec<f64>,
        material: J2,
        settings: Blt3Settings,
    ) -> Result<Self, Blt3Error> {
        if conn.len() != thickness.len() {
            return Err(Blt3Error::Thickness { conn: conn.len(), thickness: thickness.len() });
        }
        if let Some((element, &h)) =
            thickness.iter().enumerate().find(|(_, h)| !(h.is_finite() && **h > 0.0))
        {
            return Err(Blt3Error::BadThickness { element, h });
        }
        let (ne, np) = (conn.len(), settings.rule.len());
        let state = Blt3State {
            stress: vec![0.0; ne * np * N_STRESS],
            alpha: vec![0.0; ne * np],
            shear: vec![0.0; ne * N_SHEAR],
        };
        Ok(Blt3 { conn, thickness, material, settings, committed: state.clone(), trial: state })
    }

    pub fn n_elements(&self) -> usize {
        self.conn.len()
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
        let rho = self.material.elastic.rho;
        for (c, &h) in self.conn.iter().zip(&self.thickness) {
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
        let mut dt = f64::INFINITY;
        for (conn, &h) in self.conn.iter().zip(&self.thickness) {
            let f = frame(&conn.map(|n| x[n as usize]));
            let w2 = max_frequency_squared(&self.material, &self.settings, &f, h);
            dt = dt.min(2.0 / w2.sqrt());
        }
        dt
    }

    /// Adds the internal forces (6 per node, global frame) of the step with end positions
    /// `x_end` and increment `du` (6 per node) to `f`, writing the trial state.
    pub fn internal_force(&mut self, x_end: &[[f64; 3]], du: &[f64], f: &mut [f64]) {
        assert!(du.len() >= 6 * x_end.len() && f.len() >= 6 * x_end.len(), "6 dofs per node");
        let np = self.settings.rule.len();
        for (e, conn) in self.conn.iter().enumerate() {
            let nodes = conn.map(|n| n as usize);
            let xe = nodes.map(|n| x_end[n]);
            let xm = nodes.map(|n| std::array::from_fn(|k| x_end[n][k] - 0.5 * du[6 * n + k]));
            let dv = nodes.map(|n| std::array::from_fn(|k| du[6 * n + k]));
            let (s, a, q) = (e * np * N_STRESS, e * np, e * N_SHEAR);
            let fe = element(
                &self.material,
                &self.settings,
                Geometry { x_end: &xe, x_mid: &xm, du: &dv, h: self.thickness[e] },
                Committed {
                    stress: &self.committed.stress[s..s + np * N_STRESS],
                    alpha: &self.committed.alpha[a..a + np],
                    shear: &self.committed.shear[q..q + N_SHEAR],
                },
                Trial {
                    stress: &mut self.trial.stress[s..s + np * N_STRESS],
                    alpha: &mut self.trial.alpha[a..a + np],
                    shear: &mut self.trial.shear[q..q + N_SHEAR],
                },
            );
            for (i, &n) in nodes.iter().enumerate() {
                for k in 0..6 {
                    f[6 * n + k] += fe[i][k];
                }
            }
        }
    }
}

/// Gershgorin bound of the largest eigenvalue of `M^-1/2 K M^-1/2` of one element of
/// thickness `h` in frame `f` (elastic moduli; `stable_dt`).
fn max_frequency_squared(mat: &J2, set: &Blt3Settings, f: &Frame, h: f64) -> f64 {
    let el = mat.elastic;
    let r = rows(f);
    let c = el.tangent_plane_stress();
    let kgh = SHEAR_FACTOR * el.shear_modulus() * h;
    let mut k = [[0.0; N_DOF]; N_DOF];
    let mut add = |a: &[f64; N_DOF], b: &[f64; N_DOF], d: f64| {
        if d != 0.0 {
            for (ki, ai) in k.iter_mut().zip(a) {
                for (kij, bj) in ki.iter_mut().zip(b) {
                    *kij += f.area * d * ai * bj;
                }
            }
        }
    };
    for (rows, scale) in [(&r.membrane, h), (&r.curvature, h * h * h / 12.0)] {
        for i in 0..3 {
            for j in 0..3 {
                add(&rows[i], &rows[j], scale * c[i][j]);
            }
        }
    }
    add(&r.shear[0], &r.shear[0], kgh);
    add(&r.shear[1], &r.shear[1], kgh);
    add(&r.shear[2], &r.shear[2], kgh * r.linear_shear_factor);
    let m = el.rho * h * f.area / 3.0;
    let i = set.rotary.of_node(m, h, f.area);
    let mass = |d: usize| if d % 6 < 3 { m } else { i };
    (0..N_DOF)
        .map(|a| (0..N_DOF).map(|b| k[a][b].abs() / (mass(a) * mass(b)).sqrt()).sum::<f64>())
        .fold(0.0, f64::max)
}

/// One element's step geometry.
struct Geometry<'a> {
    x_end: &'a [[f64; 3]; 3],
    x_mid: &'a [[f64; 3]; 3],
    du: &'a [[f64; 6]; 3],
    h: f64,
}

/// One element's committed state.
struct Committed<'a> {
    stress: &'a [f64],
    alpha: &'a [f64],
    shear: &'a [f64],
}

/// One element's trial state.
struct Trial<'a> {
    stress: &'a mut [f64],
    alpha: &'a mut [f64],
    shear: &'a mut [f64],
}

/// Local dofs of the increment in frame `f`; rotation increments as the mid-step spin of
/// their Cayley transform, scaled by `2 tan(|Δθ|/2)/|Δθ|` (`bt4` takes its series
/// `1 + |Δθ|²/12`): a rigid rotation's chord `Δu = (R - I) X` is exactly that spin applied to
/// the mid geometry `(R + I) X / 2`, so translations and rotations agree and any rigid
/// increment below a half turn is strain free.
fn local_increment(f: &Frame, du: &[[f64; 6]; 3]) -> [f64; N_DOF] {
    let mut d = [0.0; N_DOF];
    for i in 0..3 {
        let u = [du[i][0], du[i][1], du[i][2]];
        let th = [du[i][3], du[i][4], du[i][5]];
        let t2 = dot(th, th);
        let t = t2.sqrt();
        let cay = if t > 1e-3 { 2.0 * (0.5 * t).tan() / t } else { 1.0 + t2 / 12.0 };
        for a in 0..3 {
            d[6 * i + a] = dot(f.e[a], u);
            d[6 * i + 3 + a] = dot(f.e[a], th) * cay;
        }
    }
    d
}

/// One element: strain increments at the mid geometry, stress update at every thickness
/// point, resultants, nodal forces and moments `A Bᵀ (N, M, Q)` in the end geometry (global).
fn element(mat: &J2, set: &Blt3Settings, g: Geometry, old: Committed, new: Trial) -> [[f64; 6]; 3] {
    let h = g.h;
    let fm = frame(g.x_mid);
    let rm = rows(&fm);
    let d = local_increment(&fm, g.du);
    let em = rm.membrane.map(|r| apply(&r, &d));
    let kap = rm.curvature.map(|r| apply(&r, &d));
    let gam = rm.shear.map(|r| apply(&r, &d));

    // --- Membrane and bending through the thickness.
    let el = mat.elastic;
    let c = el.tangent_plane_stress();
    let (mut n, mut m) = ([0.0; 3], [0.0; 3]);
    for (p, (&zeta, &w)) in set.rule.points.iter().zip(&set.rule.weights).enumerate() {
        let z = 0.5 * h * zeta;
        let de = [em[0] + z * kap[0], em[1] + z * kap[1], em[2] + z * kap[2]];
        let s = p * N_STRESS;
        let trial = [
            old.stress[s] + c[0][0] * de[0] + c[0][1] * de[1],
            old.stress[s + 1] + c[1][0] * de[0] + c[1][1] * de[1],
            old.stress[s + 2] + c[2][2] * de[2],
        ];
        let r = mat.return_plane_stress(trial, old.alpha[p], set.newton, 0.0);
        new.stress[s..s + N_STRESS].copy_from_slice(&r.sigma);
        new.alpha[p] = r.alpha;
        let wn = 0.5 * h * w;
        for k in 0..3 {
            n[k] += wn * r.sigma[k];
            m[k] += wn * z * r.sigma[k];
        }
    }
    // --- Elastic transverse shear: Q = κ G h γ at the centroid, κ G h m c for the linear part.
    let kgh = SHEAR_FACTOR * el.shear_modulus() * h;
    let ks = [kgh, kgh, kgh * rm.linear_shear_factor];
    for k in 0..N_SHEAR {
        new.shear[k] = old.shear[k] + ks[k] * gam[k];
    }

    // --- Forces in the end frame.
    let fe = frame(g.x_end);
    let re = rows(&fe);
    let mut fl = [0.0; N_DOF];
    for (rows, s) in [(&re.membrane, n), (&re.curvature, m)] {
        for (row, sk) in rows.iter().zip(s) {
            for (o, b) in fl.iter_mut().zip(row) {
                *o += fe.area * b * sk;
            }
        }
    }
    for (row, &q) in re.shear.iter().zip(new.shear.iter()) {
        for (o, b) in fl.iter_mut().zip(row) {
            *o += fe.area * b * q;
        }
    }
    // --- Back to the global frame.
    let mut out = [[0.0; 6]; 3];
    for i in 0..3 {
        for k in 0..3 {
            out[i][k] = (0..3).map(|a| fe.e[a][k] * fl[6 * i + a]).sum();
            out[i][3 + k] = (0..3).map(|a| fe.e[a][k] * fl[6 * i + 3 + a]).sum();
        }
    }
    out
}
