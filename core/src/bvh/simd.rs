//! SIMD helpers shared by the traversals that test four boxes (wide nodes) or four rays (packets)
//! at once with the `wide` crate's `f32x4` (SSE on x86-64, NEON on aarch64, arrays elsewhere), and
//! the cache prefetch the wide traversal issues for the children it pushes.

use wide::f32x4;

/// `max(t, acc)` where a NaN `t` (0·inf: the ray lies in a slab plane) leaves `acc` unchanged, the
/// same rule as the scalar slab test (`f32::max` ignores a NaN). SSE's maxps returns its second
/// operand on NaN; elsewhere the NaN-aware `max` is used.
#[inline(always)]
pub fn max_keep(t: f32x4, acc: f32x4) -> f32x4 {
    if cfg!(any(target_arch = "x86", target_arch = "x86_64")) {
        t.fast_max(acc)
    } else {
        t.max(acc)
    }
}

/// `min(t, acc)` with the same NaN rule as `max_keep`.
#[inline(always)]
pub fn min_keep(t: f32x4, acc: f32x4) -> f32x4 {
    if cfg!(any(target_arch = "x86", target_arch = "x86_64")) {
        t.fast_min(acc)
    } else {
        t.min(acc)
    }
}

/// Ask the CPU to start loading `p` (a node or triangle the traversal will probably visit soon)
/// into the cache. Incoherent rays spend much of their time waiting for memory, and a child pushed
/// on the stack is popped tens of nodes later. A hint only: it never changes a result.
#[inline(always)]
pub fn prefetch<T>(p: &T) {
    #[cfg(target_arch = "x86_64")]
    for line in (0..std::mem::size_of::<T>()).step_by(64) {
        // SAFETY: a prefetch never faults and reads nothing into the program; the address lies
        // inside `*p`, a live reference.
        unsafe {
            use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
            _mm_prefetch::<_MM_HINT_T0>((p as *const T).cast::<i8>().add(line));
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = p;
}
