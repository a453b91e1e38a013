//! The fluid's part of a checkpoint (DESIGN §7): the conserved array, node materials and level
//! set with `(step, t)`, beside the embedded surface's part ([`embedded::checkpoint`]); what a
//! bitwise restart reads back.

use super::FluidRun;
use crate::embedded;
use crate::state::State;
use anyhow::Context;
use interface_protocol::io::checkpoint::{self, Checkpoint, Found};
use interface_protocol::io::report::bucket;
use std::path::Path;
use std::time::Instant;

/// Checkpoint part name of the fluid.
pub const CHECKPOINT_PART: &str = "fluid";

/// Reads the conserved state, node materials and level set of the checkpoint `--restart
/// run_dir` names: the newest complete one under `run_dir/checkpoints`, or `run_dir` itself
/// when it is one checkpoint folder ([`checkpoint::restart_point`]). A checkpoint without
/// `material` is of one fluid, material 0; one without `phi` has no level set.
pub fn read_checkpoint(run_dir: &Path, n_nodes: usize) -> anyhow::Result<(State, u64, f64)> {
    let found = checkpoint::restart_point(run_dir, CHECKPOINT_PART)?.with_context(|| {
        format!("no complete fluid checkpoint in {}", run_dir.join("checkpoints").display())
    })?;
    read_fluid_part(&found, n_nodes)
}

/// The fluid part of the checkpoint `found` ([`read_checkpoint`]).
pub(super) fn read_fluid_part(found: &Found, n_nodes: usize) -> anyhow::Result<(State, u64, f64)> {
    let part = format!("{CHECKPOINT_PART}.{}", checkpoint::EXTENSION);
    let ck = Checkpoint::read_file(&found.dir.join(part))?;
    let cons = ck.f64_n::<5>("cons")?;
    let material = match ck.names().any(|n| n == "material") {
        true => ck.u8("material")?.to_vec(),
        false => vec![0; cons.len()],
    };
    let phi = match ck.names().any(|n| n == "phi") {
        true => ck.f64("phi")?.to_vec(),
        false => Vec::new(),
    };
    anyhow::ensure!(
        cons.len() == n_nodes && material.len() == n_nodes && phi.len() % n_nodes.max(1) == 0,
        "checkpoint {} holds {} nodes ({} material ids, {} level-set values), but the case's mesh \
         has {n_nodes}",
        found.dir.display(),
        cons.len(),
        material.len(),
        phi.len()
    );
    Ok((State { cons, material, phi }, ck.step, ck.time))
}

impl FluidRun<'_> {
    /// Writes the conserved state, node materials and level set as the checkpoint `tag` (part
    /// [`CHECKPOINT_PART`]), after the embedded surface's part if there is one (so a fluid part
    /// always has its embedded part beside it).
    pub fn write_checkpoint(&mut self, tag: &str) -> anyhow::Result<()> {
        let start = Instant::now();
        if let Some(e) = &self.embedded {
            embedded::checkpoint::write(e, &self.out.checkpoints()?, tag, self.step, self.t)?;
        }
        let mut ck = Checkpoint::new(self.step, self.t);
        ck.put_f64_n("cons", &self.state.cons)?;
        ck.put("material", self.state.material.clone())?;
        if !self.state.phi.is_empty() {
            ck.put("phi", self.state.phi.clone())?;
        }
        ck.write(&self.out.checkpoints()?, tag, CHECKPOINT_PART)?;
        self.timers.add_since(bucket::OUTPUT, start);
        Ok(())
    }
}
