//! The explicit BT4 loop over threads and vector units (DESIGN §6, "Speed").
//!
//! One pass over chunks of whole blocks of [`LANES`] elements, a task each
//! (`elements::incidence`): a block gathers its nodes, runs the kernel and writes its trial
//! state; its element forces go straight into the nodes its chunk owns and into work rows for
//! the nodes chunks share, which then sum their rows in ascending element order. Every node's
//! force is the serial scatter's sum, so the forces are bitwise independent of the thread
//! count. One thread is one chunk and writes no work row.
//!
//! The vector width is chosen at run time ([`SimdPath`], detected through `pulp`): the block
//! loop is compiled in functions of the AVX-512 (x86-64-v4) and AVX2 + FMA (x86-64-v3)
//! instruction sets on the lanes of `material::lanes_x86` (one or two registers per block),
//! and for the baseline (SSE2) on [`Lanes`]; the widest the processor has runs. The kernel
//! never asks for fused multiply-adds, so every path does the same IEEE operations and gives
//! the same bits.

use rayon::prelude::*;

use super::kernel::{element_block, BlockState, Constants};
use super::{LANES, N_HOURGLASS, N_STRESS};
use crate::elements::incidence::{chunk_bounds, split_at_bounds, ChunkSink, NodeScatter};
use crate::material::lanes::{Block8, Lanes};

/// Blocks of elements per task of the stable-step bound.
pub const BLOCKS_PER_TASK: usize = 16;

/// An instruction set the block loop is compiled for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SimdPath {
    /// x86-64-v4: AVX-512 (F, BW, CD, DQ, VL), a block of 8 `f64` in one register.
    Avx512,
    /// x86-64-v3: AVX2 and FMA.
    Avx2Fma,
    /// The baseline of the target (SSE2 on x86-64).
    Scalar,
}

impl SimdPath {
    pub const ALL: [SimdPath; 3] = [SimdPath::Avx512, SimdPath::Avx2Fma, SimdPath::Scalar];

    /// The widest path this processor runs.
    pub fn detected() -> SimdPath {
        Self::ALL.into_iter().find(|p| p.is_supported()).unwrap_or(SimdPath::Scalar)
    }

    /// `true` when this processor runs the path.
    pub fn is_supported(self) -> bool {
        match self {
            #[cfg(target_arch = "x86_64")]
            SimdPath::Avx512 => pulp::x86::V4::try_new().is_some(),
            #[cfg(target_arch = "x86_64")]
            SimdPath::Avx2Fma => pulp::x86::V3::try_new().is_some(),
            SimdPath::Scalar => true,
            #[allow(unreachable_patterns)]
            _ => false,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            SimdPath::Avx512 => "avx512",
            SimdPath::Avx2Fma => "avx2+fma",
            SimdPath::Scalar => "scalar",
        }
    }

    /// Runs `op` compiled for this path, on its lanes; `None` when the processor lacks it.
    pub(super) fn run<Op: BlockOp>(self, op: Op) -> Option<Op::Output> {
        if !self.is_supported() {
            return None;
        }
        match self {
            // SAFETY: `is_supported` found x86-64-v4, the instruction set of `run_v4`.
            #[cfg(target_arch = "x86_64")]
            SimdPath::Avx512 => Some(unsafe { run_v4(op) }),
            // SAFETY: `is_supported` found x86-64-v3, the instruction set of `run_v3`.
            #[cfg(target_arch = "x86_64")]
            SimdPath::Avx2Fma => Some(unsafe { run_v3(op) }),
            SimdPath::Scalar => Some(op.run::<Lanes<LANES>>()),
            #[allow(unreachable_patterns)]
            _ => None,
        }
    }
}

/// Work on blocks of [`LANES`] elements, compiled once per instruction set on its lanes.
pub(super) trait BlockOp {
    type Output;
    fn run<R: Block8>(self) -> Self::Output;
}

/// `op` on one AVX-512 register per lane block, compiled for x86-64-v4 (the features `pulp`
/// checks for it).
#[cfg(target_arch = "x86_64")]
#[target_feature(
    enable = "avx512f,avx512bw,avx512cd,avx512dq,avx512vl,avx2,avx,fma,bmi1,bmi2,lzcnt,popcnt"
)]
fn run_v4<Op: BlockOp>(op: Op) -> Op::Output {
    op.run::<crate::material::lanes_x86::Avx512>()
}

/// `op` on two AVX2 registers per lane block, compiled for x86-64-v3.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,avx,fma,bmi1,bmi2,lzcnt,popcnt")]
fn run_v3<Op: BlockOp>(op: Op) -> Op::Output {
    op.run::<crate::material::lanes_x86::Avx2>()
}

/// The inputs every task reads.
struct Shared<'a> {
    bt4: &'a Bt4View<'a>,
    x_end: &'a [[f64; 3]],
    du: &'a [f64],
}

/// The parts of a [`Bt4`] the kernel reads.
pub(super) struct Bt4View<'a> {
    pub conn: &'a [[u32; 4]],
    pub thickness: &'a [f64],
    pub constants: &'a [Constants<f64>],
    pub material_of: &'a [u16],
    pub settings: &'a super::Bt4Settings,
}

/// The blocks of one task.
struct BlockTask<'a> {
    shared: &'a Shared<'a>,
    first_block: usize,
    n_blocks: usize,
    stress_old: &'a [f64],
    alpha_old: &'a [f64],
    hg_old: &'a [f64],
    stress_new: &'a mut [f64],
    alpha_new: &'a mut [f64],
    hg_new: &'a mut [f64],
    forces: ChunkSink<'a>,
}

