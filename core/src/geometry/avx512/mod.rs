//! The AVX-512 kernels, chosen at run time where the CPU has AVX-512F and VL (`crate::cpu`), as the
//! AVX2 ones are: the eight-box slab test with its compare going straight into a mask register
//! (`slab8`), one ray against a leaf of up to sixteen triangles in one pass with masked loads
//! (`leaf`; `stored_leaf` for the stored edges and normal), and packets in groups of sixteen
//! rays (`packet`). Each computes what the scalar kernel computes, operation for operation (sign-selected planes and `max_keep`/`min_keep` NaN rule and
//! `SLACK` of `slab.rs`; the watertight test's arithmetic of `triangle.rs`), nothing fused, so
//! results and counts are the same bit for bit whichever kernel runs; the tests force each one.

pub(crate) mod lanes;
pub(crate) mod leaf;
pub(crate) mod packet;
mod slab8;
mod stored_leaf;

pub(crate) use leaf::watertight_leaf16;
pub use leaf::Hits16;
pub use slab8::RayX8Masked;
pub(crate) use stored_leaf::stored_leaf16;

pub use lanes::Avx512;
