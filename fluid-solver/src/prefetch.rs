//! Cache prefetch hints for the passes that walk scattered mesh rows (the tracking's near
//! nodes): asking for the rows of a node a few places ahead hides the wait for memory behind the
//! work on the current one. A hint never changes a result.

/// Asks the cache for the line holding `slice[i]`; nothing when `i` is past the end.
#[inline(always)]
pub fn prefetch<T>(slice: &[T], i: usize) {
    if i < slice.len() {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: a prefetch is a hint that never faults and reads nothing into the program;
        // the address is in bounds, and SSE (the instruction's feature) is part of x86-64.
        unsafe {
            use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
            _mm_prefetch::<_MM_HINT_T0>(slice.as_ptr().add(i).cast::<i8>());
        }
    }
}
