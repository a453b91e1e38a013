//! The halves of a node's reach box (module docs of [`super::near`]): the planes through the
//! node along each axis, widened by `ρ`, split the box into a lower and an upper half per axis
//! (overlapping by `2ρ`). A recorded triangle keeps the halves its box reaches, a query box needs
//! those it lies in, and a pass skips the triangles that do not reach what it needs.
//!
//! The sets are six bits: bit `d` the lower half along axis `d`, bit `3 + d` the upper one.
//! [`Split::filter`] gives, for the kept pairs of a node, both a triangle box's halves and
//! whether it meets the reach box: twelve comparisons, made two axes at a time with SSE2 (part of
//! every x86-64 processor) and one by one elsewhere, with the same results.

/// A node's position `p` with the planes that split its reach box into halves along each axis,
/// widened by `rho`: `p + rho` and `p - rho`.
#[derive(Debug, Clone, Copy)]
pub(super) struct Split {
    up: [f64; 3],
    down: [f64; 3],
}

impl Split {
    /// The six halves: what a box holding the node within `rho` reaches.
    pub const EVERY_HALF: u8 = 0b11_1111;

    #[inline]
    pub fn new(p: &[f64; 3], rho: f64) -> Split {
        Split { up: p.map(|v| v + rho), down: p.map(|v| v - rho) }
    }

    /// The halves the box `[lo, hi]` reaches: the lower along `d` when `lo[d] <= p[d] + rho`,
    /// the upper when `hi[d] >= p[d] - rho`.
    #[inline]
    pub fn halves(&self, lo: &[f64; 3], hi: &[f64; 3]) -> u8 {
        let mut bits = 0;
        for d in 0..3 {
            bits |= u8::from(lo[d] <= self.up[d]) << d;
            bits |= u8::from(hi[d] >= self.down[d]) << (3 + d);
        }
        bits
    }

    /// The halves every box overlapping `[lo, hi]` reaches: the lower along `d` when
    /// `hi[d] <= p[d] + rho`, the upper when `lo[d] >= p[d] - rho` (the halves of the box with
    /// its corners swapped).
    #[inline]
    pub fn needed(&self, lo: &[f64; 3], hi: &[f64; 3]) -> u8 {
        self.halves(hi, lo)
    }

    /// The test of the boxes `[a, b]` against the node's reach box `[lo, hi]`
    /// ([`Filter::test`]).
    #[inline]
    pub fn filter(&self, lo: &[f64; 3], hi: &[f64; 3]) -> Filter {
        Filter::new(self, lo, hi)
    }
}

/// The halves ([`Split::halves`]) of boxes and whether they meet a reach box, for one node.
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy)]
pub(super) struct Filter {
    // Each pair holds axes 0 and 1; each single axis 2 in its low lane.
    up: (std::arch::x86_64::__m128d, std::arch::x86_64::__m128d),
    down: (std::arch::x86_64::__m128d, std::arch::x86_64::__m128d),
    lo: (std::arch::x86_64::__m128d, std::arch::x86_64::__m128d),
    hi: (std::arch::x86_64::__m128d, std::arch::x86_64::__m128d),
}

#[cfg(target_arch = "x86_64")]
impl Filter {
    #[inline]
    fn new(split: &Split, lo: &[f64; 3], hi: &[f64; 3]) -> Filter {
        let pair = |v: &[f64; 3]| lanes(v);
        Filter { up: pair(&split.up), down: pair(&split.down), lo: pair(lo), hi: pair(hi) }
    }

    /// The halves the box `[a, b]` reaches, and whether it meets the reach box `[lo, hi]`.
    #[inline]
    pub fn test(&self, a: &[f64; 3], b: &[f64; 3]) -> (u8, bool) {
        use std::arch::x86_64::{__m128d, _mm_and_pd, _mm_cmpge_pd, _mm_cmple_pd, _mm_movemask_pd};
        let (a, b) = (lanes(a), lanes(b));
        // Bits 0 and 1 of a pair's mask are axes 0 and 1; bit 0 of a single's is axis 2.
        let axes = |pair: i32, single: i32| pair | (single & 1) << 2;
        let below = |x: __m128d, y: __m128d| {
            // SAFETY: SSE2 is part of every x86-64 processor; these only compare registers.
            unsafe { _mm_movemask_pd(_mm_cmple_pd(x, y)) }
        };
        let meets = |a: __m128d, b: __m128d, lo: __m128d, hi: __m128d| {
            // SAFETY: as above.
            unsafe { _mm_movemask_pd(_mm_and_pd(_mm_cmple_pd(a, hi), _mm_cmpge_pd(b, lo))) }
        };
        let lower = axes(below(a.0, self.up.0), below(a.1, self.up.1));
        let upper = axes(below(self.down.0, b.0), below(self.down.1, b.1));
        let meets =
            axes(meets(a.0, b.0, self.lo.0, self.hi.0), meets(a.1, b.1, self.lo.1, self.hi.1));
        ((lower | upper << 3) as u8, meets == 7)
    }
}

