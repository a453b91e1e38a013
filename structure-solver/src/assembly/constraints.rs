//! Constraints on dofs: fixed and prescribed dofs, symmetry planes normal to a global axis,
//! and skew symmetry planes (a linear constraint per node, reduced as `Tᵀ f`, `Tᵀ K T`,
//! `Tᵀ M T`, increments expanded by `T`).

use crate::linsolve::{Expansion, Tangent, MAX_EXPANSION};
use nalgebra::{Matrix3, Vector3};

use super::{AssemblyError, Curve, FeModel};

/// The linear constraints of skew symmetry planes at one node (`FeModel::symmetry_plane`):
/// each plane of normal `n` asks `u·n = 0` and `θ·a = θ·b = 0` (`a`, `b` spanning the plane),
/// fixed dofs ask their component to vanish. Gauss-Jordan elimination of these rows picks
/// dependent dofs (pivots) and writes the node's dofs as `u = T q`, `q` its independent dofs
/// (the node's own global components, so velocities and loads keep their meaning): the
/// reduction `Tᵀ f`, `Tᵀ K T`, `Tᵀ M T` of the rigid bodies, per node.
#[derive(Debug, Clone)]
pub(super) struct SkewNode {
    pub(super) node: usize,
    pub(super) normals: Vec<Vector3<f64>>,
    /// The node's constrained flags before its first plane.
    pub(super) base: [bool; 6],
    /// `T` (6x6, node dofs); columns of dependent dofs are zero.
    pub(super) t: nalgebra::Matrix6<f64>,
    pub(super) dependent: [bool; 6],
}

impl SkewNode {
    /// Eliminates the constraint rows of one 3-vector block (translations or rotations):
    /// returns the block of `T` and the dependent components.
    pub(super) fn eliminate(rows: &[Vector3<f64>]) -> (Matrix3<f64>, [bool; 3]) {
        let mut a: Vec<Vector3<f64>> = rows.iter().map(|r| r / r.norm()).collect();
        let mut pivots: Vec<(usize, usize)> = Vec::new();
        let mut used_rows = vec![false; a.len()];
        loop {
            // full pivoting over unused rows and free columns
            let mut best = (0.0, 0, 0);
            for (i, r) in a.iter().enumerate() {
                if used_rows[i] {
                    continue;
                }
                for c in 0..3 {
                    if !pivots.iter().any(|p| p.1 == c) && r[c].abs() > best.0 {
                        best = (r[c].abs(), i, c);
                    }
                }
            }
            if best.0 <= 1e-10 {
                break;
            }
            let (_, i, c) = best;
            used_rows[i] = true;
            let piv = a[i] / a[i][c];
            a[i] = piv;
            for (k, r) in a.iter_mut().enumerate() {
                if k != i {
                    let f = r[c];
                    *r -= f * piv;
                }
            }
            pivots.push((i, c));
        }
        let mut t = Matrix3::identity();
        let mut dep = [false; 3];
        for &(i, c) in &pivots {
            dep[c] = true;
            // u_c + Σ_j a_ij u_j = 0 over the independent j
            for j in 0..3 {
                t[(c, j)] = if j == c { 0.0 } else { -a[i][j] };
            }
        }
        for &(_, c) in &pivots {
            for r in 0..3 {
                t[(r, c)] = 0.0;
            }
        }
        (t, dep)
    }

    /// Rebuilds `T` from the planes and the node's fixed dofs.
    pub(super) fn rebuild(&mut self, fixed: &[bool]) {
        let mut tr: Vec<Vector3<f64>> = self.normals.clone();
        let mut rot = Vec::new();
        for n in &self.normals {
            let k = n.iamin();
            let a = n.cross(&Vector3::ith(k, 1.0)).normalize();
            rot.push(a);
            rot.push(n.cross(&a));
        }
        for c in 0..3 {
            if fixed[c] {
                tr.push(Vector3::ith(c, 1.0));
            }
            if fixed[3 + c] {
                rot.push(Vector3::ith(c, 1.0));
            }
        }
        let (tt, dt) = Self::eliminate(&tr);
        let (trr, dr) = Self::eliminate(&rot);
        self.t = nalgebra::Matrix6::zeros();
        self.t.fixed_view_mut::<3, 3>(0, 0).copy_from(&tt);
        self.t.fixed_view_mut::<3, 3>(3, 3).copy_from(&trr);
        self.dependent = [dt[0], dt[1], dt[2], dr[0], dr[1], dr[2]];
    }

    /// The reduced 6x6 mass block `Tᵀ diag(m) T` of the node (`m` its six lumped masses).
    pub(super) fn mass(&self, m: &[f64]) -> nalgebra::Matrix6<f64> {
        let d = nalgebra::Matrix6::from_diagonal(&nalgebra::Vector6::from_column_slice(m));
        self.t.transpose() * d * self.t
    }
}

impl FeModel {
    /// Holds dofs `mask` (`[ux, uy, uz, θx, θy, θz]`) of `nodes` at zero.
    pub fn fix(&mut self, nodes: &[usize], mask: [bool; 6]) {
        for &n in nodes {
            for c in 0..6 {
                if mask[c] {
                    self.constrained[6 * n + c] = true;
                    self.user_fixed[6 * n + c] = true;
                }
            }
            if let Some(k) = self.skew_of[n] {
                self.rebuild_skew(k);
            }
        }
    }

