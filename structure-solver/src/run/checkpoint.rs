//! The restart state of a run alone: the newest checkpoint read into the model, and
//! checkpoints written (model state, velocities, accelerations, `dt`).

use std::path::Path;

use anyhow::anyhow;
use interface_protocol::io::checkpoint::{self, Checkpoint};
use interface_protocol::io::outdir::OutputDir;

use crate::assembly::FeModel;
use crate::model::Model;
use crate::restart::{load_dynamics, restore_state, save_dynamics, save_state, PART};
use crate::time::Dynamics;

/// Where a restart resumes: step, time step and integrator state (the model is restored).
pub(super) struct Resume {
    pub(super) step: u64,
    pub(super) dt: f64,
    pub(super) dynamics: Dynamics,
}

/// Restores `model` from the newest complete checkpoint of run folder `from`.
pub(super) fn read_checkpoint(from: &Path, model: &mut FeModel) -> anyhow::Result<Resume> {
    let dir = from.join("checkpoints");
    let found = checkpoint::latest(&dir, &[PART])?.ok_or_else(|| {
        anyhow!("--restart {}: no complete checkpoint in {}", from.display(), dir.display())
    })?;
    let ck = Checkpoint::read(&dir, &found.tag, PART)?;
    eprintln!(
        "structure-solver: restarting from checkpoint {} (step {}, t = {:e}) in {}",
        found.tag,
        found.step,
        found.time,
        dir.display()
    );
    restore_state(model, &ck)?;
    let dt = ck
        .f64("dt")?
        .first()
        .copied()
        .ok_or_else(|| anyhow!("checkpoint {}: empty `dt`", found.tag))?;
    Ok(Resume { step: ck.step, dt, dynamics: load_dynamics(&ck, model.n_dof())? })
}

/// Writes `checkpoints/<checkpoint::tag_for_step(step)>/structure.ckpt`: model state, velocities, accelerations, `dt`.
pub(super) fn write_checkpoint(
    dir: &OutputDir,
    model: &FeModel,
    d: &Dynamics,
    step: u64,
    dt: f64,
) -> anyhow::Result<()> {
    let mut ck = Checkpoint::new(step, d.t);
    save_state(model, &mut ck)?;
    save_dynamics(&mut ck, d)?;
    ck.put("dt", vec![dt])?;
    ck.write(&dir.checkpoints()?, &checkpoint::tag_for_step(step), PART)?;
    Ok(())
}
