//! The element container: corotated shells and beams, total-Lagrangian tets, each with its
//! internal force, a consistent tangent by central differences of that force (translations
//! perturbed additively, rotations by spatial spins, exactly as `Model::apply_increment`
//! composes them) and a lumped mass.

use nalgebra::{DMatrix, Matrix3, Vector3};

use super::corotation::{FrameRule, Reference};
use super::rotation::exp;
use super::section::{BeamSection, ShellSection};
use super::tet4::Tet4;
use super::{beam, dkt, mitc4};
use crate::material::j2::J2State3d;
use crate::material::Material;

/// Element families, for output and sets.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ElementKind {
    Quad4,
    Tri3,
    Beam2,
    Tet4,
}

#[derive(Debug, Clone)]
enum Body {
    /// Corotated element with a constant local stiffness.
    Corotated {
        reference: Reference,
        k: DMatrix<f64>,
    },
    Tet(Tet4),
}

/// One finite element.
#[derive(Debug, Clone)]
pub struct Element {
    pub kind: ElementKind,
    pub nodes: Vec<usize>,
    body: Body,
    /// Lumped mass, 6 per node: translational mass and the physical rotary inertia.
    pub mass: Vec<f64>,
    /// Mid-surface area (shells), length (beams) or volume (tets).
    pub measure: f64,
}

/// A configuration-dependent load: nodal positions to nodal forces (6 per node).
pub type LoadFn = dyn Fn(&[Vector3<f64>], &mut [f64]) + Sync;

/// Relative step of the finite-difference tangent.
const FD_STEP: f64 = 1e-6;

impl Element {
    /// A 4-node MITC4 shell (`x0`: initial nodal positions, counter-clockwise about the normal).
    pub fn quad4(nodes: [usize; 4], x0: &[Vector3<f64>; 4], sec: &ShellSection) -> Self {
        let reference = Reference::new(FrameRule::Quad, x0);
        let xy = [0, 1, 2, 3].map(|i| [reference.a[i].x, reference.a[i].y]);
        let k = mitc4::stiffness(&xy, sec);
        let area = mitc4::area(&xy);
        Self::shell(ElementKind::Quad4, nodes.to_vec(), reference, k, area, sec)
    }

    /// A 3-node DKT shell.
    pub fn tri3(nodes: [usize; 3], x0: &[Vector3<f64>; 3], sec: &ShellSection) -> Self {
        let reference = Reference::new(FrameRule::Triangle, x0);
        let xy = [0, 1, 2].map(|i| [reference.a[i].x, reference.a[i].y]);
        let k = dkt::stiffness(&xy, sec);
        let area = dkt::area(&xy);
        Self::shell(ElementKind::Tri3, nodes.to_vec(), reference, k, area, sec)
    }

    fn shell(
        kind: ElementKind,
        nodes: Vec<usize>,
        reference: Reference,
        k: DMatrix<f64>,
        area: f64,
        sec: &ShellSection,
    ) -> Self {
        let n = nodes.len() as f64;
        let m = sec.rho * sec.h * area / n;
        let i = sec.rho * sec.h.powi(3) / 12.0 * area / n;
        let mass = (0..nodes.len()).flat_map(|_| [m, m, m, i, i, i]).collect();
        Element { kind, nodes, body: Body::Corotated { reference, k }, mass, measure: area }
    }

    /// A 2-node beam; `up` fixes the local `y` axis (projected normal to the beam).
    pub fn beam2(
        nodes: [usize; 2],
        x0: &[Vector3<f64>; 2],
        up: Vector3<f64>,
        sec: &BeamSection,
    ) -> Self {
        let chord = x0[1] - x0[0];
        let l = chord.norm();
        let e1 = chord / l;
        let q0 = (up - up.dot(&e1) * e1).normalize();
        let reference = Reference::new(FrameRule::Beam { q0: [q0.x, q0.y, q0.z] }, x0);
        let k = beam::stiffness(l, sec);
        let m = sec.rho * sec.area * l / 2.0;
        // section inertia (torsion, y, z) rotated to global, diagonal kept
        let local = Matrix3::from_diagonal(&Vector3::new(sec.iy + sec.iz, sec.iy, sec.iz))
            * (sec.rho * l / 2.0);
        let g = reference.e0 * local * reference.e0.transpose();
        let mass = (0..2).flat_map(|_| [m, m, m, g[(0, 0)], g[(1, 1)], g[(2, 2)]]).collect();
        Element {
            kind: ElementKind::Beam2,
            nodes: nodes.to_vec(),
            body: Body::Corotated { reference, k },
            mass,
            measure: l,
        }
    }

    /// A 4-node tetrahedron.
    pub fn tet4(nodes: [usize; 4], x0: &[Vector3<f64>; 4], material: Material) -> Self {
        let tet = Tet4::new(x0, material.as_j2());
        let m = material.elastic().rho * tet.volume / 4.0;
        let mass = (0..4).flat_map(|_| [m, m, m, 0.0, 0.0, 0.0]).collect();
        let measure = tet.volume;
        Element {
            kind: ElementKind::Tet4,
            nodes: nodes.to_vec(),
            body: Body::Tet(tet),
            mass,
            measure,
        }
    }

