//! The one seeded random generator of bvhscope: the checker's random rays, and the tests' and
//! benchmarks' random cases, repeat from run to run. SplitMix64 (Steele, Lea & Flood, "Fast
//! splittable pseudorandom number generators", OOPSLA 2014): one add and a mix per number, and
//! `at(seed, i)` gives the i-th number of a stream without the ones before it, so that a stream
//! can be cut into batches traced on any number of threads and still give the same rays.

/// A SplitMix64 stream.
#[derive(Clone, Debug)]
pub struct Rng(u64);

const GOLDEN: u64 = 0x9E37_79B9_7F4A_7C15;

/// SplitMix64's mixing function.
#[inline]
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

impl Rng {
    pub fn new(seed: u64) -> Self {
        Rng(seed)
    }

    /// The stream of `seed` from its `i`-th number on (`Rng::new(seed)` after `i` calls).
    pub fn at(seed: u64, i: u64) -> Self {
        Rng(seed.wrapping_add(GOLDEN.wrapping_mul(i)))
    }

    #[inline]
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(GOLDEN);
        mix(self.0)
    }

    /// Uniform in [0, 1), on a grid of 2⁻²⁴ (every value exactly representable).
    #[inline]
    pub fn unit(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// Uniform in [lo, hi).
    #[inline]
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.unit()
    }

    /// A ray at a box (`center`, `extent`): from a random point of the box three times its size
    /// towards a random point in it, as (origin, direction). What the checker's random rays and
    /// many tests trace.
    pub fn ray_at(&mut self, center: glam::Vec3, extent: glam::Vec3) -> (glam::Vec3, glam::Vec3) {
        let mut v = || glam::Vec3::new(self.unit() - 0.5, self.unit() - 0.5, self.unit() - 0.5);
        let o = center + v() * extent * 3.0;
        let t = center + v() * extent;
        (o, t - o)
    }

    /// `n` rays at the box of `b` (`ray_at`), from seed `seed`.
    pub fn rays_at(seed: u64, n: usize, bounds: (glam::Vec3, glam::Vec3)) -> Vec<(glam::Vec3, glam::Vec3)> {
        let (lo, hi) = bounds;
        let (center, extent) = ((lo + hi) * 0.5, (hi - lo).max(glam::Vec3::splat(1e-6)));
        let mut r = Rng::new(seed);
        (0..n).map(|_| r.ray_at(center, extent)).collect()
    }

    /// Uniform in 0..n (n > 0).
    #[inline]
    pub fn below(&mut self, n: u64) -> u64 {
        // Multiply-shift: no modulo bias worth the name for the n we draw from.
        ((self.next_u64() as u128 * n as u128) >> 64) as u64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_stream_can_be_entered_anywhere() {
        let mut a = Rng::new(42);
        let first: Vec<u64> = (0..10).map(|_| a.next_u64()).collect();
        for (i, &f) in first.iter().enumerate() {
            assert_eq!(Rng::at(42, i as u64).next_u64(), f);
        }
        // SplitMix64's published first output for seed 0.
        assert_eq!(Rng::new(0).next_u64(), 0xE220_A839_7B1D_CDAF);
    }

    #[test]
    fn units_stay_in_range_and_spread() {
        let mut r = Rng::new(7);
        let v: Vec<f32> = (0..10_000).map(|_| r.unit()).collect();
        assert!(v.iter().all(|&x| (0.0..1.0).contains(&x)));
        let mean = v.iter().sum::<f32>() / v.len() as f32;
        assert!((mean - 0.5).abs() < 0.02, "{mean}");
        assert!((0..1000).all(|_| r.below(3) < 3));
    }
}
