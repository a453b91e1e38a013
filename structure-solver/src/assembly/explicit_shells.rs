//! The explicit one-point shells of a model: BT4 on the quadrilaterals and BLT3 on the
//! triangles of `Part::Bt4` cells, in one explicit step. Both read the end positions and the
//! step's increment (translations and summed spins since the last commit) in the layout they
//! share, add their forces in a fixed order (quadrilaterals, then triangles: bitwise
//! independent of the thread count), and give their own bound of the critical step.

use nalgebra::Vector3;

use super::State;
use crate::elements::blt3::{Blt3, Blt3State};
use crate::elements::bt4::{Bt4, Bt4State};
use crate::elements::RotaryInertia;

/// The BT4 and BLT3 shells of a model with their work arrays.
#[derive(Debug, Clone)]
pub(super) struct ExplicitShells {
    pub quads: Option<Bt4>,
    pub triangles: Option<Blt3>,
    /// Positions and the increment since the last commit, in the layout the shells read.
    pub x: Vec<[f64; 3]>,
    pub du: Vec<f64>,
    /// A trial state was computed since the last commit or revert.
    pub evaluated: bool,
}

fn array(p: &Vector3<f64>) -> [f64; 3] {
    [p.x, p.y, p.z]
}

impl ExplicitShells {
    /// The shells at the reference positions `x0`; `None` when there are none.
    pub fn new(quads: Option<Bt4>, triangles: Option<Blt3>, x0: &[Vector3<f64>]) -> Option<Self> {
        if quads.is_none() && triangles.is_none() {
            return None;
        }
        Some(ExplicitShells {
            quads,
            triangles,
            x: x0.iter().map(array).collect(),
            du: vec![0.0; 6 * x0.len()],
            evaluated: false,
        })
    }

    /// Adds the internal forces of the step from `committed` to `trial` to `f`.
    pub fn internal_force(&mut self, trial: &State, committed: &State, f: &mut [f64]) {
        let (t, c) = (trial, committed);
        for n in 0..t.x.len() {
            let (dx, dw) = (t.x[n] - c.x[n], t.spin_sum[n] - c.spin_sum[n]);
            self.x[n] = array(&t.x[n]);
            self.du[6 * n..6 * n + 6].copy_from_slice(&[dx.x, dx.y, dx.z, dw.x, dw.y, dw.z]);
        }
        if let Some(q) = &mut self.quads {
            q.internal_force(&self.x, &self.du, f);
        }
        if let Some(t) = &mut self.triangles {
            t.internal_force(&self.x, &self.du, f);
        }
        self.evaluated = true;
    }

    /// Accepts the trial state of the last internal force, if any.
    pub fn commit(&mut self) {
        if self.evaluated {
            if let Some(q) = &mut self.quads {
                q.commit();
            }
            if let Some(t) = &mut self.triangles {
                t.commit();
            }
            self.evaluated = false;
        }
    }

    /// The smaller element bound of the critical step of the two families at the positions of
    /// their last internal force: BT4's geometric bound, BLT3's reference bound scaled by the
    /// change of shape.
    pub fn stable_dt(&self) -> f64 {
        let q = self.quads.as_ref().map_or(f64::INFINITY, |q| q.stable_dt(&self.x));
        let t = self.triangles.as_ref().map_or(f64::INFINITY, |t| t.scaled_stable_dt(&self.x));
        q.min(t)
    }

    /// Sets the rotary inertia, adds the lumped masses at `x0` to `mass` and takes `x0` as
    /// the triangles' reference of the step bound.
    pub fn set_rotary_inertia(
        &mut self,
        rotary: RotaryInertia,
        x0: &[Vector3<f64>],
        mass: &mut [f64],
    ) {
        let x0: Vec<[f64; 3]> = x0.iter().map(array).collect();
        if let Some(q) = &mut self.quads {
            q.settings.rotary = rotary;
            q.lumped_mass(&x0, mass);
        }
        if let Some(t) = &mut self.triangles {
            t.settings.rotary = rotary;
            t.lumped_mass(&x0, mass);
            t.set_reference(&x0);
        }
    }

    /// Appends a node at `p`.
    pub fn add_node(&mut self, p: &Vector3<f64>) {
        self.x.push(array(p));
        self.du.extend([0.0; 6]);
    }

    /// Restores a committed state at positions `x`; refuses states of other shells.
    pub fn restore(
        &mut self,
        quads: Option<Bt4State>,
        triangles: Option<Blt3State>,
        x: &[Vector3<f64>],
    ) -> Result<(), String> {
        let sizes = |s: &Bt4State| (s.stress.len(), s.alpha.len(), s.hourglass.len());
        let sizes3 = |s: &Blt3State| (s.stress.len(), s.alpha.len(), s.shear.len());
        match (&self.quads, &quads) {
            (Some(b), Some(s)) if sizes(b.state()) != sizes(s) => {
                return Err("a BT4 state of another mesh or thickness rule".into())
            }
            (Some(_), None) => return Err("the model has BT4 shells, the state has none".into()),
            (None, Some(_)) => return Err("the state has BT4 shells, the model has none".into()),
            _ => {}
        }
        match (&self.triangles, &triangles) {
            (Some(b), Some(s)) if sizes3(b.state()) != sizes3(s) => {
                return Err("a BLT3 state of another mesh or thickness rule".into())
            }
            (Some(_), None) => return Err("the model has BLT3 shells, the state has none".into()),
            (None, Some(_)) => return Err("the state has BLT3 shells, the model has none".into()),
            _ => {}
        }
        if let (Some(b), Some(s)) = (&mut self.quads, quads) {
            b.set_state(s);
        }
        if let (Some(b), Some(s)) = (&mut self.triangles, triangles) {
            b.set_state(s)?;
        }
        self.evaluated = false;
        // the configuration the shells' stable step reads
        for (b, p) in self.x.iter_mut().zip(x) {
            *b = array(p);
        }
        Ok(())
    }
}
