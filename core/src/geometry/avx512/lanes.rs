//! The AVX-512 kernels' token (`Avx512`: proof the CPU has the features) and the lane operations shared by 8- and 16-wide code.

use std::arch::x86_64::*;

/// Proof that this CPU has AVX-512F and AVX-512VL on top of everything `slab8::Avx2` proves
/// (AVX2, FMA, POPCNT, BMI1/2, LZCNT): made only by `detect`, so a kernel holding it may use their
/// instructions. The walks that use it are compiled for them (`#[target_feature]`) and chosen at
/// run time.
#[derive(Clone, Copy, Debug)]
pub struct Avx512(crate::geometry::slab8::Avx2);

impl Avx512 {
    /// The proof, if this CPU has the features (asked once; each call after that is one load).
    #[inline]
    pub fn detect() -> Option<Avx512> {
        static HAS: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
        let avx2 = crate::geometry::slab8::Avx2::detect()?;
        HAS.get_or_init(|| is_x86_feature_detected!("avx512f") && is_x86_feature_detected!("avx512vl"))
            .then_some(Avx512(avx2))
    }

    /// The AVX2 proof this one includes.
    #[inline(always)]
    pub fn avx2(self) -> crate::geometry::slab8::Avx2 {
        self.0
    }
}

/// A vector of `N` floats with AVX-512 masks (eight lanes with VL, or sixteen), so one kernel is
/// written once for both widths: a leaf of up to eight triangles takes the 256-bit form, which on
/// CPUs that split 512-bit operations in two (AMD Zen 4) costs half. Every method is an intrinsic
/// of AVX-512F/VL, compiled with those features (`#[target_feature]`) so that it inlines into
/// kernels compiled with them. Why every kernel function carries the attribute itself rather than
/// rely on being inlined into a walk that has it: a function without the features (a closure,
/// a method LLVM chose not to inline) keeps each intrinsic as an out-of-line call, which measured
/// four to seven times slower than the AVX2 walk.
pub(crate) trait Lanes: Copy {
    const N: usize;
    /// # Safety
    /// For every method: the CPU has AVX-512F and VL (an `Avx512` exists).
    unsafe fn splat(x: f32) -> Self;
    /// Lanes in `mask` loaded from `p + k`, the others zero. # Safety: those lanes are readable.
    unsafe fn load(p: *const f32, mask: u32) -> Self;
    unsafe fn add(self, b: Self) -> Self;
    unsafe fn sub(self, b: Self) -> Self;
    unsafe fn mul(self, b: Self) -> Self;
    unsafe fn div(self, b: Self) -> Self;
    /// `_CMP_*` predicate `P` lane by lane, as bits.
    unsafe fn cmp<const P: i32>(self, b: Self) -> u32;
    /// Bitwise and, xor of the lanes' bits (a sign taken, a sign flipped: exact, unlike `0 − x`).
    unsafe fn and(self, b: Self) -> Self;
    unsafe fn xor(self, b: Self) -> Self;
    /// Lane k into `out[k]`, for `k < N`.
    unsafe fn store(self, out: &mut [f32; 16]);
}

impl Lanes for __m256 {
    const N: usize = 8;
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl")]
    unsafe fn splat(x: f32) -> Self {
        _mm256_set1_ps(x)
    }
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl")]
    unsafe fn load(p: *const f32, mask: u32) -> Self {
        _mm256_maskz_loadu_ps(mask as __mmask8, p)
    }
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl")]
    unsafe fn add(self, b: Self) -> Self {
        _mm256_add_ps(self, b)
    }
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl")]
    unsafe fn sub(self, b: Self) -> Self {
        _mm256_sub_ps(self, b)
    }
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl")]
    unsafe fn mul(self, b: Self) -> Self {
        _mm256_mul_ps(self, b)
    }
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl")]
    unsafe fn div(self, b: Self) -> Self {
        _mm256_div_ps(self, b)
    }
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl")]
    unsafe fn cmp<const P: i32>(self, b: Self) -> u32 {
        _mm256_cmp_ps_mask::<P>(self, b) as u32
    }
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl")]
    unsafe fn store(self, out: &mut [f32; 16]) {
        _mm256_storeu_ps(out.as_mut_ptr(), self)
    }
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl")]
    unsafe fn and(self, b: Self) -> Self {
        _mm256_and_ps(self, b)
    }
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl")]
    unsafe fn xor(self, b: Self) -> Self {
        _mm256_xor_ps(self, b)
    }
}

impl Lanes for __m512 {
    const N: usize = 16;
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl")]
    unsafe fn splat(x: f32) -> Self {
        _mm512_set1_ps(x)
    }
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl")]
    unsafe fn load(p: *const f32, mask: u32) -> Self {
        _mm512_maskz_loadu_ps(mask as __mmask16, p)
    }
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl")]
    unsafe fn add(self, b: Self) -> Self {
        _mm512_add_ps(self, b)
    }
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl")]
    unsafe fn sub(self, b: Self) -> Self {
        _mm512_sub_ps(self, b)
    }
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl")]
    unsafe fn mul(self, b: Self) -> Self {
        _mm512_mul_ps(self, b)
    }
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl")]
    unsafe fn div(self, b: Self) -> Self {
        _mm512_div_ps(self, b)
    }
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl")]
    unsafe fn cmp<const P: i32>(self, b: Self) -> u32 {
        _mm512_cmp_ps_mask::<P>(self, b) as u32
    }
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl")]
    unsafe fn store(self, out: &mut [f32; 16]) {
        _mm512_storeu_ps(out.as_mut_ptr(), self)
    }
    // The float forms of these need AVX-512DQ; the integer ones are AVX-512F.
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl")]
    unsafe fn and(self, b: Self) -> Self {
        _mm512_castsi512_ps(_mm512_and_si512(_mm512_castps_si512(self), _mm512_castps_si512(b)))
    }
    #[inline]
    #[target_feature(enable = "avx512f,avx512vl")]
    unsafe fn xor(self, b: Self) -> Self {
        _mm512_castsi512_ps(_mm512_xor_si512(_mm512_castps_si512(self), _mm512_castps_si512(b)))
    }
}
