//! The element container: corotated shells (elastic, or J2 through the thickness: `layered`)
//! and beams (elastic, or J2 by fibres: `beam::FibreBeam`), total-Lagrangian tets, each with its internal force from a flat per-element
//! material state, a consistent tangent (corotated elements: `Bᵀ K_l B` plus the geometric
//! stiffness of `corotation::Reference::tangent`, with the algorithmic tangent of J2 sections;
//! tets: central differences of the force, translations perturbed additively, rotations by
//! spatial spins, exactly as `Model::apply_increment` composes them; the central differences
//! of every element are kept as `tangent_by_differences`, the check of the others) and a
//! lumped mass.

use nalgebra::{DMatrix, Matrix3, Vector3};

use super::beam::FibreBeam;
use super::corotation::{FrameRule, Reference};
use super::layered::{LayeredJ2, Layers};
use super::rotation::exp;
use super::section::{BeamSection, BeamYield, ShellSection, ShellYield};
use super::tet4::Tet4;
use super::{beam, dkt, mitc4};
use crate::material::j2::J2State3d;
use crate::material::{Elastic, Material, ThicknessRule, J2};

/// State values of a tet's one point: plastic strain (6) and equivalent plastic strain.
const TET_STATE: usize = 7;

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
        stress: ElasticStress,
    },
    /// Corotated shell of a J2 material integrated through the thickness.
    Layered {
        reference: Reference,
        shell: Box<LayeredJ2>,
    },
    /// Corotated beam of a J2 material integrated over fibres.
    Fibred {
        reference: Reference,
        beam: Box<FibreBeam>,
    },
    Tet(Tet4),
}

/// What the stress of an elastic corotated element is read from.
#[derive(Debug, Clone)]
enum ElasticStress {
    /// Shell: the in-plane points and the section.
    Shell { layers: Box<Layers>, sec: ShellSection },
    /// Beam: the section (end forces come from `K d`).
    Beam(BeamSection),
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
    /// A 4-node MITC4 shell (`x0`: initial nodal positions, counter-clockwise about the
    /// normal), elastic, or J2 through the thickness with `yield_`.
    pub fn quad4(
        nodes: [usize; 4],
        x0: &[Vector3<f64>; 4],
        sec: &ShellSection,
        yield_: Option<ShellYield>,
    ) -> Self {
        let reference = Reference::new(FrameRule::Quad, x0);
        let xy = [0, 1, 2, 3].map(|i| [reference.a[i].x, reference.a[i].y]);
        let layers = mitc4::layers(&xy, sec);
        let area = mitc4::area(&xy);
        Self::shell(ElementKind::Quad4, nodes.to_vec(), reference, layers, area, sec, yield_)
    }

    /// A 3-node DKT shell, elastic or J2 through the thickness.
    pub fn tri3(
        nodes: [usize; 3],
        x0: &[Vector3<f64>; 3],
        sec: &ShellSection,
        yield_: Option<ShellYield>,
    ) -> Self {
        let reference = Reference::new(FrameRule::Triangle, x0);
        let xy = [0, 1, 2].map(|i| [reference.a[i].x, reference.a[i].y]);
        let layers = dkt::layers(&xy, sec);
        let area = dkt::area(&xy);
        Self::shell(ElementKind::Tri3, nodes.to_vec(), reference, layers, area, sec, yield_)
    }

    fn shell(
        kind: ElementKind,
        nodes: Vec<usize>,
        reference: Reference,
        layers: Layers,
        area: f64,
        sec: &ShellSection,
        yield_: Option<ShellYield>,
    ) -> Self {
        let n = nodes.len() as f64;
        let m = sec.rho * sec.h * area / n;
        let i = sec.rho * sec.h.powi(3) / 12.0 * area / n;
        let mass = (0..nodes.len()).flat_map(|_| [m, m, m, i, i, i]).collect();
        let body = match yield_ {
            None => Body::Corotated {
                k: layers.elastic_stiffness(sec),
                reference,
                stress: ElasticStress::Shell { layers: Box::new(layers), sec: *sec },
            },
            Some(y) => {
                let material = J2 {
                    elastic: Elastic { e: sec.e, nu: sec.nu, rho: sec.rho },
                    sigma_y: y.sigma_y,
                    h: y.hardening,
                };
                let rule = ThicknessRule::gauss(y.points);
                Body::Layered {
                    reference,
                    shell: Box::new(LayeredJ2 { layers, material, rule, h: sec.h }),
                }
            }
        };
        Element { kind, nodes, body, mass, measure: area }
    }