    /// Symmetry about the plane normal to global axis `axis` (0, 1, 2): `u·n = 0` and
    /// rotation only about `n`.
    pub fn symmetry(&mut self, nodes: &[usize], axis: usize) {
        let mut mask = [false; 6];
        mask[axis] = true;
        mask[3 + (axis + 1) % 3] = true;
        mask[3 + (axis + 2) % 3] = true;
        self.fix(nodes, mask);
    }

    /// Symmetry about the plane of unit `normal` (any direction; normalised here) through
    /// `nodes`: `u·n = 0` and rotation only about `n`. Axis-aligned normals at nodes without a
    /// skew plane fix dofs as `symmetry` does; others constrain the node's dofs linearly
    /// (`SkewNode`: dependent dofs marked constrained, forces, tangent and mass reduced by
    /// the node's `T`, increments and dependent velocities expanded by it), so every solver
    /// respects them. A node may lie on several planes and have fixed dofs (fix before or
    /// after); it may not belong to a rigid body or carry a prescribed dof.
    pub fn symmetry_plane(
        &mut self,
        nodes: &[usize],
        normal: [f64; 3],
    ) -> Result<(), AssemblyError> {
        let n = Vector3::from(normal);
        let len = n.norm();
        if !len.is_finite() || len == 0.0 {
            return Err(AssemblyError::BadNormal { normal });
        }
        let n = n / len;
        let nn = self.x0.len();
        for &node in nodes {
            if node >= nn {
                return Err(AssemblyError::NodeRange { node, n: nn });
            }
            if self.body_of[node].is_some() {
                return Err(AssemblyError::SymmetryRigid { node });
            }
            if self.prescribed.iter().any(|p| p.0 / 6 == node) {
                return Err(AssemblyError::SymmetryPrescribed { node });
            }
        }
        let axis = (0..3).find(|&a| n[a].abs() == 1.0);
        for &node in nodes {
            match (axis, self.skew_of[node]) {
                (Some(a), None) => self.symmetry(&[node], a),
                (_, Some(k)) => {
                    self.skew[k].normals.push(n);
                    self.rebuild_skew(k);
                }
                (None, None) => {
                    let d = 6 * node;
                    let mut base = [false; 6];
                    base.copy_from_slice(&self.constrained[d..d + 6]);
                    self.skew_of[node] = Some(self.skew.len());
                    self.skew.push(SkewNode {
                        node,
                        normals: vec![n],
                        base,
                        t: nalgebra::Matrix6::identity(),
                        dependent: [false; 6],
                    });
                    self.rebuild_skew(self.skew.len() - 1);
                }
            }
        }
        self.reduce_mass();
        Ok(())
    }

    /// Recomputes skew node `k`'s `T` and its constrained flags.
    pub(super) fn rebuild_skew(&mut self, k: usize) {
        let s = &mut self.skew[k];
        let d = 6 * s.node;
        s.rebuild(&self.user_fixed[d..d + 6]);
        for c in 0..6 {
            self.constrained[d + c] = s.base[c] || self.user_fixed[d + c] || s.dependent[c];
        }
    }

    /// `f ← Tᵀ f` at the skew symmetry nodes.
    pub(super) fn reduce_skew_forces(&self, f: &mut [f64]) {
        for k in &self.skew {
            let d = 6 * k.node;
            let r = k.t.transpose() * nalgebra::Vector6::from_column_slice(&f[d..d + 6]);
            f[d..d + 6].copy_from_slice(r.as_slice());
        }
    }

    /// `v ← T v` at the skew symmetry nodes (dependent dofs from the independent ones).
    pub(super) fn expand_skew(&self, v: &mut [f64]) {
        for k in &self.skew {
            let d = 6 * k.node;
            let r = k.t * nalgebra::Vector6::from_column_slice(&v[d..d + 6]);
            v[d..d + 6].copy_from_slice(r.as_slice());
        }
    }

    /// `K ← Tᵀ K T` on triplets at the skew symmetry nodes (`T` is constant: no geometric
    /// term).
    pub(super) fn reduce_skew_tangent(&self, k: &mut Tangent) {
        let expand = |d: usize| -> Expansion {
            let (n, c) = (d / 6, d % 6);
            let mut out = [(d, 1.0); MAX_EXPANSION];
            let Some(s) = self.skew_of[n] else { return (out, 1) };
            let t = &self.skew[s].t;
            let mut len = 0;
            for j in 0..6 {
                if t[(c, j)] != 0.0 {
                    out[len] = (6 * n + j, t[(c, j)]);
                    len += 1;
                }
            }
            (out, len)
        };
        k.reduce(|d| self.skew_of[d / 6].is_some(), expand);
    }

    /// Prescribes dof `c` of `nodes` to `value · curve(t)`.
    pub fn prescribe(&mut self, nodes: &[usize], c: usize, value: f64, curve: Curve) {
        for &n in nodes {
            self.constrained[6 * n + c] = true;
            self.user_fixed[6 * n + c] = true;
            self.prescribed.push((6 * n + c, value, curve.clone()));
        }
    }
}