    /// `true` if the element has rotational freedoms.
    pub fn has_rotations(&self) -> bool {
        matches!(self.body, Body::Corotated { .. })
    }

    /// Internal force (6 per node, global) at nodal positions `x` and rotations `r` from the
    /// committed material `state`; returns the trial state (unchanged for elastic elements).
    pub fn force(&self, x: &[Vector3<f64>], r: &[Matrix3<f64>], state: &J2State3d, f: &mut [f64]) -> J2State3d {
        match &self.body {
            Body::Corotated { reference, k } => {
                let mut d = [0.0; 24];
                let nd = 6 * x.len();
                let local = |d: &[f64], fl: &mut [f64]| {
                    for (i, o) in fl.iter_mut().enumerate() {
                        *o = (0..nd).map(|j| k[(i, j)] * d[j]).sum();
                    }
                };
                reference.force(x, r, &mut d[..nd], local, f);
                *state
            }
            Body::Tet(t) => {
                let xs = [x[0], x[1], x[2], x[3]];
                let (fa, trial) = t.force(&xs, state);
                f.fill(0.0);
                for a in 0..4 {
                    f[6 * a..6 * a + 3].copy_from_slice(fa[a].as_slice());
                }
                trial
            }
        }
    }

    /// Local deformational displacements `d` of a corotated element (None for tets).
    pub fn deformation(&self, x: &[Vector3<f64>], r: &[Matrix3<f64>]) -> Option<Vec<f64>> {
        match &self.body {
            Body::Corotated { reference, .. } => {
                let mut d = vec![0.0; 6 * x.len()];
                reference.deformation(x, r, &mut d, None);
                Some(d)
            }
            Body::Tet(_) => None,
        }
    }

    /// Tangent `∂f/∂q` by central differences of `force` (relative step `FD_STEP`; forward
    /// differences proved too inaccurate for thin shells in large rotation); `extra` adds a configuration-dependent load term (`-f_ext`) differentiated with it.
    pub fn tangent(
        &self,
        x: &[Vector3<f64>],
        r: &[Matrix3<f64>],
        state: &J2State3d,
        extra: Option<&LoadFn>,
    ) -> DMatrix<f64> {
        let n = x.len();
        let size = 6 * n;
        let scale = (1..n).map(|i| (x[i] - x[0]).norm()).fold(0.0, f64::max).max(1e-300);
        let ht = FD_STEP * scale;
        let hr = FD_STEP;
        let mut k = DMatrix::zeros(size, size);
        let (mut xp, mut rp) = (x.to_vec(), r.to_vec());
        let mut f0 = vec![0.0; size];
        let mut fp = vec![0.0; size];
        let mut tmp = vec![0.0; size];
        let mut eval = |xs: &[Vector3<f64>], rs: &[Matrix3<f64>], out: &mut [f64]| {
            self.force(xs, rs, state, out);
            if let Some(g) = extra {
                g(xs, &mut tmp);
                for (o, t) in out.iter_mut().zip(&tmp) {
                    *o -= t;
                }
            }
        };
        for j in 0..n {
            for c in 0..6 {
                if c >= 3 && !self.has_rotations() {
                    continue;
                }
                let h = if c < 3 { ht } else { hr };
                for (sign, out) in [(1.0, &mut fp), (-1.0, &mut f0)] {
                    if c < 3 {
                        xp[j][c] = x[j][c] + sign * h;
                    } else {
                        let mut w = Vector3::zeros();
                        w[c - 3] = sign * h;
                        rp[j] = exp(&w) * r[j];
                    }
                    eval(&xp, &rp, out);
                    xp[j] = x[j];
                    rp[j] = r[j];
                }
                for i in 0..size {
                    k[(i, 6 * j + c)] = (fp[i] - f0[i]) / (2.0 * h);
                }
            }
        }
        k
    }

    /// Largest eigenvalue of `M⁻¹ K` at the initial configuration (power iteration on the
    /// element; bounds the assembled one, Irons 1970), for the critical time step.
    pub fn max_frequency_squared(&self, x0: &[Vector3<f64>], rot_mass: &[f64]) -> f64 {
        let n = x0.len();
        let ident = vec![Matrix3::identity(); n];
        let k = self.tangent(x0, &ident, &J2State3d::default(), None);
        let size = 6 * n;
        let minv: Vec<f64> = (0..size)
            .map(|i| {
                let m = if i % 6 < 3 { self.mass[i] } else { rot_mass[i] };
                if m > 0.0 {
                    1.0 / m
                } else {
                    0.0
                }
            })
            .collect();
        // symmetric form M^-1/2 K M^-1/2
        let s = DMatrix::from_fn(size, size, |i, j| {
            0.5 * (k[(i, j)] + k[(j, i)]) * (minv[i] * minv[j]).sqrt()
        });
        let ev = s.symmetric_eigenvalues();
        ev.iter().cloned().fold(0.0, f64::max)
    }
}
