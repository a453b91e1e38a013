//! The model as the integrators and solvers call it (`Model`): increments, internal and
//! external forces, the tangent, the mass operators with their rigid and skew blocks, commit
//! and revert.

use faer::sparse::Triplet;
use nalgebra::Vector3;
use rayon::prelude::*;

use super::loads::pressure_force;
use super::{gather, FeModel};
use crate::model::{Model, Tangent};

impl Model for FeModel {
    fn n_nodes(&self) -> usize {
        self.x0.len()
    }

    fn lumped_mass(&self) -> &[f64] {
        &self.mass
    }

    fn constrained(&self) -> &[bool] {
        &self.constrained
    }

    fn prescribed(&self, t: f64, out: &mut [f64]) {
        for (d, &c) in self.constrained.iter().enumerate() {
            if c {
                out[d] = 0.0;
            }
        }
        for (d, v, c) in &self.prescribed {
            out[*d] = v * c.at(t);
        }
    }

    fn apply_increment(&mut self, du: &[f64]) {
        self.fint_valid = false;
        let expanded;
        let du = if self.skew.is_empty() {
            du
        } else {
            expanded = {
                let mut v = du.to_vec();
                self.expand_skew(&mut v);
                v
            };
            &expanded
        };
        let s = &mut self.trial;
        for n in 0..s.x.len() {
            if self.slave[n] {
                continue;
            }
            let d = &du[6 * n..6 * n + 6];
            s.x[n] += Vector3::new(d[0], d[1], d[2]);
            let w = Vector3::new(d[3], d[4], d[5]);
            if w != Vector3::zeros() {
                s.r[n] = crate::elements::rotation::exp(&w) * s.r[n];
                s.spin_sum[n] += w;
            }
        }
        if !self.rigid.is_empty() {
            self.place_slaves(du);
        }
    }

    fn internal_force(&mut self, f: &mut [f64]) {
        f.fill(0.0);
        self.element_forces(f);
        self.spring_forces(f);
        if let Some(b) = &mut self.explicit {
            b.internal_force(&self.trial, &self.committed, f);
        }
        if !self.rigid.is_empty() {
            self.fint_full.clear();
            self.fint_full.extend_from_slice(f);
            self.fint_valid = true;
            self.reduce_forces(f);
        }
        self.reduce_skew_forces(f);
    }

    fn external_force(&mut self, t: f64, f: &mut [f64]) {
        self.external_force_with(t, None, f);
    }

    /// Every load (the case's, the coupling's `extra`) gathered per node, then reduced once:
    /// skew-plane nodes to their plane, rigid slaves to their master.
    fn external_force_with(&mut self, t: f64, extra: Option<&[f64]>, f: &mut [f64]) {
        self.hold_extra(extra);
        self.external_unreduced(t, f);
        self.reduce_skew_forces(f);
        if self.rigid.is_empty() {
            return;
        }
        if let Some((g, c)) = &self.gravity {
            // the weight of extra masses, at their centres
            let s = c.at(t);
            for b in &self.rigid {
                let (mass, arm) = b.extra_weight(&self.trial.r[b.master]);
                if mass > 0.0 {
                    let w = Vector3::from(*g) * (mass * s);
                    let moment = arm.cross(&w);
                    for k in 0..3 {
                        f[6 * b.master + k] += w[k];
                        f[6 * b.master + 3 + k] += moment[k];
                    }
                }
            }
        }
        self.reduce_forces(f);
    }

    /// Tangent of internal minus external force, reduced by the rigid bodies.
    fn tangent(&mut self, t: f64, out: &mut Tangent) {
        self.element_tangent(t, out);
        self.spring_tangent(out);
        if !self.rigid.is_empty() {
            self.reduce_tangent(t, out);
        }
        if !self.skew.is_empty() {
            self.reduce_skew_tangent(out);
        }
    }

