//! Equal-count split: the median centroid on the widest axis, found by selection in O(n) rather
//! than a full sort (pbrt-v4 §7.3.1, "SplitMethod::EqualCounts"). Always splits, so it is also the
//! driver's fallback when another strategy cannot. Big nodes select in parallel: a radix select on
//! the sort key's bytes (histograms per chunk), then a parallel partition at the key found.

use crate::bvh::builders::split::splitter::{partition, BuildPrim, NodeInfo, Proposal, Splitter};
use crate::parallel::PARTITION_MIN;
use rayon::prelude::*;

pub struct EqualCount;

impl EqualCount {
    /// The median split of `prims` (two or more): the axis and the partition point.
    pub fn median(prims: &mut [BuildPrim], node: &NodeInfo) -> (u8, usize) {
        let axis = node.centroid_bounds.widest_axis();
        let mid = prims.len() / 2;
        if prims.len() >= PARTITION_MIN {
            select_parallel(prims, axis, mid);
        } else {
            // Ties broken by index so the result does not depend on the input order's accidents.
            prims.select_nth_unstable_by(mid, |a, b| {
                a.centroid()[axis].total_cmp(&b.centroid()[axis]).then(a.index().cmp(&b.index()))
            });
        }
        (axis as u8, mid)
    }
}

/// The order `select_nth_unstable_by` sorts by above, as one integer: the centroid's bits mapped
/// so integers compare as `total_cmp` compares the floats, then the index.
#[inline(always)]
fn key(p: &BuildPrim, axis: usize) -> u64 {
    let bits = p.centroid()[axis].to_bits();
    let ordered = if bits >> 31 == 1 { !bits } else { bits | 1 << 31 };
    (ordered as u64) << 32 | p.index() as u64
}

/// Put the `mid`-th smallest key at `mid`, smaller ones before it, larger ones after, as
/// `select_nth_unstable_by` does: the key's bytes from the top, each found from a histogram of
/// the keys that share the bytes found so far, then two partitions. Every step is a count or a
/// partition in fixed blocks, so the result does not depend on the thread count.
fn select_parallel(prims: &mut [BuildPrim], axis: usize, mid: usize) {
    const CHUNK: usize = 1 << 14;
    let (mut prefix, mut rank) = (0u64, mid);
    for shift in (0..64).step_by(8).rev() {
        // The bytes above `shift` that are already fixed.
        let high = if shift == 56 { 0 } else { !0u64 << (shift + 8) };
        let hist = crate::parallel::region(|| {
            prims
                .par_chunks(CHUNK)
                .map(|c| {
                    let mut h = [0u32; 256];
                    for k in c.iter().map(|p| key(p, axis)).filter(|k| k & high == prefix) {
                        h[(k >> shift) as usize & 255] += 1;
                    }
                    h
                })
                .reduce(
                    || [0; 256],
                    |mut a, b| {
                        a.iter_mut().zip(b).for_each(|(x, y)| *x += y);
                        a
                    },
                )
        });
        let mut byte = 0;
        while rank >= hist[byte] as usize {
            rank -= hist[byte] as usize;
            byte += 1;
        }
        prefix |= (byte as u64) << shift;
    }
    // `prefix` is the mid-th key; `rank` counts the keys equal to it that come before `mid`.
    let less = partition(prims, |p| key(p, axis) < prefix);
    debug_assert_eq!(less + rank, mid);
    partition(&mut prims[less..], |p| key(p, axis) == prefix);
}

impl Splitter for EqualCount {
    fn split(&mut self, prims: &mut [BuildPrim], node: &NodeInfo) -> Proposal {
        let (axis, mid) = Self::median(prims, node);
        let plane = prims[mid].centroid()[axis as usize];
        Proposal::Split { axis, mid, weighted: None, plane }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Aabb;

    /// The parallel selection puts the same key at `mid` as the serial one, with the keys on
    /// each side in place, also with repeated keys (an SBVH's references share indices).
    #[test]
    fn the_parallel_median_is_the_serial_one() {
        let mut rng = crate::random::Rng::new(5);
        let n = PARTITION_MIN + 999;
        let prims: Vec<BuildPrim> = (0..n)
            .map(|i| {
                let c = glam::Vec3::new(rng.range(-4.0, 4.0).round(), rng.unit(), 0.0);
                BuildPrim::new(Aabb::new(c, c), (i % 5000) as u32)
            })
            .collect();
        for axis in 0..2 {
            let mid = n / 2;
            let mut serial = prims.clone();
            serial.select_nth_unstable_by(mid, |a, b| key(a, axis).cmp(&key(b, axis)));
            let mut par = prims.clone();
            select_parallel(&mut par, axis, mid);
            let pivot = key(&par[mid], axis);
            assert_eq!(pivot, key(&serial[mid], axis));
            assert!(par[..mid].iter().all(|p| key(p, axis) <= pivot));
            assert!(par[mid..].iter().all(|p| key(p, axis) >= pivot));
        }
        // The key orders as total_cmp does, negative zero and infinities included.
        let at = |x: f32| key(&BuildPrim::new(Aabb::new(glam::Vec3::splat(x), glam::Vec3::splat(x)), 0), 0);
        let xs = [f32::NEG_INFINITY, -2.0, -0.0, 0.0, 1e-30, 3.0, f32::INFINITY];
        assert!(xs.windows(2).all(|w| at(w[0]) < at(w[1])));
    }
}
