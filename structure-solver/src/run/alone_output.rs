//! What a run alone writes per step: probe rows, the field series and the progress bar.

use interface_protocol::io::probes::ProbeWriter;
use interface_protocol::io::progress::Progress;

use crate::assembly::FeModel;
use crate::model::Model;
use crate::output::{gather_nodal, FieldOutput};

/// What a run alone writes per step: probe rows every `probes_every` steps, the field series
/// every `fields_every` steps (0: first and last only), both at the end; the first non-finite
/// value stops the run.
pub(super) struct AloneOutput {
    pub(super) probe_nodes: Vec<usize>,
    pub(super) probes: ProbeWriter,
    pub(super) probes_every: u64,
    pub(super) fields: FieldOutput,
    pub(super) fields_every: u64,
    pub(super) disp: Vec<[f64; 3]>,
    pub(super) vel: Vec<[f64; 3]>,
    pub(super) bar: Progress,
}

impl AloneOutput {
    /// Writes step `step` at `t` (`last`: the final state); `cells` gives the model for cell
    /// fields (dynamic runs).
    pub(super) fn write(
        &mut self,
        model: &dyn Model,
        cells: Option<&FeModel>,
        v: &[f64],
        (step, t, dt): (u64, f64, f64),
        last: bool,
    ) -> anyhow::Result<()> {
        let probe = step % self.probes_every == 0 || last;
        let field = step == 0 || last || (self.fields_every > 0 && step % self.fields_every == 0);
        self.bar.update(step, t, dt);
        if !(probe || field) {
            return Ok(());
        }
        let user = |s: usize| self.fields.node_user(s);
        gather_nodal(t, model, v, &mut self.disp, &mut self.vel, &user)?;
        if probe {
            let mut row = Vec::with_capacity(6 * self.probe_nodes.len());
            for &p in &self.probe_nodes {
                row.extend_from_slice(&self.disp[p]);
                row.extend_from_slice(&self.vel[p]);
            }
            self.probes.write_row(t, &row)?;
        }
        if field {
            self.fields.gather(t, model, cells, v)?;
            self.fields.write(t)?;
        }
        Ok(())
    }
}