    /// A 2-node beam; `up` fixes the local `y` axis (projected normal to the beam).
    pub fn beam2(
        nodes: [usize; 2],
        x0: &[Vector3<f64>; 2],
        up: Vector3<f64>,
        sec: &BeamSection,
    ) -> Self {
        let (reference, l, mass) = Self::beam_frame(x0, up, sec);
        let k = beam::stiffness(l, sec);
        Element {
            kind: ElementKind::Beam2,
            nodes: nodes.to_vec(),
            body: Body::Corotated { reference, k, stress: ElasticStress::Beam(*sec) },
            mass,
            measure: l,
        }
    }

    /// A 2-node beam of a J2 material by fibres (`beam::FibreBeam`); `up` as for `beam2`.
    pub fn beam2_j2(
        nodes: [usize; 2],
        x0: &[Vector3<f64>; 2],
        up: Vector3<f64>,
        sec: &BeamSection,
        yield_: BeamYield,
    ) -> Self {
        let (reference, l, mass) = Self::beam_frame(x0, up, sec);
        Element {
            kind: ElementKind::Beam2,
            nodes: nodes.to_vec(),
            body: Body::Fibred { reference, beam: Box::new(FibreBeam::new(l, *sec, yield_)) },
            mass,
            measure: l,
        }
    }

    /// The corotated reference, length and lumped mass of a beam.
    fn beam_frame(
        x0: &[Vector3<f64>; 2],
        up: Vector3<f64>,
        sec: &BeamSection,
    ) -> (Reference, f64, Vec<f64>) {
        let chord = x0[1] - x0[0];
        let l = chord.norm();
        let e1 = chord / l;
        let q0 = (up - up.dot(&e1) * e1).normalize();
        let reference = Reference::new(FrameRule::Beam { q0: [q0.x, q0.y, q0.z] }, x0);
        let m = sec.rho * sec.area * l / 2.0;
        // section inertia (torsion, y, z) rotated to global, diagonal kept
        let local = Matrix3::from_diagonal(&Vector3::new(sec.iy + sec.iz, sec.iy, sec.iz))
            * (sec.rho * l / 2.0);
        let g = reference.e0 * local * reference.e0.transpose();
        let mass = (0..2).flat_map(|_| [m, m, m, g[(0, 0)], g[(1, 1)], g[(2, 2)]]).collect();
        (reference, l, mass)
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
        !matches!(self.body, Body::Tet(_))
    }

    /// Length of the element's material state array (0 for elastic shells and beams).
    pub fn n_state(&self) -> usize {
        match &self.body {
            Body::Corotated { .. } => 0,
            Body::Layered { shell, .. } => shell.n_state(),
            Body::Fibred { beam, .. } => beam.n_state(),
            Body::Tet(_) => TET_STATE,
        }
    }

    /// Internal force (6 per node, global) at nodal positions `x` and rotations `r` from the
    /// committed material state `old` (`n_state` values); writes the trial state into `new`.
    pub fn force(
        &self,
        x: &[Vector3<f64>],
        r: &[Matrix3<f64>],
        old: &[f64],
        new: &mut [f64],
        f: &mut [f64],
    ) {
        let mut d = [0.0; 24];
        let nd = 6 * x.len();
        match &self.body {
            Body::Corotated { reference, k, .. } => {
                // fl = K d as a sum of contiguous columns of K (column-major storage)
                let local = |d: &[f64], fl: &mut [f64]| {
                    fl.fill(0.0);
                    for (col, &dj) in k.as_slice().chunks_exact(nd).zip(d) {
                        for (o, kij) in fl.iter_mut().zip(col) {
                            *o += kij * dj;
                        }
                    }
                };
                reference.force(x, r, &mut d[..nd], local, f);
            }
            Body::Layered { reference, shell } => {
                let local = |d: &[f64], fl: &mut [f64]| shell.force(d, old, new, fl, None);
                reference.force(x, r, &mut d[..nd], local, f);
            }
            Body::Fibred { reference, beam } => {
                let local = |d: &[f64], fl: &mut [f64]| beam.force(d, old, new, fl, None);
                reference.force(x, r, &mut d[..nd], local, f);
            }
            Body::Tet(t) => {
                let xs = [x[0], x[1], x[2], x[3]];
                let state = J2State3d { eps_p: std::array::from_fn(|i| old[i]), alpha: old[6] };
                let (fa, trial) = t.force(&xs, &state);
                new[..6].copy_from_slice(&trial.eps_p);
                new[6] = trial.alpha;
                f.fill(0.0);
                for a in 0..4 {
                    f[6 * a..6 * a + 3].copy_from_slice(fa[a].as_slice());
                }
            }
        }
    }

