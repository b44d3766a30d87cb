//! The cache prefetch the wide traversal issues for the children it pushes. (The SIMD slab tests
//! are in `geometry::slab`.)

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
