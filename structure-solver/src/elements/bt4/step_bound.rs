//! The element bound of the critical step of a BT4 part (see [`Bt4::stable_dt`]), by blocks of
//! [`LANES`] elements compiled for the widest vector unit, as the force loop (`forces`): the
//! same operations per element as the one-element form, so the same bits.
//!
//! [`Bt4::stable_dt`]: super::Bt4::stable_dt

use rayon::prelude::*;

use super::forces::{lanes, BlockOp, Bt4View, SimdPath};
use super::kernel::frame;
use super::{BLOCKS_PER_TASK, LANES};
use crate::elements::section::SHEAR_FACTOR;
use crate::material::lanes::{Block8, Real};
use crate::material::J2;

/// The material constants of the bound: plate wave speed `c`, `12 κ G`, `4 E` and `ρ`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct BoundConstants<R> {
    pub wave: R,
    pub s12: R,
    pub e4: R,
    pub rho: R,
}

impl BoundConstants<f64> {
    pub fn of(m: &J2) -> Self {
        let el = m.elastic;
        BoundConstants {
            wave: el.plate_wave_speed(),
            s12: 12.0 * SHEAR_FACTOR * el.shear_modulus(),
            e4: 4.0 * el.e,
            rho: el.rho,
        }
    }
}

/// The membrane bound `L_e / c` and the rotational bound `2/ω_r` of an element (block) with
/// nodes `x` and thickness `h`; `scaled`: the rotary inertia takes the added area `A`.
#[inline(always)]
pub(super) fn bounds<R: Real>(
    x: &[[R; 3]; 4],
    h: R,
    c: &BoundConstants<R>,
    scaled: bool,
) -> (R, R) {
    let a = frame(x).area;
    let l = a / distance(&x[0], &x[2]).max(distance(&x[1], &x[3]));
    let a_rot = if scaled { a } else { R::splat(0.0) };
    let w2 = (c.s12 + c.e4 * h * h / a) / (c.rho * (h * h + a_rot));
    (l / c.wave, R::splat(2.0) / w2.sqrt())
}

/// `|a - b|`.
#[inline(always)]
fn distance<R: Real>(a: &[R; 3], b: &[R; 3]) -> R {
    let s = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt()
}

/// The blocks of one task.
struct BoundTask<'a> {
    bt4: &'a Bt4View<'a>,
    bounds: &'a [BoundConstants<f64>],
    x: &'a [[f64; 3]],
    blocks: std::ops::Range<usize>,
}

impl BlockOp for BoundTask<'_> {
    type Output = f64;
    #[inline(always)]
    fn run<R: Block8>(self) -> f64 {
        let (bt4, x) = (self.bt4, self.x);
        let ne = bt4.conn.len();
        let scaled = bt4.settings.rotary == super::RotaryInertia::Scaled;
        let mut dt = f64::INFINITY;
        for b in self.blocks {
            let e0 = b * LANES;
            let valid = (ne - e0).min(LANES);
            let el = |l: usize| e0 + l.min(valid - 1);
            let mut xe = [[[0.0; LANES]; 3]; 4];
            for l in 0..LANES {
                let c = &bt4.conn[el(l)];
                for i in 0..4 {
                    let p = &x[c[i] as usize];
                    for k in 0..3 {
                        xe[i][k][l] = p[k];
                    }
                }
            }
            let xe = lanes::<R, 3>(xe);
            let h = R::from_array(std::array::from_fn(|l| bt4.thickness[el(l)]));
            let m: [&BoundConstants<f64>; LANES] =
                std::array::from_fn(|l| &self.bounds[bt4.material_of[el(l)] as usize]);
            let c = BoundConstants {
                wave: R::from_array(std::array::from_fn(|l| m[l].wave)),
                s12: R::from_array(std::array::from_fn(|l| m[l].s12)),
                e4: R::from_array(std::array::from_fn(|l| m[l].e4)),
                rho: R::from_array(std::array::from_fn(|l| m[l].rho)),
            };
            let (t1, t2) = bounds(&xe, h, &c, scaled);
            let (t1, t2) = (t1.to_array(), t2.to_array());
            for l in 0..valid {
                dt = dt.min(t1[l].min(t2[l]));
            }
        }
        dt
    }
}

/// The smallest element bound of the part at positions `x`, over the threads of the current
/// pool on `path` (`None` when the processor lacks it). The minimum does not depend on the
/// order, so neither on the threads.
pub(super) fn stable_dt(
    path: SimdPath,
    bt4: &Bt4View<'_>,
    bounds: &[BoundConstants<f64>],
    x: &[[f64; 3]],
) -> Option<f64> {
    if !path.is_supported() {
        return None;
    }
    let nb = bt4.conn.len().div_ceil(LANES);
    let t = BLOCKS_PER_TASK;
    let dt = (0..nb.div_ceil(t))
        .into_par_iter()
        .map(|task| {
            let blocks = task * t..((task + 1) * t).min(nb);
            path.run(BoundTask { bt4, bounds, x, blocks }).expect("a supported path")
        })
        .reduce(|| f64::INFINITY, f64::min);
    Some(dt)
}