    /// Local deformational displacements `d` of a corotated element (None for tets).
    pub fn deformation(&self, x: &[Vector3<f64>], r: &[Matrix3<f64>]) -> Option<Vec<f64>> {
        match &self.body {
            Body::Corotated { reference, .. }
            | Body::Layered { reference, .. }
            | Body::Fibred { reference, .. } => {
                let mut d = vec![0.0; 6 * x.len()];
                reference.deformation(x, r, &mut d, None);
                Some(d)
            }
            Body::Tet(_) => None,
        }
    }

    /// Largest von Mises stress of the element at nodal positions `x` and rotations `r` with
    /// the committed material `state`: shells, the largest over the in-plane points and the
    /// thickness points (J2, `LayeredJ2::von_mises`) or the bottom, mid and top surfaces
    /// (elastic, `Layers::von_mises`), in-plane stresses only; beams, the largest axial plus
    /// bending stress `|N|/A + |M_y| c_z/I_y + |M_z| c_y/I_z` at the two ends, `c` the corner
    /// distances of the rectangle with the section's `A`, `I_y`, `I_z` (exact for rectangular
    /// sections; torsion left out), J2 beams the largest `|σ|` of their fibres; tets, of the Cauchy stress (`Tet4::von_mises`).
    pub fn von_mises(&self, x: &[Vector3<f64>], r: &[Matrix3<f64>], state: &[f64]) -> f64 {
        let local = || self.deformation(x, r).unwrap_or_default();
        match &self.body {
            Body::Corotated { stress: ElasticStress::Shell { layers, sec }, .. } => {
                layers.von_mises(&local(), sec)
            }
            Body::Corotated { stress: ElasticStress::Beam(sec), k, .. } => {
                if sec.area <= 0.0 {
                    return 0.0;
                }
                let fl = k * nalgebra::DVector::from_vec(local());
                // |M| c / I with c the half-width of the equivalent rectangle (c² = 3 I / A)
                let bending = |m: f64, i: f64| {
                    if i > 0.0 {
                        m.abs() * (3.0 * i / sec.area).sqrt() / i
                    } else {
                        0.0
                    }
                };
                let axial = fl[6].abs() / sec.area;
                [0, 6]
                    .map(|o| axial + bending(fl[o + 4], sec.iy) + bending(fl[o + 5], sec.iz))
                    .into_iter()
                    .fold(0.0, f64::max)
            }
            Body::Layered { shell, .. } => shell.von_mises(&local(), state),
            Body::Fibred { beam, .. } => beam.von_mises(&local(), state),
            Body::Tet(t) => {
                let xs = [x[0], x[1], x[2], x[3]];
                let st = J2State3d { eps_p: std::array::from_fn(|i| state[i]), alpha: state[6] };
                t.von_mises(&xs, &st)
            }
        }
    }

    /// Tangent `∂f/∂q` (with `extra`, a configuration-dependent load term `-f_ext`
    /// differentiated with it). Corotated shells and beams: the consistent tangent
    /// `Bᵀ K_l B + K_G` of `Reference::tangent`, `K_l` the elastic stiffness or the algorithmic
    /// tangent of the J2 sections; tets: central differences of `force`
    /// (`tangent_by_differences`). The load term (positions only) by central differences.
    pub fn tangent(
        &self,
        x: &[Vector3<f64>],
        r: &[Matrix3<f64>],
        state: &[f64],
        extra: Option<&LoadFn>,
    ) -> DMatrix<f64> {
        let size = 6 * x.len();
        let (reference, fl, kl, d, b, fr) = match &self.body {
            Body::Tet(_) => return self.tangent_by_differences(x, r, state, extra),
            Body::Corotated { reference, k, .. } => {
                let mut d = vec![0.0; size];
                let mut b = DMatrix::zeros(size, size);
                let fr = reference.deformation(x, r, &mut d, Some(&mut b));
                let fl = k * nalgebra::DVector::from_column_slice(&d);
                (reference, fl.as_slice().to_vec(), std::borrow::Cow::Borrowed(k), d, b, fr)
            }
            Body::Layered { reference, shell } => {
                let mut d = vec![0.0; size];
                let mut b = DMatrix::zeros(size, size);
                let fr = reference.deformation(x, r, &mut d, Some(&mut b));
                let mut fl = vec![0.0; size];
                let mut kl = DMatrix::zeros(size, size);
                let mut trial = vec![0.0; state.len()];
                shell.force(&d, state, &mut trial, &mut fl, Some(&mut kl));
                (reference, fl, std::borrow::Cow::Owned(kl), d, b, fr)
            }
            Body::Fibred { reference, beam } => {
                let mut d = vec![0.0; size];
                let mut b = DMatrix::zeros(size, size);
                let fr = reference.deformation(x, r, &mut d, Some(&mut b));
                let mut fl = vec![0.0; size];
                let mut kl = DMatrix::zeros(size, size);
                let mut trial = vec![0.0; state.len()];
                beam.force(&d, state, &mut trial, &mut fl, Some(&mut kl));
                (reference, fl, std::borrow::Cow::Owned(kl), d, b, fr)
            }
        };
        let mut kt = reference.tangent(x, r, &d, &b, &fr, &fl, &kl);
        if let Some(load) = extra {
            Self::add_load_tangent(x, load, &mut kt);
        }
        kt
    }

