//! The element bound of the critical step of central differences at the current
//! configuration (`Model::stable_dt`, checked against the assembled estimates in
//! `time::critical`). Each element's `2/ω_e` (Irons' element bound) is computed once at the
//! reference configuration; every step it is scaled by how the element's characteristic
//! length changed, `ρ = L(x)/L(X)`: by `ρ` for tets (a wave speed over a length), by
//! `min(ρ, ρ²)` for shells and beams (their bending frequencies go as `1/L²`), so a shrinking
//! element shortens the step. The explicit shells give their own (`ExplicitShells::stable_dt`),
//! the springs theirs (`springs`: `2/ω` with the mass of the node they hold).

use nalgebra::Vector3;

use super::FeModel;
use crate::elements::ElementKind;

/// An element's step bound and characteristic length at the reference configuration.
#[derive(Debug, Clone, Copy)]
pub(super) struct ElementBound {
    pub(super) dt: f64,
    pub(super) length: f64,
}

/// The characteristic length of an element of `kind` with nodes at `x`: the smallest
/// altitude of a tet (`3V / max face area`) or a triangle (`2A / max side`), a quadrilateral's
/// area over its longer diagonal, a beam's length.
pub(super) fn characteristic_length(kind: ElementKind, x: &[Vector3<f64>]) -> f64 {
    match kind {
        ElementKind::Tet4 => {
            let v = (x[1] - x[0]).cross(&(x[2] - x[0])).dot(&(x[3] - x[0])).abs() / 6.0;
            let face =
                |a: usize, b: usize, c: usize| 0.5 * (x[b] - x[a]).cross(&(x[c] - x[a])).norm();
            let amax = face(1, 2, 3).max(face(0, 2, 3)).max(face(0, 1, 3)).max(face(0, 1, 2));
            3.0 * v / amax
        }
        ElementKind::Tri3 => {
            let a = 0.5 * (x[1] - x[0]).cross(&(x[2] - x[0])).norm();
            let side = (x[1] - x[0]).norm().max((x[2] - x[1]).norm()).max((x[0] - x[2]).norm());
            2.0 * a / side
        }
        ElementKind::Quad4 => {
            let (d1, d2) = (x[2] - x[0], x[3] - x[1]);
            0.5 * d1.cross(&d2).norm() / d1.norm().max(d2.norm())
        }
        ElementKind::Beam2 => (x[1] - x[0]).norm(),
    }
}

impl FeModel {
    /// The element bound of the critical step at the current configuration (the trial
    /// positions; explicit shells at the positions of their last internal force).
    pub(super) fn current_stable_dt(&self) -> f64 {
        let x = &self.trial.x;
        let mut dt = f64::INFINITY;
        for (e, b) in self.elements.iter().zip(&self.element_bound) {
            if !b.dt.is_finite() {
                continue;
            }
            let mut p = [Vector3::zeros(); 4];
            for (p, &n) in p.iter_mut().zip(&e.nodes) {
                *p = x[n];
            }
            let rho = characteristic_length(e.kind, &p[..e.nodes.len()]) / b.length;
            let scale = match e.kind {
                ElementKind::Tet4 => rho,
                _ => rho.min(rho * rho),
            };
            dt = dt.min(b.dt * scale);
        }
        if let Some(b) = &self.explicit {
            dt = dt.min(b.stable_dt());
        }
        dt.min(self.spring_stable_dt())
    }
}
