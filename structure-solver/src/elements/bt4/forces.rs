//! The explicit BT4 loop over threads and vector units (DESIGN §6, "Speed").
//!
//! One pass in two phases, both over threads:
//! 1. blocks of [`LANES`] elements, [`BLOCKS_PER_TASK`] blocks a task: gather the block's
//!    nodes, run the kernel, write the trial state and the element forces (24 per element) to
//!    a work array, so no two tasks write the same memory;
//! 2. nodes, a node's force summing its elements' contributions in ascending element order
//!    (`elements::incidence`), exactly the order of a serial scatter.
//!
//! So the forces are bitwise independent of the thread count and of rayon's splitting. On one
//! thread the blocks add their forces to the nodes as they go, in ascending element order: the
//! same sums without the work array.
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
use crate::elements::incidence::Incidence;
use crate::material::lanes::{Block8, Lanes};

/// Blocks of elements per task of the first phase.
pub const BLOCKS_PER_TASK: usize = 16;
/// Element forces per element in the work array: 6 per node, `[node][dof]`.
const F_PER_ELEMENT: usize = 24;

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

/// Where a task puts its element forces.
enum Sink<'a> {
    /// Its rows of the work array.
    Rows(&'a mut [f64]),
    /// Added to the nodal forces (6 per node) in element order.
    Nodes(&'a mut [f64]),
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
    forces: Sink<'a>,
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
            match &mut self.forces {
                Sink::Rows(rows) => {
                    let n = LANES * F_PER_ELEMENT;
                    let out = &mut rows[j * n..(j + 1) * n];
                    for l in 0..LANES {
                        for i in 0..4 {
                            for d in 0..6 {
                                out[(l * 4 + i) * 6 + d] = fe[i][d][l];
                            }
                        }
                    }
                }
                Sink::Nodes(f) => {
                    for l in 0..valid {
                        for (i, &n) in bt4.conn[e0 + l].iter().enumerate() {
                            let fnode = &mut f[6 * n as usize..6 * n as usize + 6];
                            for d in 0..6 {
                                fnode[d] += fe[i][d][l];
                            }
                        }
                    }
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
    pub incidence: Incidence,
    /// Element forces, `[element][node][dof]`, padded to whole blocks.
    pub forces: Vec<f64>,
}

impl Work {
    pub fn bytes(&self) -> usize {
        self.incidence.bytes() + 8 * self.forces.len()
    }
}

/// Phase 1 and 2 of the module docs on `path`; `None` when the processor lacks it.
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
    if work.incidence.n_nodes() != nn {
        work.incidence = Incidence::new(bt4.conn, nn);
    }
    let nb = bt4.conn.len().div_ceil(LANES);
    let np = bt4.settings.rule.len();
    let t = BLOCKS_PER_TASK;
    let (old, new) = state;
    let shared = Shared { bt4, x_end, du };
    if rayon::current_num_threads() == 1 {
        let op = BlockTask {
            shared: &shared,
            first_block: 0,
            n_blocks: nb,
            stress_old: &old.stress,
            alpha_old: &old.alpha,
            hg_old: &old.hourglass,
            stress_new: &mut new.stress,
            alpha_new: &mut new.alpha,
            hg_new: &mut new.hourglass,
            forces: Sink::Nodes(f),
        };
        return path.run(op);
    }
    work.forces.resize(nb * LANES * F_PER_ELEMENT, 0.0);
    (
        old.stress.par_chunks(t * np * N_STRESS * LANES),
        old.alpha.par_chunks(t * np * LANES),
        old.hourglass.par_chunks(t * N_HOURGLASS * LANES),
        new.stress.par_chunks_mut(t * np * N_STRESS * LANES),
        new.alpha.par_chunks_mut(t * np * LANES),
        new.hourglass.par_chunks_mut(t * N_HOURGLASS * LANES),
        work.forces.par_chunks_mut(t * LANES * F_PER_ELEMENT),
    )
        .into_par_iter()
        .enumerate()
        .for_each(|(task, (so, ao, ho, sn, an, hn, fo))| {
            let op = BlockTask {
                shared: &shared,
                first_block: task * t,
                n_blocks: fo.len() / (LANES * F_PER_ELEMENT),
                stress_old: so,
                alpha_old: ao,
                hg_old: ho,
                stress_new: sn,
                alpha_new: an,
                hg_new: hn,
                forces: Sink::Rows(fo),
            };
            path.run(op).expect("a supported path");
        });
    work.incidence.add_rows(&work.forces, f);
    Some(())
}