    /// Adds `-∂f_ext/∂x` of a load of the positions by central differences.
    fn add_load_tangent(x: &[Vector3<f64>], load: &LoadFn, kt: &mut DMatrix<f64>) {
        let size = 6 * x.len();
        let (mut fp, mut fm) = (vec![0.0; size], vec![0.0; size]);
        let r = vec![Matrix3::identity(); x.len()];
        Self::perturb(x, &r, false, |xs, _, col, h| {
            if h > 0.0 {
                load(xs, &mut fp);
            } else {
                load(xs, &mut fm);
                for i in 0..size {
                    kt[(i, col)] -= (fp[i] - fm[i]) / (-2.0 * h);
                }
            }
        });
    }

    /// The tangent by central differences of `force` (and of `extra`): translations and
    /// spatial spins, exactly as `Model::apply_increment` composes them; `FD_STEP` relative.
    /// The check of the consistent tangent, and the tangent of tets.
    pub fn tangent_by_differences(
        &self,
        x: &[Vector3<f64>],
        r: &[Matrix3<f64>],
        state: &[f64],
        extra: Option<&LoadFn>,
    ) -> DMatrix<f64> {
        let size = 6 * x.len();
        let mut kt = DMatrix::zeros(size, size);
        let (mut fp, mut fm) = (vec![0.0; size], vec![0.0; size]);
        let mut trial = vec![0.0; state.len()];
        let mut tmp = vec![0.0; size];
        let mut eval = |xs: &[Vector3<f64>], rs: &[Matrix3<f64>], out: &mut [f64]| {
            self.force(xs, rs, state, &mut trial, out);
            if let Some(g) = extra {
                g(xs, &mut tmp);
                for (o, t) in out.iter_mut().zip(&tmp) {
                    *o -= t;
                }
            }
        };
        // each column is visited with +h, then -h
        Self::perturb(x, r, self.has_rotations(), |xs, rs, col, h| {
            if h > 0.0 {
                eval(xs, rs, &mut fp);
            } else {
                eval(xs, rs, &mut fm);
                for i in 0..size {
                    kt[(i, col)] = (fp[i] - fm[i]) / (-2.0 * h);
                }
            }
        });
        kt
    }

    /// Calls `visit(x', r', column, step)` for each perturbed configuration of a
    /// central-difference tangent: translations moved by `±FD_STEP · size`, rotations by spatial
    /// spins `±FD_STEP`, `+` then `-` for each column; rotations only if `rotations`.
    fn perturb(
        x: &[Vector3<f64>],
        r: &[Matrix3<f64>],
        rotations: bool,
        mut visit: impl FnMut(&[Vector3<f64>], &[Matrix3<f64>], usize, f64),
    ) {
        let n = x.len();
        let scale = (1..n).map(|i| (x[i] - x[0]).norm()).fold(0.0, f64::max).max(1e-300);
        let (mut xp, mut rp) = (x.to_vec(), r.to_vec());
        for j in 0..n {
            for c in 0..6 {
                if c >= 3 && !rotations {
                    continue;
                }
                let h = if c < 3 { FD_STEP * scale } else { FD_STEP };
                for sign in [1.0, -1.0] {
                    let s = sign * h;
                    if c < 3 {
                        xp[j][c] = x[j][c] + s;
                    } else {
                        let mut w = Vector3::zeros();
                        w[c - 3] = s;
                        rp[j] = exp(&w) * r[j];
                    }
                    visit(&xp, &rp, 6 * j + c, s);
                    xp[j] = x[j];
                    rp[j] = r[j];
                }
            }
        }
    }

    /// Largest eigenvalue of `M⁻¹ K` at the initial configuration (power iteration on the
    /// element; bounds the assembled one, Irons 1970), for the critical time step.
    pub fn max_frequency_squared(&self, x0: &[Vector3<f64>], rot_mass: &[f64]) -> f64 {
        let n = x0.len();
        let ident = vec![Matrix3::identity(); n];
        let k = self.tangent(x0, &ident, &vec![0.0; self.n_state()], None);
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
