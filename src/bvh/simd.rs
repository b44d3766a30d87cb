//! SIMD helpers shared by the traversals that test four boxes (wide nodes) or four rays (packets)
//! at once with the `wide` crate's `f32x4` (SSE on x86-64, NEON on aarch64, arrays elsewhere).

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
