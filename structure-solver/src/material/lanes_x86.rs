//! Eight `f64` lanes in the vector registers of an x86-64 instruction set chosen at run time:
//! one AVX-512 register ([`Avx512`]) or two AVX2 registers ([`Avx2`]). A block kernel written
//! over [`Real`] then compiles to one vector instruction (or two) per operation, whatever the
//! compiler's vectoriser would make of the lane loops of [`Lanes`](super::lanes::Lanes). The
//! operations are the IEEE ones of `Lanes` (no fused multiply-adds; negation and absolute
//! value on the sign bit; `max`, `min` as the compare-and-select of `Lanes`), so the results
//! are the same bits.
//!
//! Invariant: the types are crate-private, and their values are made only by block kernels
//! entered through `elements::bt4::SimdPath::run` on a path the processor was checked to
//! have (`SimdPath::is_supported`), in functions compiled with its instruction set; the
//! `// SAFETY:` comments below rest on it.

use std::arch::x86_64::*;
use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

use super::lanes::{Block8, Real};

/// Eight lanes in one AVX-512 register.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Avx512(__m512d);

/// Eight lanes in two AVX2 registers.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Avx2([__m256d; 2]);

/// Arithmetic from one intrinsic per register, written out (no closures, so that every
/// intrinsic is inlined into the kernel compiled with its instruction set).
macro_rules! arithmetic {
    ($t:ident, $apply:ident, $(($tr:ident, $f:ident, $atr:ident, $af:ident, $op:ident)),*) => {
        $(
            impl $tr for $t {
                type Output = Self;
                #[inline(always)]
                fn $f(self, o: Self) -> Self {
                    $apply!(self, o, $op)
                }
            }
            impl $atr for $t {
                #[inline(always)]
                fn $af(&mut self, o: Self) {
                    *self = $apply!(*self, o, $op);
                }
            }
        )*
    };
}

macro_rules! apply512 {
    ($a:expr, $b:expr, $op:ident) => {
        // SAFETY: module invariant (the processor has AVX-512 F and DQ).
        Avx512(unsafe { $op($a.0, $b.0) })
    };
}

macro_rules! apply256 {
    ($a:expr, $b:expr, $op:ident) => {{
        let (a, b) = ($a.0, $b.0);
        // SAFETY: module invariant (the processor has AVX).
        Avx2(unsafe { [$op(a[0], b[0]), $op(a[1], b[1])] })
    }};
}

arithmetic!(
    Avx512,
    apply512,
    (Add, add, AddAssign, add_assign, _mm512_add_pd),
    (Sub, sub, SubAssign, sub_assign, _mm512_sub_pd),
    (Mul, mul, MulAssign, mul_assign, _mm512_mul_pd)
);

impl Div for Avx512 {
    type Output = Self;
    #[inline(always)]
    fn div(self, o: Self) -> Self {
        apply512!(self, o, _mm512_div_pd)
    }
}

impl Neg for Avx512 {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        apply512!(self, Self::splat(-0.0), _mm512_xor_pd)
    }
}

impl Real for Avx512 {
    type Mask = __mmask8;
    #[inline(always)]
    fn splat(v: f64) -> Self {
        // SAFETY: module invariant (the processor has AVX-512 F).
        Avx512(unsafe { _mm512_set1_pd(v) })
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        // SAFETY: module invariant (the processor has AVX-512 F).
        Avx512(unsafe { _mm512_sqrt_pd(self.0) })
    }
    #[inline(always)]
    fn abs(self) -> Self {
        apply512!(Self::splat(-0.0), self, _mm512_andnot_pd)
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        Self::select(self.gt(o), self, o)
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        Self::select(o.gt(self), self, o)
    }
    #[inline(always)]
    fn gt(self, o: Self) -> __mmask8 {
        // SAFETY: module invariant (the processor has AVX-512 F).
        unsafe { _mm512_cmp_pd_mask::<_CMP_GT_OQ>(self.0, o.0) }
    }
    #[inline(always)]
    fn select(m: __mmask8, a: Self, b: Self) -> Self {
        // SAFETY: module invariant (the processor has AVX-512 F).
        Avx512(unsafe { _mm512_mask_blend_pd(m, b.0, a.0) })
    }
    #[inline(always)]
    fn any(m: __mmask8) -> bool {
        m != 0
    }
}

