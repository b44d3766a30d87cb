//! Which SIMD kernels this CPU runs, decided once at run time: AVX-512 where the CPU has AVX-512F
//! and VL on top of AVX2, else AVX2 where it has AVX2 and FMA (`is_x86_feature_detected!`), else
//! four-lane SIMD (SSE2 on every x86-64, NEON on aarch64), else one box at a time. Users need no
//! `-C target-cpu` flag; a build for another architecture takes the portable path.
//! `BVHSCOPE_SIMD=scalar|simd4|avx2|avx512` asks for a lower level than the CPU offers (for
//! comparing kernels, and for tests); asking for one it lacks gives what it has.
//! Every kernel computes the same results bit for bit (`geometry::slab::SlabKernel`).

use std::sync::OnceLock;

/// A kernel family, from the most portable to the fastest.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Simd {
    /// One box or triangle at a time.
    Scalar,
    /// Four lanes (`wide::f32x4`): SSE2 on x86-64, NEON on aarch64.
    Simd4,
    /// Eight lanes with AVX2 (x86-64 only, when the CPU has AVX2 and FMA).
    Avx2,
    /// AVX-512F and VL on top of AVX2 (x86-64 only): the eight-box test with mask registers, a
    /// leaf's triangles in one pass of up to sixteen lanes, packets in groups of sixteen rays
    /// (`geometry::avx512`).
    Avx512,
}

impl Simd {
    pub const ALL: [Simd; 4] = [Simd::Scalar, Simd::Simd4, Simd::Avx2, Simd::Avx512];

    pub fn name(self) -> &'static str {
        match self {
            Simd::Scalar => "scalar",
            Simd::Simd4 => "simd4",
            Simd::Avx2 => "avx2",
            Simd::Avx512 => "avx512",
        }
    }

    /// The best level this CPU has.
    pub fn detected() -> Simd {
        #[cfg(target_arch = "x86_64")]
        if crate::geometry::avx512::Avx512::detect().is_some() {
            return Simd::Avx512;
        }
        #[cfg(target_arch = "x86_64")]
        if crate::geometry::slab8::Avx2::detect().is_some() {
            return Simd::Avx2;
        }
        Simd::Simd4
    }

    /// The level the traversals use: the detected one, or a lower one `BVHSCOPE_SIMD` asks for.
    pub fn chosen() -> Simd {
        static CHOSEN: OnceLock<Simd> = OnceLock::new();
        *CHOSEN.get_or_init(|| {
            let asked = std::env::var("BVHSCOPE_SIMD").ok();
            let asked = asked.and_then(|v| Simd::ALL.into_iter().find(|s| s.name() == v.trim().to_lowercase()));
            asked.map_or(Simd::detected(), |a| a.min(Simd::detected()))
        })
    }

    /// `self` if this CPU can run it, else the best level it has below.
    pub fn available(self) -> Simd {
        self.min(Simd::detected())
    }
}
