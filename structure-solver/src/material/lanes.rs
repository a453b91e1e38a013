//! The arithmetic of the blocked kernels: `f64` for one element, [`Lanes`] for a block of
//! elements processed side by side so the compiler emits SIMD (DESIGN §6, "blocked form").
//!
//! Kernels are written once, generic over [`Real`]; branches become masks and `select`.

use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

/// A scalar or a block of lanes with elementwise arithmetic.
pub trait Real:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + AddAssign
    + SubAssign
    + MulAssign
{
    /// Lane mask of comparisons.
    type Mask: Copy;
    fn splat(v: f64) -> Self;
    fn sqrt(self) -> Self;
    fn abs(self) -> Self;
    fn max(self, o: Self) -> Self;
    fn min(self, o: Self) -> Self;
    /// `self > o` per lane.
    fn gt(self, o: Self) -> Self::Mask;
    /// `a` where `m`, else `b`, per lane.
    fn select(m: Self::Mask, a: Self, b: Self) -> Self;
    /// `true` when some lane of `m` is set.
    fn any(m: Self::Mask) -> bool;
}

impl Real for f64 {
    type Mask = bool;
    #[inline(always)]
    fn splat(v: f64) -> Self {
        v
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        f64::abs(self)
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        f64::max(self, o)
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        f64::min(self, o)
    }
    #[inline(always)]
    fn gt(self, o: Self) -> bool {
        self > o
    }
    #[inline(always)]
    fn select(m: bool, a: Self, b: Self) -> Self {
        if m {
            a
        } else {
            b
        }
    }
    #[inline(always)]
    fn any(m: bool) -> bool {
        m
    }
}

/// `N` values processed together.
#[derive(Debug, Clone, Copy, PartialEq)]
#[repr(C, align(64))]
pub struct Lanes<const N: usize>(pub [f64; N]);

macro_rules! lanewise {
    ($tr:ident, $f:ident, $op:tt, $atr:ident, $af:ident) => {
        impl<const N: usize> $tr for Lanes<N> {
            type Output = Self;
            #[inline(always)]
            fn $f(self, o: Self) -> Self {
                let mut r = self.0;
                for i in 0..N {
                    r[i] = self.0[i] $op o.0[i];
                }
                Lanes(r)
            }
        }
        impl<const N: usize> $atr for Lanes<N> {
            #[inline(always)]
            fn $af(&mut self, o: Self) {
                for i in 0..N {
                    self.0[i] = self.0[i] $op o.0[i];
                }
            }
        }
    };
}
lanewise!(Add, add, +, AddAssign, add_assign);
lanewise!(Sub, sub, -, SubAssign, sub_assign);
lanewise!(Mul, mul, *, MulAssign, mul_assign);

impl<const N: usize> Div for Lanes<N> {
    type Output = Self;
    #[inline(always)]
    fn div(self, o: Self) -> Self {
        Lanes(std::array::from_fn(|i| self.0[i] / o.0[i]))
    }
}

impl<const N: usize> Neg for Lanes<N> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Lanes(self.0.map(|v| -v))
    }
}

impl<const N: usize> Real for Lanes<N> {
    type Mask = [u64; N];
    #[inline(always)]
    fn splat(v: f64) -> Self {
        Lanes([v; N])
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Lanes(self.0.map(f64::sqrt))
    }
    #[inline(always)]
    fn abs(self) -> Self {
        Lanes(self.0.map(f64::abs))
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        Lanes(std::array::from_fn(|i| if self.0[i] > o.0[i] { self.0[i] } else { o.0[i] }))
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        Lanes(std::array::from_fn(|i| if self.0[i] < o.0[i] { self.0[i] } else { o.0[i] }))
    }
    /// All bits set where true: the form of a vector comparison, so `select` is a blend.
    #[inline(always)]
    fn gt(self, o: Self) -> [u64; N] {
        std::array::from_fn(|i| if self.0[i] > o.0[i] { u64::MAX } else { 0 })
    }
    #[inline(always)]
    fn select(m: [u64; N], a: Self, b: Self) -> Self {
        Lanes(std::array::from_fn(|i| {
            f64::from_bits((a.0[i].to_bits() & m[i]) | (b.0[i].to_bits() & !m[i]))
        }))
    }
    #[inline(always)]
    fn any(m: [u64; N]) -> bool {
        m.iter().fold(0, |acc, &v| acc | v) != 0
    }
}

/// Eight lanes read from and written to arrays: the blocks of the element kernels, as
/// [`Lanes`] or as vector registers of one instruction set (`lanes_x86`).
pub trait Block8: Real {
    fn from_array(a: [f64; 8]) -> Self;
    fn to_array(self) -> [f64; 8];
}

impl Block8 for Lanes<8> {
    #[inline(always)]
    fn from_array(a: [f64; 8]) -> Self {
        Lanes(a)
    }
    #[inline(always)]
    fn to_array(self) -> [f64; 8] {
        self.0
    }
}