impl Block8 for Avx512 {
    #[inline(always)]
    fn from_array(a: [f64; 8]) -> Self {
        // SAFETY: module invariant (AVX-512 F); `a` holds the 8 values read.
        Avx512(unsafe { _mm512_loadu_pd(a.as_ptr()) })
    }
    #[inline(always)]
    fn to_array(self) -> [f64; 8] {
        let mut a = [0.0; 8];
        // SAFETY: module invariant (AVX-512 F); `a` has room for the 8 values written.
        unsafe { _mm512_storeu_pd(a.as_mut_ptr(), self.0) };
        a
    }
}

arithmetic!(
    Avx2,
    apply256,
    (Add, add, AddAssign, add_assign, _mm256_add_pd),
    (Sub, sub, SubAssign, sub_assign, _mm256_sub_pd),
    (Mul, mul, MulAssign, mul_assign, _mm256_mul_pd)
);

impl Div for Avx2 {
    type Output = Self;
    #[inline(always)]
    fn div(self, o: Self) -> Self {
        apply256!(self, o, _mm256_div_pd)
    }
}

impl Neg for Avx2 {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        apply256!(self, Self::splat(-0.0), _mm256_xor_pd)
    }
}

impl Real for Avx2 {
    /// All bits set in the lanes where true, as the comparisons give it.
    type Mask = [__m256d; 2];
    #[inline(always)]
    fn splat(v: f64) -> Self {
        // SAFETY: module invariant (the processor has AVX).
        let r = unsafe { _mm256_set1_pd(v) };
        Avx2([r, r])
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        let a = self.0;
        // SAFETY: module invariant (the processor has AVX).
        Avx2(unsafe { [_mm256_sqrt_pd(a[0]), _mm256_sqrt_pd(a[1])] })
    }
    #[inline(always)]
    fn abs(self) -> Self {
        apply256!(Self::splat(-0.0), self, _mm256_andnot_pd)
    }
    #[inline(always)]
    fn max(self, o: Self) -> Self {
        Self::select(self.gt(o), self, o)
    }
    #[inline(always)]
    fn min(self, o: Self) -> Self {
        Self::select(o.gt(self), self, o)
    }
    #[inline(always)]
    fn gt(self, o: Self) -> [__m256d; 2] {
        let (a, b) = (self.0, o.0);
        // SAFETY: module invariant (the processor has AVX).
        unsafe {
            [_mm256_cmp_pd::<_CMP_GT_OQ>(a[0], b[0]), _mm256_cmp_pd::<_CMP_GT_OQ>(a[1], b[1])]
        }
    }
    #[inline(always)]
    fn select(m: [__m256d; 2], a: Self, b: Self) -> Self {
        let (a, b) = (a.0, b.0);
        // SAFETY: module invariant (the processor has AVX).
        Avx2(unsafe { [_mm256_blendv_pd(b[0], a[0], m[0]), _mm256_blendv_pd(b[1], a[1], m[1])] })
    }
    #[inline(always)]
    fn any(m: [__m256d; 2]) -> bool {
        // SAFETY: module invariant (the processor has AVX).
        unsafe { _mm256_movemask_pd(_mm256_or_pd(m[0], m[1])) != 0 }
    }
}

impl Block8 for Avx2 {
    #[inline(always)]
    fn from_array(a: [f64; 8]) -> Self {
        // SAFETY: module invariant (AVX); `a` holds the 8 values read, 4 from each offset.
        unsafe { Avx2([_mm256_loadu_pd(a.as_ptr()), _mm256_loadu_pd(a.as_ptr().add(4))]) }
    }
    #[inline(always)]
    fn to_array(self) -> [f64; 8] {
        let mut a = [0.0; 8];
        // SAFETY: module invariant (AVX); `a` has room for the 8 values, 4 at each offset.
        unsafe {
            _mm256_storeu_pd(a.as_mut_ptr(), self.0[0]);
            _mm256_storeu_pd(a.as_mut_ptr().add(4), self.0[1]);
        }
        a
    }
}
