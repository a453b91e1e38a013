//! Loads: time curves, point loads, gravity, follower pressure on shells and on the boundary
//! faces of solids, and the external nodal array the coupling fills; all of them gathered
//! unreduced per node, then reduced once by the constraints (`forces`).

use nalgebra::Vector3;

use super::{AssemblyError, FeModel};

/// A scalar function of time multiplying a load or a prescribed value.
#[derive(Debug, Clone, PartialEq)]
pub enum Curve {
    /// 1 at all times.
    Constant,
    /// `t` (a static load factor).
    Linear,
    /// Piecewise linear through `(t, value)` points, constant outside.
    Table(Vec<(f64, f64)>),
}

impl Curve {
    pub fn at(&self, t: f64) -> f64 {
        match self {
            Curve::Constant => 1.0,
            Curve::Linear => t,
            Curve::Table(p) => {
                if p.is_empty() {
                    return 0.0;
                }
                if t <= p[0].0 {
                    return p[0].1;
                }
                for w in p.windows(2) {
                    if t <= w[1].0 {
                        let s = (t - w[0].0) / (w[1].0 - w[0].0);
                        return w[0].1 + s * (w[1].1 - w[0].1);
                    }
                }
                p[p.len() - 1].1
            }
        }
    }
}

impl FeModel {
    /// A point load (or moment) `value · curve(t)` on dof `c` of `node`.
    pub fn point_load(&mut self, node: usize, c: usize, value: f64, curve: Curve) {
        self.point_loads.push((6 * node + c, value, curve));
    }

    /// Follower pressure `p · curve(t)` on shell cells `cells`, acting along the normal of the
    /// right-hand rule of each cell's node order.
    pub fn pressure(&mut self, cells: &[usize], p: f64, curve: Curve) {
        self.pressures.push((cells.to_vec(), p, curve));
    }

    /// Gravity acceleration `g · curve(t)`.
    pub fn gravity(&mut self, g: [f64; 3], curve: Curve) {
        self.gravity = Some((g, curve));
    }

    /// Follower pressure `p · curve(t)` on boundary faces of solids: each face `[a, b, c]`
    /// counter-clockwise seen from outside (`wet::tet_boundary` orders them so), pushed
    /// into the solid by `-p A n` shared equally by its three nodes, `A n` its current
    /// area vector. Faces naming a node outside the model are refused.
    pub fn face_pressure(
        &mut self,
        faces: &[[usize; 3]],
        p: f64,
        curve: Curve,
    ) -> Result<(), AssemblyError> {
        let nn = self.x0.len();
        if let Some(&node) = faces.iter().flatten().find(|&&n| n >= nn) {
            return Err(AssemblyError::NodeRange { node, n: nn });
        }
        self.face_pressures.push((faces.to_vec(), p, curve));
        Ok(())
    }

    /// The external nodal load array (6 per node) the coupled participant fills; added to the
    /// external force at every `t` as it is.
    pub fn external_loads_mut(&mut self) -> &mut [f64] {
        &mut self.external
    }

    /// Total pressure on each mesh cell at time `t`.
    pub(super) fn cell_pressure(&self, t: f64) -> Vec<f64> {
        let mut p = vec![0.0; self.cells.len()];
        for (cells, v, c) in &self.pressures {
            let s = v * c.at(t);
            for &e in cells {
                p[e] += s;
            }
        }
        p
    }

    /// Keeps the nodal load from outside the model for the external forces that follow
    /// (`None`: there is none).
    pub(super) fn hold_extra(&mut self, extra: Option<&[f64]>) {
        self.held_extra.clear();
        if let Some(x) = extra {
            self.held_extra.extend_from_slice(x);
        }
    }

    /// External force before the rigid and skew reduction (loads on every node as given,
    /// the held load from outside the model included).
    pub(super) fn external_unreduced(&self, t: f64, f: &mut [f64]) {
        f.copy_from_slice(&self.external);
        for (f, x) in f.iter_mut().zip(&self.held_extra) {
            *f += x;
        }
        for (d, v, c) in &self.point_loads {
            f[*d] += v * c.at(t);
        }
        if let Some((g, c)) = &self.gravity {
            let s = c.at(t);
            for n in 0..self.x0.len() {
                for k in 0..3 {
                    f[6 * n + k] += self.node_mass[6 * n + k] * g[k] * s;
                }
            }
        }
        let pc = if self.pressures.is_empty() { vec![] } else { self.cell_pressure(t) };
        let (mut fe, mut xe) = ([0.0; 24], [Vector3::zeros(); 4]);
        for (p, nodes) in pc.iter().zip(&self.cells) {
            if *p != 0.0 {
                let k = nodes.len();
                for (x, &n) in xe.iter_mut().zip(nodes) {
                    *x = self.trial.x[n];
                }
                pressure_force(*p, &xe[..k], &mut fe[..6 * k]);
                for (i, &n) in nodes.iter().enumerate() {
                    for c in 0..3 {
                        f[6 * n + c] += fe[6 * i + c];
                    }
                }
            }
        }
        let x = &self.trial.x;
        for (faces, p, c) in &self.face_pressures {
            let s = p * c.at(t) / 3.0;
            if s == 0.0 {
                continue;
            }
            for &[a, b, d] in faces {
                let push = -0.5 * s * (x[b] - x[a]).cross(&(x[d] - x[a]));
                for n in [a, b, d] {
                    for k in 0..3 {
                        f[6 * n + k] += push[k];
                    }
                }
            }
        }
    }
}

/// Nodal forces of a uniform pressure `p` on a flat or warped polygon (the area vector shared
/// equally among the nodes).
pub(super) fn pressure_force(p: f64, x: &[Vector3<f64>], out: &mut [f64]) {
    let a = if x.len() == 4 {
        0.5 * (x[2] - x[0]).cross(&(x[3] - x[1]))
    } else {
        0.5 * (x[1] - x[0]).cross(&(x[2] - x[0]))
    };
    let f = a * (p / x.len() as f64);
    out.fill(0.0);
    for i in 0..x.len() {
        out[6 * i..6 * i + 3].copy_from_slice(f.as_slice());
    }
}