    fn apply_inverse_mass(&self, f: &[f64], a: &mut [f64]) {
        let (m, c) = (&self.mass, &self.constrained);
        for (i, a) in a.iter_mut().enumerate() {
            *a = if c[i] || m[i] <= 0.0 { 0.0 } else { f[i] / m[i] };
        }
        for b in &self.rigid {
            let d = 6 * b.master;
            let am = b.inverse_mass(&self.trial.r[b.master], &c[d..d + 6], &f[d..d + 6]);
            a[d..d + 6].copy_from_slice(am.as_slice());
        }
        for k in &self.skew {
            let d = 6 * k.node;
            let mut mk = k.mass(&self.node_mass[d..d + 6]);
            let mut rhs = nalgebra::Vector6::from_column_slice(&f[d..d + 6]);
            for i in 0..6 {
                if c[d + i] || mk[(i, i)] <= 0.0 {
                    mk.row_mut(i).fill(0.0);
                    mk.column_mut(i).fill(0.0);
                    mk[(i, i)] = 1.0;
                    rhs[i] = 0.0;
                }
            }
            let ak = mk.cholesky().map_or(nalgebra::Vector6::zeros(), |ch| ch.solve(&rhs));
            a[d..d + 6].copy_from_slice(ak.as_slice());
        }
    }

    fn mass_product(&self, v: &[f64], out: &mut [f64]) {
        for ((o, m), v) in out.iter_mut().zip(&self.mass).zip(v) {
            *o = m * v;
        }
        for b in &self.rigid {
            let d = 6 * b.master;
            let vm = nalgebra::Vector6::from_column_slice(&v[d..d + 6]);
            let p = b.mass6(&self.trial.r[b.master]) * vm;
            out[d..d + 6].copy_from_slice(p.as_slice());
        }
        for k in &self.skew {
            let d = 6 * k.node;
            let vk = nalgebra::Vector6::from_column_slice(&v[d..d + 6]);
            let p = k.mass(&self.node_mass[d..d + 6]) * vk;
            out[d..d + 6].copy_from_slice(p.as_slice());
        }
    }

    fn nondiagonal_mass(&self, out: &mut Vec<Triplet<usize, usize, f64>>) {
        out.clear();
        for b in &self.rigid {
            let d = 6 * b.master;
            let m6 = b.mass6(&self.trial.r[b.master]);
            for i in 0..6 {
                for j in 0..6 {
                    let v = if i == j { m6[(i, j)] - self.mass[d + i] } else { m6[(i, j)] };
                    if v != 0.0 {
                        out.push(Triplet::new(d + i, d + j, v));
                    }
                }
            }
        }
        for k in &self.skew {
            let d = 6 * k.node;
            let mk = k.mass(&self.node_mass[d..d + 6]);
            for i in 0..6 {
                for j in 0..6 {
                    if i != j && mk[(i, j)] != 0.0 {
                        out.push(Triplet::new(d + i, d + j, mk[(i, j)]));
                    }
                }
            }
        }
    }

    fn explicit_drift(&self, dt: f64, v_half: &mut [f64], du: &mut [f64]) {
        let (x, r) = (&self.trial.x, &self.trial.r);
        for b in &self.rigid {
            let m = b.master;
            let d = 6 * m;
            let cons = &self.constrained[d..d + 6];
            let (dx, r1) = b.drift(&r[m], cons, dt, &mut v_half[d..d + 6], &du[d..d + 6]);
            let w = crate::elements::rotation::log(&(r1 * r[m].transpose()));
            du[d..d + 3].copy_from_slice(dx.as_slice());
            du[d + 3..d + 6].copy_from_slice(w.as_slice());
            let xm1 = x[m] + dx;
            for (k, &s) in b.slaves.iter().enumerate() {
                let dxs = b.slave(k, &xm1, &r1).0 - x[s];
                du[6 * s..6 * s + 3].copy_from_slice(dxs.as_slice());
                du[6 * s + 3..6 * s + 6].copy_from_slice(w.as_slice());
                for c in 0..6 {
                    v_half[6 * s + c] = du[6 * s + c] / dt;
                }
            }
        }
    }