impl BlockOp for BlockTask<'_> {
    type Output = ();
    #[inline(always)]
    fn run<R: Block8>(mut self) {
        let Shared { bt4, x_end, du } = *self.shared;
        let np = bt4.settings.rule.len();
        let ne = bt4.conn.len();
        let (ns, na) = (np * N_STRESS * LANES, np * LANES);
        let nh = N_HOURGLASS * LANES;
        for j in 0..self.n_blocks {
            let e0 = (self.first_block + j) * LANES;
            let valid = (ne - e0).min(LANES);
            // Gather: padded lanes repeat the block's last element.
            let el = |l: usize| e0 + l.min(valid - 1);
            let mut xe = [[[0.0; LANES]; 3]; 4];
            let mut xm = xe;
            let mut dv = [[[0.0; LANES]; 6]; 4];
            for l in 0..LANES {
                let c = &bt4.conn[el(l)];
                for i in 0..4 {
                    let n = c[i] as usize;
                    let (p, d) = (&x_end[n], &du[6 * n..6 * n + 6]);
                    for k in 0..3 {
                        xe[i][k][l] = p[k];
                        xm[i][k][l] = p[k] - 0.5 * d[k];
                    }
                    for k in 0..6 {
                        dv[i][k][l] = d[k];
                    }
                }
            }
            let (xe, xm, dv) = (lanes(xe), lanes(xm), lanes(dv));
            let h = R::from_array(std::array::from_fn(|l| bt4.thickness[el(l)]));
            let m0 = bt4.material_of[e0];
            let mat = if (0..valid).all(|l| bt4.material_of[e0 + l] == m0) {
                Constants::splat(&bt4.constants[m0 as usize])
            } else {
                Constants::gather(|l| &bt4.constants[bt4.material_of[el(l)] as usize])
            };
            let fe: [[R; 6]; 4] = element_block(
                &mat,
                bt4.settings,
                &xe,
                &xm,
                &dv,
                h,
                BlockState {
                    stress_old: &self.stress_old[j * ns..(j + 1) * ns],
                    alpha_old: &self.alpha_old[j * na..(j + 1) * na],
                    hg_old: &self.hg_old[j * nh..(j + 1) * nh],
                    stress_new: &mut self.stress_new[j * ns..(j + 1) * ns],
                    alpha_new: &mut self.alpha_new[j * na..(j + 1) * na],
                    hg_new: &mut self.hg_new[j * nh..(j + 1) * nh],
                },
            );
            let mut out = [[[0.0; LANES]; 6]; 4];
            for i in 0..4 {
                for d in 0..6 {
                    out[i][d] = fe[i][d].to_array();
                }
            }
            let fe = out;
            for l in 0..valid {
                let e = e0 + l;
                for (i, &n) in bt4.conn[e].iter().enumerate() {
                    self.forces.add(e, i, n, std::array::from_fn(|d| fe[i][d][l]));
                }
            }
        }
    }
}

/// Lane arrays `[node][component][lane]` as blocks.
#[inline(always)]
pub(super) fn lanes<R: Block8, const C: usize>(a: [[[f64; LANES]; C]; 4]) -> [[R; C]; 4] {
    let mut out = [[R::splat(0.0); C]; 4];
    for i in 0..4 {
        for k in 0..C {
            out[i][k] = R::from_array(a[i][k]);
        }
    }
    out
}

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

/// The element pass and the node phase of the module docs on `path`; `None` when the
/// processor lacks it.
pub(super) fn internal_force(
    path: SimdPath,
    bt4: &Bt4View<'_>,
    state: (&super::Bt4State, &mut super::Bt4State),
    work: &mut Work,
    x_end: &[[f64; 3]],
    du: &[f64],
    f: &mut [f64],
) -> Option<()> {
    if !path.is_supported() {
        return None;
    }
    let nn = x_end.len();
    let bounds = chunk_bounds(bt4.conn.len(), LANES, rayon::current_num_threads());
    if !work.scatter.fits(nn, &bounds) {
        work.scatter = NodeScatter::new(bt4.conn, nn, bounds);
    }
    let np = bt4.settings.rule.len();
    let (old, new) = state;
    let shared = Shared { bt4, x_end, du };
    // the chunks' blocks and their slices of the trial state
    let blocks: Vec<usize> = work.scatter.bounds().iter().map(|b| b.div_ceil(LANES)).collect();
    let (stress_new, alpha_new, hg_new) = (
        split_at_bounds(&mut new.stress, &blocks, np * N_STRESS * LANES),
        split_at_bounds(&mut new.alpha, &blocks, np * LANES),
        split_at_bounds(&mut new.hourglass, &blocks, N_HOURGLASS * LANES),
    );
    let tasks: Vec<_> = work
        .scatter
        .sinks(f)
        .into_iter()
        .zip(stress_new)
        .zip(alpha_new)
        .zip(hg_new)
        .zip(blocks.windows(2))
        .map(|((((sink, sn), an), hn), b)| BlockTask {
            shared: &shared,
            first_block: b[0],
            n_blocks: b[1] - b[0],
            stress_old: &old.stress[b[0] * np * N_STRESS * LANES..],
            alpha_old: &old.alpha[b[0] * np * LANES..],
            hg_old: &old.hourglass[b[0] * N_HOURGLASS * LANES..],
            stress_new: sn,
            alpha_new: an,
            hg_new: hn,
            forces: sink,
        })
        .collect();
    if tasks.len() == 1 {
        tasks.into_iter().for_each(|op| path.run(op).expect("a supported path"));
    } else {
        tasks.into_par_iter().with_max_len(1).for_each(|op| {
            path.run(op).expect("a supported path");
        });
    }
    work.scatter.sum_shared(f);
    Some(())
}
