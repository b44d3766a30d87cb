//! A heatmap's min, max and mean over millions of pixels, in parallel, equal to the serial loop's
//! to the last bit (the legend drawn into an image must not change with the thread count).

use rayon::prelude::*;

/// What `exact_stats` gathers of a chunk's values.
#[derive(Clone, Copy)]
pub(super) struct Acc {
    lo: f32,
    hi: f32,
    sum: f64,
    n: u64,
    /// The sum of the magnitudes.
    magnitude: f64,
    /// The exponent of the lowest set bit of any value (`lowest_bit`).
    lowest: i32,
    finite: bool,
}

impl Acc {
    const EMPTY: Acc = Acc {
        lo: f32::INFINITY,
        hi: f32::NEG_INFINITY,
        sum: 0.0,
        n: 0,
        magnitude: 0.0,
        lowest: i32::MAX,
        finite: true,
    };

    #[inline]
    pub(super) fn add(&mut self, v: f32) {
        self.lo = self.lo.min(v);
        self.hi = self.hi.max(v);
        self.sum += v as f64;
        self.n += 1;
        self.magnitude += v.abs() as f64;
        self.lowest = self.lowest.min(lowest_bit(v));
        self.finite &= v.is_finite();
    }

    fn join(self, b: Acc) -> Acc {
        Acc {
            lo: self.lo.min(b.lo),
            hi: self.hi.max(b.hi),
            sum: self.sum + b.sum,
            n: self.n + b.n,
            magnitude: self.magnitude + b.magnitude,
            lowest: self.lowest.min(b.lowest),
            finite: self.finite && b.finite,
        }
    }
}

/// Min, max, sum (in f64) and count of the values `each` adds for the items, in parallel over
/// `chunk` of them at a time; `None` where the sum could differ from the serial loop's.
///
/// Min and max do not depend on the order. The sum does where f64 rounds, so it is only taken
/// where no partial sum rounds in any order: every value is a whole multiple of 2^e (the lowest
/// set bit over all values) and the sum of their magnitudes stays below 2^52 · 2^e (a bit below
/// f64's 53, for the rounding of that bound itself). Counts of nodes and tests, and costs with the
/// usual constants, are; otherwise the caller sums serially, so the legend's mean never changes.
pub(super) fn exact_stats<T: Sync>(
    items: &[T],
    chunk: usize,
    each: impl Fn(&[T], &mut Acc) + Sync,
) -> Option<(f32, f32, f64, u64)> {
    let parts: Vec<Acc> = crate::parallel::region(|| {
        items
            .par_chunks(chunk)
            .map(|chunk| {
                let mut acc = Acc::EMPTY;
                each(chunk, &mut acc);
                acc
            })
            .collect()
    });
    let all = parts.into_iter().fold(Acc::EMPTY, Acc::join);
    let exact = all.finite && (all.lowest == i32::MAX || all.magnitude < 2f64.powi(52 + all.lowest));
    exact.then_some((all.lo, all.hi, all.sum, all.n))
}

/// The exponent of the lowest set bit of `v` (i32::MAX for zero): `v` is a whole multiple of
/// 2^that.
fn lowest_bit(v: f32) -> i32 {
    let bits = v.to_bits() & 0x7fff_ffff;
    let (field, fraction) = (bits >> 23, bits & 0x7f_ffff);
    let (mantissa, exp) = if field == 0 { (fraction, -149) } else { (fraction | 0x80_0000, field as i32 - 150) };
    if mantissa == 0 {
        i32::MAX
    } else {
        exp + mantissa.trailing_zeros() as i32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn serial(values: &[f32]) -> (f32, f32, f64, u64) {
        let (mut lo, mut hi, mut sum) = (f32::INFINITY, f32::NEG_INFINITY, 0f64);
        for &v in values {
            (lo, hi, sum) = (lo.min(v), hi.max(v), sum + v as f64);
        }
        (lo, hi, sum, values.len() as u64)
    }

    fn parallel(values: &[f32], threads: usize) -> Option<(f32, f32, f64, u64)> {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| exact_stats(values, 7, |c, acc| c.iter().for_each(|&v| acc.add(v))))
    }

    #[test]
    fn the_lowest_set_bit_is_found_in_normal_and_subnormal_numbers() {
        assert_eq!(lowest_bit(0.0), i32::MAX);
        assert_eq!(lowest_bit(-0.0), i32::MAX);
        assert_eq!(lowest_bit(1.0), 0);
        assert_eq!(lowest_bit(12.0), 2);
        assert_eq!(lowest_bit(-2.5), -1);
        assert_eq!(lowest_bit(0.1), -27, "13421773 · 2^-27");
        assert_eq!(lowest_bit(f32::from_bits(1)), -149);
        assert_eq!(lowest_bit(f32::MAX), 127 - 23);
    }

    /// Where the sum is taken it equals the serial loop's, bit for bit; where it could differ,
    /// none is given.
    #[test]
    fn a_sum_is_given_only_where_it_is_the_serial_one() {
        let mut rng = crate::random::Rng::new(7);
        let counts: Vec<f32> = (0..10_000).map(|_| rng.below(500) as f32).collect();
        let halves: Vec<f32> = counts.iter().map(|c| c * 1.5 + 0.5).collect();
        for values in [&counts[..], &halves[..], &[][..], &[0.0, 0.0][..]] {
            for threads in [1, 3] {
                let got = parallel(values, threads).expect("whole multiples of 2^-1: exact");
                assert_eq!(got.3, values.len() as u64);
                let want = serial(values);
                assert_eq!((got.0, got.1, got.2.to_bits(), got.3), (want.0, want.1, want.2.to_bits(), want.3));
            }
        }
        // Values a sum of which rounds: none, and the caller sums serially.
        let rounding: Vec<f32> = (0..1000).map(|i| if i % 2 == 0 { rng.unit() } else { 1e20 }).collect();
        let tiny_and_huge = [1e30f32, f32::from_bits(1)];
        assert_eq!(parallel(&rounding, 3), None);
        assert_eq!(parallel(&tiny_and_huge, 1), None);
        assert_eq!(parallel(&[1.0, f32::INFINITY], 1), None);
        assert_eq!(parallel(&[1.0, f32::NAN], 1), None);
    }
}
