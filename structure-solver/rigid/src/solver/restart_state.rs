//! The rigid structure's checkpoint (`checkpoints/<tag>/structure.ckpt`): the body's state, the
//! DOF names and the scheme's history, written at `Checkpoint` and read back by a coupled
//! restart so that the run continues bitwise.

use super::{io_failure, probe_failure, RigidSolver, CHECKPOINT_PART};
use interface_protocol::io::checkpoint::Checkpoint;
use interface_protocol::participant::Failure;

impl RigidSolver {
    /// The DOF names the checkpoint's metadata holds.
    fn dof_names(&self) -> Vec<String> {
        (0..self.body.dofs.len()).map(|i| self.body.dof_name(i).to_string()).collect()
    }

    /// Writes `checkpoints/<tag>/structure.ckpt`: `u`, `v`, `a`, `v_half` of the free DOFs, their
    /// names in the metadata, and the scheme's history (`coupling.<name>`,
    /// `Staggered::history`); flushes the probes first.
    pub(super) fn write_checkpoint(&mut self, tag: &str) -> Result<(), Failure> {
        let fail = |e| io_failure("cannot write the checkpoint", e);
        let mut ck = Checkpoint::new(self.steps, self.t);
        ck.set_meta(&self.dof_names()).map_err(fail)?;
        let s = &self.state;
        for (name, values) in [("u", &s.u), ("v", &s.v), ("a", &s.a), ("v_half", &s.v_half)] {
            ck.put(name, values.clone()).map_err(fail)?;
        }
        for (name, values) in self.scheme.history() {
            ck.put(&format!("coupling.{name}"), values).map_err(fail)?;
        }
        self.probes.flush().map_err(probe_failure)?;
        let dir =
            self.out.checkpoints().map_err(|e| io_failure("cannot create checkpoints/", e))?;
        ck.write(&dir, tag, CHECKPOINT_PART).map_err(fail)?;
        Ok(())
    }
}

impl RigidSolver {
    /// Puts the state, the scheme's history, the step and the time of `ck` (written by
    /// [`RigidSolver::write_checkpoint`]) back; an error names what does not fit the case.
    pub(super) fn restore(&mut self, ck: &Checkpoint) -> Result<(), String> {
        let names: Vec<String> = ck.meta().map_err(|e| e.to_string())?;
        if names != self.dof_names() {
            return Err(format!(
                "it holds the DOFs {names:?}, the case's structure.rigid.dofs are {:?}",
                self.dof_names()
            ));
        }
        let n = names.len();
        let sized = |name: &str| -> Result<Vec<f64>, String> {
            let v = ck.f64(name).map_err(|e| e.to_string())?;
            match v.len() == n {
                true => Ok(v.to_vec()),
                false => Err(format!("`{name}` holds {} values, expected {n}", v.len())),
            }
        };
        let s = &mut self.state;
        (s.u, s.v, s.a, s.v_half) = (sized("u")?, sized("v")?, sized("a")?, sized("v_half")?);
        self.scheme
            .restore(|name| ck.f64(&format!("coupling.{name}")).ok().map(<[f64]>::to_vec))?;
        (self.steps, self.t) = (ck.step, ck.time);
        Ok(())
    }
}