    fn dependent_motion(&self, v: &mut [f64], a: &mut [f64]) {
        let x = &self.trial.x;
        let v3 = |v: &[f64], i: usize| Vector3::new(v[i], v[i + 1], v[i + 2]);
        for b in &self.rigid {
            let d = 6 * b.master;
            let (vm, w, am, al) = (v3(v, d), v3(v, d + 3), v3(a, d), v3(a, d + 3));
            for &s in &b.slaves {
                let r = x[s] - x[b.master];
                let vs = vm + w.cross(&r);
                let acc = am + al.cross(&r) + w.cross(&w.cross(&r));
                v[6 * s..6 * s + 3].copy_from_slice(vs.as_slice());
                v[6 * s + 3..6 * s + 6].copy_from_slice(w.as_slice());
                a[6 * s..6 * s + 3].copy_from_slice(acc.as_slice());
                a[6 * s + 3..6 * s + 6].copy_from_slice(al.as_slice());
            }
        }
        self.expand_skew(v);
        self.expand_skew(a);
    }

    fn commit(&mut self) {
        self.committed.clone_from(&self.trial);
        if let Some(b) = &mut self.explicit {
            b.commit();
        }
    }

    fn revert(&mut self) {
        self.fint_valid = false;
        self.trial.clone_from(&self.committed);
        if let Some(b) = &mut self.explicit {
            b.evaluated = false;
        }
    }

    fn has_tangent(&self) -> bool {
        self.explicit.is_none()
    }

    /// The topology version (`topology`): 1 as built, increased by every run-time change.
    fn topology_epoch(&self) -> u64 {
        self.topology.version
    }

    fn stable_dt(&self) -> f64 {
        self.current_stable_dt()
    }

    fn displacement(&self, out: &mut [[f64; 3]]) {
        for (n, o) in out.iter_mut().enumerate() {
            let d = self.trial.x[n] - self.x0[n];
            *o = [d.x, d.y, d.z];
        }
    }
}

impl FeModel {
    /// The displacement as 6 values per node, rotations zero (the kinematics a coupled
    /// structure publishes).
    pub fn displacement_dofs(&self, out: &mut [f64]) {
        out.fill(0.0);
        for (n, o) in out.chunks_exact_mut(6).enumerate() {
            let d = self.trial.x[n] - self.x0[n];
            o[..3].copy_from_slice(&[d.x, d.y, d.z]);
        }
    }

    /// The tangent of the elements, one block each, computed in parallel in place; explicit
    /// shells add nothing (`has_tangent` is then `false`).
    pub(super) fn element_tangent(&mut self, t: f64, out: &mut Tangent) {
        out.entries.clear(); // the blocks are all replaced
        let pc = self.cell_pressure(t);
        let pe: Vec<f64> = self.element_cell.iter().map(|&c| pc[c]).collect();
        let dofs = self
            .elements
            .iter()
            .map(|e| e.nodes.iter().flat_map(|&n| (0..6).map(move |c| 6 * n + c)));
        let mut blocks = out.set_blocks(dofs);
        let s = &self.trial;
        let committed = &self.committed.material;
        blocks.par_iter_mut().zip(&self.elements).enumerate().for_each(|(ei, (block, e))| {
            let x = gather(&s.x, &e.nodes);
            let r = gather(&s.r, &e.nodes);
            let st = &committed[self.state_offsets[ei]..self.state_offsets[ei + 1]];
            let k = if pe[ei] != 0.0 {
                let p = pe[ei];
                let load = move |xs: &[Vector3<f64>], o: &mut [f64]| pressure_force(p, xs, o);
                e.tangent(&x, &r, st, Some(&load))
            } else {
                e.tangent(&x, &r, st, None)
            };
            block.copy_from_slice(k.as_slice());
        });
    }
}