/// Axes 0 and 1 of `v` in one register, axis 2 in the low lane of another.
#[cfg(target_arch = "x86_64")]
#[inline]
fn lanes(v: &[f64; 3]) -> (std::arch::x86_64::__m128d, std::arch::x86_64::__m128d) {
    use std::arch::x86_64::{_mm_set_pd, _mm_set_sd};
    // SAFETY: SSE2 is part of every x86-64 processor; this only fills registers.
    unsafe { (_mm_set_pd(v[1], v[0]), _mm_set_sd(v[2])) }
}

/// The halves ([`Split::halves`]) of boxes and whether they meet a reach box, for one node.
#[cfg(not(target_arch = "x86_64"))]
#[derive(Clone, Copy)]
pub(super) struct Filter {
    split: Split,
    lo: [f64; 3],
    hi: [f64; 3],
}

#[cfg(not(target_arch = "x86_64"))]
impl Filter {
    #[inline]
    fn new(split: &Split, lo: &[f64; 3], hi: &[f64; 3]) -> Filter {
        Filter { split: *split, lo: *lo, hi: *hi }
    }

    /// The halves the box `[a, b]` reaches, and whether it meets the reach box `[lo, hi]`.
    #[inline]
    pub fn test(&self, a: &[f64; 3], b: &[f64; 3]) -> (u8, bool) {
        (self.split.halves(a, b), crate::embedded::bvh::overlaps(&self.lo, &self.hi, a, b))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::embedded::bvh::overlaps;

    /// Boxes on, off and across every plane and face, with ties: the filter's halves and overlap
    /// are those of the plain comparisons.
    #[test]
    fn the_filter_gives_the_plain_halves_and_overlap() {
        let split = Split::new(&[0.5, 0.5, 0.5], 0.125);
        let (lo, hi) = ([0.25; 3], [0.75; 3]);
        let filter = split.filter(&lo, &hi);
        let values: [f64; 7] = [0.0, 0.25, 0.375, 0.5, 0.625, 0.75, 1.0];
        let mut seen = [false; 64];
        let mut met = [0usize; 2];
        for k in 0..values.len().pow(6) {
            let mut r = k;
            let mut digit = || {
                let v = values[r % values.len()];
                r /= values.len();
                v
            };
            let a = [digit(), digit(), digit()];
            let b = [0, 1, 2].map(|d| a[d].max(digit()));
            let (halves, meets) = filter.test(&a, &b);
            assert_eq!(halves, split.halves(&a, &b), "{a:?} {b:?}");
            assert_eq!(meets, overlaps(&lo, &hi, &a, &b), "{a:?} {b:?}");
            seen[halves as usize] = true;
            met[usize::from(meets)] += 1;
        }
        // Per axis a box reaches the lower half, the upper or both: all 27 sets are met.
        assert_eq!(seen.iter().filter(|&&s| s).count(), 27);
        assert!(met[0] > 1000 && met[1] > 1000, "{met:?}");
    }

    /// A box overlapping a query box reaches every half the query box needs.
    #[test]
    fn needed_halves_are_reached_by_every_overlapping_box() {
        let split = Split::new(&[0.5, 0.5, 0.5], 0.0625);
        let values: [f64; 7] = [0.0, 0.3, 0.4375, 0.5, 0.5625, 0.7, 1.0];
        for k in 0..values.len().pow(4) {
            let v = |s: usize| values[(k / values.len().pow(s as u32)) % values.len()];
            let (qlo, qhi) = ([v(0), 0.1, 0.6], [v(0).max(v(1)), 0.45, 0.9]);
            let (blo, bhi) = ([v(2), 0.0, 0.55], [v(2).max(v(3)), 0.2, 0.7]);
            if overlaps(&qlo, &qhi, &blo, &bhi) {
                let need = split.needed(&qlo, &qhi);
                assert_eq!(
                    split.halves(&blo, &bhi) & need,
                    need,
                    "{qlo:?} {qhi:?} {blo:?} {bhi:?}"
                );
            }
        }
    }
}
