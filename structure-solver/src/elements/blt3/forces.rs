//! The explicit BLT3 loop over threads, in the two phases of `bt4`: tasks of
//! [`ELEMENTS_PER_TASK`] elements run the kernel and write the trial state and the element
//! forces (18 per element) to their own memory; then each node sums its elements' forces in
//! ascending element order (`elements::incidence`). So the forces are bitwise independent of
//! the thread count and of rayon's splitting.

use rayon::prelude::*;

use super::kernel::{element, Committed, Geometry, Trial};
use super::{Blt3, N_SHEAR, N_STRESS};
use crate::elements::incidence::Incidence;

/// Elements per task of the element phase.
pub const ELEMENTS_PER_TASK: usize = 256;
/// Element forces per element in the work array: 6 per node, `[node][dof]`.
const F_PER_ELEMENT: usize = 18;

/// Work arrays of the loop.
#[derive(Debug, Clone, Default)]
pub(super) struct Work {
    pub incidence: Incidence,
    /// Element forces, `[element][node][dof]`.
    pub forces: Vec<f64>,
}

impl Work {
    pub fn bytes(&self) -> usize {
        self.incidence.bytes() + 8 * self.forces.len()
    }
}

impl Blt3 {
    /// Both phases of the module docs.
    pub(super) fn threaded_force(&mut self, x_end: &[[f64; 3]], du: &[f64], f: &mut [f64]) {
        let nn = x_end.len();
        if self.work.incidence.n_nodes() != nn {
            self.work.incidence = Incidence::new(&self.conn, nn);
        }
        self.work.forces.resize(F_PER_ELEMENT * self.conn.len(), 0.0);
        let np = self.settings.rule.len();
        let t = ELEMENTS_PER_TASK;
        let (old, new) = (&self.committed, &mut self.trial);
        let (conn, thickness, set) = (&self.conn, &self.thickness, &self.settings);
        let (materials, material_of) = (&self.materials, &self.material_of);
        (
            old.stress.par_chunks(t * np * N_STRESS),
            old.alpha.par_chunks(t * np),
            old.shear.par_chunks(t * N_SHEAR),
            new.stress.par_chunks_mut(t * np * N_STRESS),
            new.alpha.par_chunks_mut(t * np),
            new.shear.par_chunks_mut(t * N_SHEAR),
            self.work.forces.par_chunks_mut(t * F_PER_ELEMENT),
        )
            .into_par_iter()
            .enumerate()
            .for_each(|(task, (so, ao, qo, sn, an, qn, fo))| {
                for (j, out) in fo.chunks_exact_mut(F_PER_ELEMENT).enumerate() {
                    let e = task * t + j;
                    let nodes = conn[e].map(|n| n as usize);
                    let xe = nodes.map(|n| x_end[n]);
                    let xm =
                        nodes.map(|n| std::array::from_fn(|k| x_end[n][k] - 0.5 * du[6 * n + k]));
                    let dv = nodes.map(|n| std::array::from_fn(|k| du[6 * n + k]));
                    let (s, a, q) = (j * np * N_STRESS, j * np, j * N_SHEAR);
                    let fe = element(
                        &materials[material_of[e] as usize],
                        set,
                        Geometry { x_end: &xe, x_mid: &xm, du: &dv, h: thickness[e] },
                        Committed {
                            stress: &so[s..s + np * N_STRESS],
                            alpha: &ao[a..a + np],
                            shear: &qo[q..q + N_SHEAR],
                        },
                        Trial {
                            stress: &mut sn[s..s + np * N_STRESS],
                            alpha: &mut an[a..a + np],
                            shear: &mut qn[q..q + N_SHEAR],
                        },
                    );
                    for (i, fi) in fe.iter().enumerate() {
                        out[6 * i..6 * i + 6].copy_from_slice(fi);
                    }
                }
            });
        self.work.incidence.add_rows(&self.work.forces, f);
    }
}
