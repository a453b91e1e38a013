//! The internal force of the elements other than BT4 shells, in parallel over elements, with
//! work arrays allocated once (at the first evaluation, or when the elements change) so an
//! explicit step allocates nothing: each element's nodal positions and rotations, its force
//! and its trial material state land in its own scratch, then are summed into the global
//! vector and copied into the trial state in element order (the same sum as before, bitwise).

use nalgebra::{Matrix3, Vector3};
use rayon::prelude::*;

use super::FeModel;

/// One element's work arrays (at most four nodes).
#[derive(Debug, Clone, Default)]
pub(super) struct ElementScratch {
    x: [Vector3<f64>; 4],
    r: [Matrix3<f64>; 4],
    force: Vec<f64>,
    state: Vec<f64>,
}

impl FeModel {
    /// Sizes the scratch of every element (nothing when it already fits).
    fn ensure_scratch(&mut self) {
        let fits = self.scratch.len() == self.elements.len()
            && self.elements.iter().zip(&self.scratch).zip(self.state_offsets.windows(2)).all(
                |((e, s), w)| s.force.len() == 6 * e.nodes.len() && s.state.len() == w[1] - w[0],
            );
        if fits {
            return;
        }
        self.scratch = self
            .elements
            .iter()
            .zip(self.state_offsets.windows(2))
            .map(|(e, w)| ElementScratch {
                force: vec![0.0; 6 * e.nodes.len()],
                state: vec![0.0; w[1] - w[0]],
                ..ElementScratch::default()
            })
            .collect();
    }

    /// Adds the elements' internal forces at the trial configuration to `f` and writes their
    /// trial material state.
    pub(super) fn element_forces(&mut self, f: &mut [f64]) {
        self.ensure_scratch();
        let (x, r) = (&self.trial.x, &self.trial.r);
        let committed = &self.committed.material;
        let offsets = &self.state_offsets;
        self.elements.par_iter().zip(self.scratch.par_iter_mut()).enumerate().for_each(
            |(ei, (e, s))| {
                let k = e.nodes.len();
                for (i, &n) in e.nodes.iter().enumerate() {
                    s.x[i] = x[n];
                    s.r[i] = r[n];
                }
                s.force.fill(0.0);
                let old = &committed[offsets[ei]..offsets[ei + 1]];
                e.force(&s.x[..k], &s.r[..k], old, &mut s.state, &mut s.force);
            },
        );
        let trial = &mut self.trial.material;
        for ((e, s), w) in self.elements.iter().zip(&self.scratch).zip(offsets.windows(2)) {
            for (i, &n) in e.nodes.iter().enumerate() {
                for c in 0..6 {
                    f[6 * n + c] += s.force[6 * i + c];
                }
            }
            trial[w[0]..w[1]].copy_from_slice(&s.state);
        }
    }
}
