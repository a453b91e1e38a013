//! The committed state of a model as checkpoints hold it, and its restoration.

use nalgebra::{Matrix3, Vector3};

use super::FeModel;

impl FeModel {
    /// Restores a committed state (configuration, accumulated spins, the material state of
    /// the elements as `element_state` reads it, concatenated, and the BT4 state) and commits
    /// it, so that a run resumes bitwise; refuses arrays of another model.
    pub fn restore_committed(
        &mut self,
        x: &[Vector3<f64>],
        r: &[Matrix3<f64>],
        spins: &[Vector3<f64>],
        material: &[f64],
        bt4: Option<crate::elements::bt4::Bt4State>,
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
        match (&mut self.bt4, bt4) {
            (Some(b), Some(s)) => {
                let have = b.shells.state();
                if (s.stress.len(), s.alpha.len(), s.hourglass.len())
                    != (have.stress.len(), have.alpha.len(), have.hourglass.len())
                {
                    return Err("a BT4 state of another mesh or thickness rule".into());
                }
                b.shells.set_state(s);
                b.evaluated = false;
                // the configuration the shells' stable step reads
                for (b, p) in b.x.iter_mut().zip(x) {
                    *b = [p.x, p.y, p.z];
                }
            }
            (None, None) => {}
            (Some(_), None) => return Err("the model has BT4 shells, the state has none".into()),
            (None, Some(_)) => return Err("the state has BT4 shells, the model has none".into()),
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
