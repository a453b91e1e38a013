//! Checkpoints of the structure (DESIGN §6, §7): the model's configuration and element state and
//! the integrator's velocities and accelerations, as named arrays of an
//! `interface_protocol::io::checkpoint` file (`checkpoints/<tag>/structure.ckpt`).
//!
//! What each model holds: BT4 shells (`ShellModel`): committed positions, and per point the
//! stresses, equivalent plastic strain and hourglass stresses. MITC4/DKT/beam/tet models
//! (`FeModel`): positions, nodal rotation matrices and the committed J2 state per element;
//! `FeModel` offers no setter for its material state nor for the accumulated spins of prescribed
//! rotations, so a checkpoint with plastic state is refused at restart (elastic restarts are
//! exact).

use interface_protocol::io::checkpoint::Checkpoint;
use nalgebra::{Matrix3, Vector3};

use crate::assembly::FeModel;
use crate::elements::bt4::Bt4State;
use crate::explicit_shell::ShellModel;
use crate::model::Model;
use crate::time::Dynamics;

/// The part name of the structure's checkpoint files.
pub const PART: &str = "structure";

/// A model whose state can be saved and restored.
pub trait Restorable: Model {
    /// Puts the committed configuration and element state into `ck`.
    fn save_state(&self, ck: &mut Checkpoint) -> anyhow::Result<()>;
    /// Restores what `save_state` wrote and commits it.
    fn restore_state(&mut self, ck: &Checkpoint) -> anyhow::Result<()>;
    /// Per-element output fields (one value per mesh cell, in mesh order) of the committed
    /// state: name and values; none by default.
    fn element_fields(&self) -> Vec<(&'static str, Vec<f64>)> {
        Vec::new()
    }
}

/// `ck`'s array `name` with exactly `n` values, or an error naming it.
fn sized<'a>(ck: &'a Checkpoint, name: &str, n: usize) -> anyhow::Result<&'a [f64]> {
    let a = ck.f64(name)?;
    if a.len() != n {
        anyhow::bail!(
            "checkpoint at step {}: array `{name}` holds {} values, the model needs {n} (another mesh?)",
            ck.step,
            a.len()
        );
    }
    Ok(a)
}

impl Restorable for ShellModel {
    fn save_state(&self, ck: &mut Checkpoint) -> anyhow::Result<()> {
        ck.put("x", self.committed_positions().as_flattened().to_vec())?;
        let s = self.bt4.state();
        ck.put("bt4.stress", s.stress.clone())?;
        ck.put("bt4.plastic_strain", s.alpha.clone())?;
        ck.put("bt4.hourglass", s.hourglass.clone())?;
        Ok(())
    }

    fn restore_state(&mut self, ck: &Checkpoint) -> anyhow::Result<()> {
        let x = sized(ck, "x", 3 * self.n_nodes())?;
        let s = self.bt4.state();
        let state = Bt4State {
            stress: sized(ck, "bt4.stress", s.stress.len())?.to_vec(),
            alpha: sized(ck, "bt4.plastic_strain", s.alpha.len())?.to_vec(),
            hourglass: sized(ck, "bt4.hourglass", s.hourglass.len())?.to_vec(),
        };
        self.set_positions(x.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect());
        self.bt4.set_state(state);
        self.commit();
        Ok(())
    }

    /// The largest von Mises stress and equivalent plastic strain through each shell's thickness.
    fn element_fields(&self) -> Vec<(&'static str, Vec<f64>)> {
        let (ne, np) = (self.bt4.n_elements(), self.bt4.settings.rule.len());
        let max_over = |f: &dyn Fn(usize, usize) -> f64| -> Vec<f64> {
            (0..ne).map(|e| (0..np).map(|p| f(e, p)).fold(0.0, f64::max)).collect()
        };
        vec![
            ("von_mises", max_over(&|e, p| von_mises(self.bt4.stress(e, p)))),
            ("plastic_strain", max_over(&|e, p| self.bt4.plastic_strain(e, p))),
        ]
    }
}

/// Von Mises stress of a shell point `[σxx, σyy, σxy, σyz, σzx]` (σzz = 0).
fn von_mises(s: [f64; 5]) -> f64 {
    let [xx, yy, xy, yz, zx] = s;
    (xx * xx - xx * yy + yy * yy + 3.0 * (xy * xy + yz * yz + zx * zx)).sqrt()
}

impl Restorable for FeModel {
    fn save_state(&self, ck: &mut Checkpoint) -> anyhow::Result<()> {
        let x: Vec<f64> = self.positions().iter().flat_map(|p| [p.x, p.y, p.z]).collect();
        let r: Vec<f64> = self.rotations().iter().flat_map(|m| m.as_slice().to_vec()).collect();
        ck.put("x", x)?;
        ck.put("rotations", r)?;
        let material: Vec<f64> =
            (0..self.elements().len()).flat_map(|e| self.element_state(e).to_vec()).collect();
        ck.put("material", material)?;
        Ok(())
    }

    fn restore_state(&mut self, ck: &Checkpoint) -> anyhow::Result<()> {
        let n = self.n_nodes();
        let x: Vec<Vector3<f64>> =
            sized(ck, "x", 3 * n)?.chunks_exact(3).map(Vector3::from_column_slice).collect();
        let r: Vec<Matrix3<f64>> = sized(ck, "rotations", 9 * n)?
            .chunks_exact(9)
            .map(Matrix3::from_column_slice)
            .collect();
        // `FeModel` can read its J2 state but not set it: a yielded model cannot resume exactly.
        if let Some(i) = ck.f64("material")?.iter().position(|&v| v != 0.0) {
            anyhow::bail!(
                "checkpoint at step {}: the model has plastic state (value {i} is nonzero) and \
                 FeModel cannot restore material state; restart from a checkpoint before yield",
                ck.step
            );
        }
        self.set_configuration(&x, &r);
        self.commit();
        Ok(())
    }
}

/// Puts the integrator state (`t` is the checkpoint's time).
pub fn save_dynamics(ck: &mut Checkpoint, d: &Dynamics) -> anyhow::Result<()> {
    ck.put("v", d.v.clone())?;
    ck.put("a", d.a.clone())?;
    Ok(())
}

/// The integrator state of a checkpoint for a model of `n_dof` dofs.
pub fn load_dynamics(ck: &Checkpoint, n_dof: usize) -> anyhow::Result<Dynamics> {
    Ok(Dynamics {
        t: ck.time,
        v: sized(ck, "v", n_dof)?.to_vec(),
        a: sized(ck, "a", n_dof)?.to_vec(),
    })
}
