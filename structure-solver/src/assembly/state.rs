//! The committed state of a model as checkpoints hold it, and its restoration.

use nalgebra::{Matrix3, Vector3};

use super::FeModel;

impl FeModel {
    /// Restores a committed state (configuration, accumulated spins, the material state of
    /// the elements as `element_state` reads it, concatenated, and the BT4 and BLT3 states) and commits
    /// it, so that a run resumes bitwise; refuses arrays of another model.
    pub fn restore_committed(
        &mut self,
        x: &[Vector3<f64>],
        r: &[Matrix3<f64>],
        spins: &[Vector3<f64>],
        material: &[f64],
        bt4: Option<crate::elements::bt4::Bt4State>,
        blt3: Option<crate::elements::blt3::Blt3State>,
    ) -> Result<(), String> {
        let nn = self.x0.len();
        if x.len() != nn || r.len() != nn || spins.len() != nn {
            return Err(format!("a configuration of another mesh ({} nodes, not {nn})", x.len()));
        }
        if material.len() != self.committed.material.len() {
            return Err(format!(
                "{} material state values, the model holds {}",
                material.len(),
                self.committed.material.len()
            ));
        }
        match &mut self.explicit {
            Some(b) => b.restore(bt4, blt3, x)?,
            None if bt4.is_some() || blt3.is_some() => {
                return Err("the state has explicit shells, the model has none".into())
            }
            None => {}
        }
        let s = &mut self.trial;
        s.x.copy_from_slice(x);
        s.r.copy_from_slice(r);
        s.spin_sum.copy_from_slice(spins);
        s.material.copy_from_slice(material);
        self.committed.clone_from(&self.trial);
        self.fint_valid = false;
        Ok(())
    }
}
