//! The explicit BLT3 loop over threads, on the chunks of `bt4` (`elements::incidence`): a
//! task runs the kernel on a contiguous chunk of elements and writes its trial state; the
//! element forces go straight into the nodes the chunk owns and into work rows for the nodes
//! chunks share, summed afterwards in ascending element order. So the forces are bitwise
//! independent of the thread count.

use rayon::prelude::*;

use super::kernel::{element, Committed, Geometry, Trial};
use super::{Blt3, N_SHEAR, N_STRESS};
use crate::elements::incidence::{chunk_bounds, split_at_bounds, ChunkSink, NodeScatter};

/// Work arrays of the loop.
#[derive(Debug, Clone, Default)]
pub(super) struct Work {
    /// The chunks of the element pass and the nodes they share.
    pub scatter: NodeScatter,
}

impl Work {
    pub fn bytes(&self) -> usize {
        self.scatter.bytes()
    }
}

/// One task of the element pass: its sink and its slices of the trial state.
struct Chunk<'a> {
    sink: ChunkSink<'a>,
    sn: &'a mut [f64],
    an: &'a mut [f64],
    qn: &'a mut [f64],
}

impl Blt3 {
    /// The element pass and the node phase of the module docs.
    pub(super) fn threaded_force(&mut self, x_end: &[[f64; 3]], du: &[f64], f: &mut [f64]) {
        let nn = x_end.len();
        let bounds = chunk_bounds(self.conn.len(), 1, rayon::current_num_threads());
        if !self.work.scatter.fits(nn, &bounds) {
            self.work.scatter = NodeScatter::new(&self.conn, nn, bounds);
        }
        let np = self.settings.rule.len();
        let (old, new) = (&self.committed, &mut self.trial);
        let (conn, thickness, set) = (&self.conn, &self.thickness, &self.settings);
        let (materials, material_of) = (&self.materials, &self.material_of);
        let scatter = &mut self.work.scatter;
        let bounds = scatter.bounds().to_vec();
        let tasks: Vec<_> = scatter
            .sinks(f)
            .into_iter()
            .zip(split_at_bounds(&mut new.stress, &bounds, np * N_STRESS))
            .zip(split_at_bounds(&mut new.alpha, &bounds, np))
            .zip(split_at_bounds(&mut new.shear, &bounds, N_SHEAR))
            .map(|(((sink, sn), an), qn)| Chunk { sink, sn, an, qn })
            .collect();
        let run = |Chunk { mut sink, sn, an, qn }: Chunk<'_>| {
            let e0 = sink.elements().start;
            for e in sink.elements() {
                let nodes = conn[e].map(|n| n as usize);
                let xe = nodes.map(|n| x_end[n]);
                let xm = nodes.map(|n| std::array::from_fn(|k| x_end[n][k] - 0.5 * du[6 * n + k]));
                let dv = nodes.map(|n| std::array::from_fn(|k| du[6 * n + k]));
                let j = e - e0;
                let (s, a, q) = (j * np * N_STRESS, j * np, j * N_SHEAR);
                let fe = element(
                    &materials[material_of[e] as usize],
                    set,
                    Geometry { x_end: &xe, x_mid: &xm, du: &dv, h: thickness[e] },
                    Committed {
                        stress: &old.stress[e * np * N_STRESS..(e + 1) * np * N_STRESS],
                        alpha: &old.alpha[e * np..(e + 1) * np],
                        shear: &old.shear[e * N_SHEAR..(e + 1) * N_SHEAR],
                    },
                    Trial {
                        stress: &mut sn[s..s + np * N_STRESS],
                        alpha: &mut an[a..a + np],
                        shear: &mut qn[q..q + N_SHEAR],
                    },
                );
                for (i, fi) in fe.into_iter().enumerate() {
                    sink.add(e, i, conn[e][i], fi);
                }
            }
        };
        if tasks.len() == 1 {
            tasks.into_iter().for_each(run);
        } else {
            tasks.into_par_iter().with_max_len(1).for_each(run);
        }
        scatter.sum_shared(f);
    }
}
