//! Binned SAH: on each axis, drop centroids into `bins` equal-width bins, sweep the bins to get the
//! cost of each of the `bins - 1` planes, and keep the cheapest plane of all three axes — or make a
//! leaf when that is cheaper. Wald, "On fast Construction of SAH-based Bounding Volume Hierarchies"
//! (RT 2007); pbrt-v4 §7.3.2. The bins live in the build's scratch memory and all three axes are
//! binned in one pass over the triangles, so a node costs O(n + bins), with no per-node allocation
//! below the top levels; big nodes are binned in parallel chunks.

use crate::bvh::builders::split::splitter::{is_active, partition, BuildPrim, NodeInfo, PlaneSink, Proposal, Splitter};
use crate::bvh::params::BuildParams;
use crate::geometry::Aabb;
use glam::{BVec4A, Vec3, Vec3A, Vec4};
use rayon::prelude::*;

/// Upper bound on the bin count.
pub const MAX_BINS: usize = 256;

/// Nodes with at least this many triangles are binned in parallel.
const PARALLEL_BINNING_MIN: usize = 1 << 15;

/// One bin: the triangles' bounds and count.
#[derive(Clone, Copy, Debug)]
pub struct Bin {
    bounds: Aabb,
    count: u32,
}

impl Bin {
    const EMPTY: Bin = Bin { bounds: Aabb::EMPTY, count: 0 };

    #[inline(always)]
    fn merge(&mut self, o: &Bin) {
        self.count += o.count;
        self.bounds = self.bounds.union(o.bounds);
    }
}

/// Bin indices of a scaled centroid offset on the three axes (lane 3 unused), clamped to
/// `0..=top`. NaN lands in bin 0: SSE's max returns its second operand on NaN, and elsewhere the
/// float-to-int cast maps NaN to 0. One SIMD conversion on x86-64, where the per-lane saturating
/// casts cost a dozen instructions per triangle in the build's hottest loop.
#[inline(always)]
fn bin_indices(scaled: Vec3A, top: Vec3A) -> [u32; 4] {
    let clamped = scaled.max(Vec3A::ZERO).min(top);
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{__m128, __m128i, _mm_cvttps_epi32};
        // SAFETY: SSE2 is part of the x86-64 baseline. (The clamp above keeps every lane in 0..=top,
        // so the conversion is exact; `__m128::from` needs glam's SSE2 backend, its default there.)
        let i: __m128i = unsafe { _mm_cvttps_epi32(__m128::from(clamped)) };
        // SAFETY: __m128i and [u32; 4] have the same size, and any bits are a valid u32.
        unsafe { std::mem::transmute::<__m128i, [u32; 4]>(i) }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        let u = clamped.as_uvec3();
        [u.x, u.y, u.z, 0]
    }
}

/// The binned SAH with its scratch: the bins of the three axes, and per plane the right side's
/// area on each axis (lanes 0..3).
pub struct SahBinned {
    max_bins: usize,
    bins: Vec<Bin>,
    plane_areas: Vec<Vec4>,
}

impl SahBinned {
    pub fn new(params: &BuildParams) -> Self {
        Self { max_bins: params.sah_bins as usize, bins: Vec::new(), plane_areas: Vec::new() }
    }
}

impl Splitter for SahBinned {
    fn prices_splits(&self) -> bool {
        true
    }

    fn split(&mut self, prims: &mut [BuildPrim], node: &NodeInfo) -> Proposal {
        binned(prims, node, self.max_bins, &mut self.bins, &mut self.plane_areas, &mut ())
    }
}

/// The binned SAH over `prims` (partitioned by its choice) with at most `max_bins` bins, reporting
/// every plane between bins that has triangles on both sides to `sink`: the node inspector's
/// stepped cost curve. Two triangles are split directly, without bins or reports.
pub fn binned_planes(prims: &mut [BuildPrim], node: &NodeInfo, max_bins: usize, sink: &mut impl PlaneSink) -> Proposal {
    binned(prims, node, max_bins, &mut Vec::new(), &mut Vec::new(), sink)
}

/// The bins a node of `n` triangles is binned into: n/3 (at least 4), at most `max_bins`.
pub fn bins_for(n: usize, max_bins: usize) -> usize {
    max_bins.min((n / 3).max(4)).clamp(2, MAX_BINS)
}

fn binned<P: PlaneSink>(
    prims: &mut [BuildPrim],
    node: &NodeInfo,
    max_bins: usize,
    all: &mut Vec<Bin>,
    right_area: &mut Vec<Vec4>,
    sink: &mut P,
) -> Proposal {
    let n = prims.len();
    let cb = node.centroid_bounds;
    let extent = cb.max - cb.min;
    if n == 2 {
        return split_two(prims, extent);
    }
    // A node of n triangles fills at most n bins per axis, and planes between bins of one or two
    // centroids seldom beat their neighbours; the sweeps, not the binning, are the cost of the
    // many small nodes near the leaves. So a node gets n/3 bins (at least 4) up to the maximum:
    // a faster build for a tenth of a percent of SAH cost (BENCHMARKS.md, "Ninth round").
    let bins = bins_for(n, max_bins);
    // Axes with no extent cannot be split by a plane; their scale 0 puts everything in bin 0.
    let scale: [f32; 3] = std::array::from_fn(|a| if extent[a] > 0.0 { bins as f32 / extent[a] } else { 0.0 });
    let (lo, sc, top) = (cb.min, Vec3A::from(Vec3::from(scale)), Vec3A::splat((bins - 1) as f32));
    let bin_into = |all: &mut [Bin], chunk: &[BuildPrim]| {
        for p in chunk {
            let idx = bin_indices((p.centroid() - lo) * sc, top);
            for (axis, &i) in idx.iter().take(3).enumerate() {
                let bin = &mut all[axis * bins + i as usize];
                bin.count += 1;
                bin.bounds = bin.bounds.union(p.bounds());
            }
        }
    };
    all.clear();
    all.resize(3 * bins, Bin::EMPTY);
    if n >= PARALLEL_BINNING_MIN {
        // Big nodes (the top of the tree, where the parallel subtrees have not started yet) are
        // binned in parallel chunks whose bins are then merged.
        let merged = crate::parallel::region(|| {
            prims
                .par_chunks(PARALLEL_BINNING_MIN / 4)
                .map(|chunk| {
                    let mut local = vec![Bin::EMPTY; 3 * bins];
                    bin_into(&mut local, chunk);
                    local
                })
                .reduce_with(|mut a, b| {
                    for (x, y) in a.iter_mut().zip(&b) {
                        x.merge(y);
                    }
                    a
                })
        });
        if let Some(m) = merged {
            all.copy_from_slice(&m);
        }
    } else {
        bin_into(all, prims);
    }
    // The three axes are swept together, plane by plane, with lane k of each vector for axis k:
    // three independent chains of box unions, and the three areas and costs of a plane computed
    // with one set of SIMD operations.
    right_area.clear();
    right_area.resize(bins, Vec4::ZERO);
    let bin = |axis: usize, i: usize| &all[axis * bins + i];
    // right_area[i]: per axis, the area of bins i..; plane i separates bins ..i from i..
    let mut acc = [Aabb::EMPTY; 3];
    for (i, area) in right_area.iter_mut().enumerate().skip(1).rev() {
        for (axis, a) in acc.iter_mut().enumerate() {
            *a = a.union(bin(axis, i).bounds);
        }
        *area = areas3(&acc);
    }
    let splittable = extent.to_array().map(|e| e > 0.0);
    let (mut acc, mut left) = ([Aabb::EMPTY; 3], [0u32; 3]);
    // Per axis, the cheapest plane so far (the first of equal ones).
    let (mut lane_cost, mut lane_plane) = (Vec4::INFINITY, Vec4::ZERO);
    for (i, &right_area) in right_area.iter().enumerate().skip(1) {
        for axis in 0..3 {
            let b = bin(axis, i - 1);
            acc[axis] = acc[axis].union(b.bounds);
            left[axis] += b.count;
        }
        let right = left.map(|l| n as u32 - l);
        let counts = |c: [u32; 3]| Vec4::new(c[0] as f32, c[1] as f32, c[2] as f32, 0.0);
        let left_area = areas3(&acc);
        let cost = left_area * counts(left) + right_area * counts(right);
        let usable = |a: usize| left[a] != 0 && right[a] != 0 && splittable[a];
        if is_active(sink) {
            for a in (0..3).filter(|&a| usable(a)) {
                let areas = [left_area[a], right_area[a]];
                sink.plane(a, cb.min[a] + i as f32 / scale[a], left[a], right[a], cost[a], areas);
            }
        }
        let better = cost.cmplt(lane_cost) & BVec4A::new(usable(0), usable(1), usable(2), false);
        lane_cost = Vec4::select(better, cost, lane_cost);
        lane_plane = Vec4::select(better, Vec4::splat(i as f32), lane_plane);
    }
    // The cheapest axis; on a tie the lower axis.
    let (mut best_cost, mut best_axis, mut best_plane) = (f32::INFINITY, 0, 0);
    for axis in 0..3 {
        if lane_cost[axis] < best_cost {
            (best_cost, best_axis, best_plane) = (lane_cost[axis], axis, lane_plane[axis] as usize);
        }
    }
    let best = (best_plane != 0).then_some((best_cost, best_axis, best_plane));
    let Some((weighted, axis, plane)) = best else {
        return Proposal::None; // all centroids coincide
    };
    let (lo, s, plane) = (cb.min[axis], scale[axis], plane as f32);
    // Same arithmetic as the binning above (SIMD there, scalar here: IEEE gives equal results).
    // For an integer plane in 1..bins, floor(clamp(x, 0, bins - 1)) < plane ⟺ x < plane, so the
    // clamp and the cast can be skipped; `!(x >= plane)` sends NaN left, as its bin 0 would.
    let mid = partition(prims, |p| goes_left((p.centroid()[axis] - lo) * s, plane));
    debug_assert_eq!(
        mid,
        all[axis * bins..axis * bins + plane as usize].iter().map(|b| b.count as usize).sum::<usize>(),
        "the partition sends left exactly the triangles binned left of the plane"
    );
    Proposal::Split { axis: axis as u8, mid, weighted: Some(weighted), plane: lo + plane / s }
}

/// The partition's side for a scaled centroid offset and an integer plane in 1..bins: left exactly
/// when `bin_indices` puts it in a bin below the plane (NaN included, in bin 0).
#[inline(always)]
fn goes_left(scaled: f32, plane: f32) -> bool {
    !(scaled >= plane)
}

/// Surface areas of three boxes at once: lane k is `boxes[k].area()`, computed with the same
/// operations in the same order (lane 3 is 0).
#[inline(always)]
fn areas3(boxes: &[Aabb; 3]) -> Vec4 {
    let e = boxes.map(|b| (b.max - b.min).max(Vec3A::ZERO));
    let (x, y, z) = (
        Vec4::new(e[0].x, e[1].x, e[2].x, 0.0),
        Vec4::new(e[0].y, e[1].y, e[2].y, 0.0),
        Vec4::new(e[0].z, e[1].z, e[2].z, 0.0),
    );
    2.0 * (x * y + y * z + z * x)
}

/// Two triangles: every plane between their centroids makes the same two one-triangle children, so
/// their cost is computed directly (what the bins would give, without them); the axis is the first
/// with extent, as the sweep would pick, and the triangle of the lower centroid goes left.
fn split_two(prims: &mut [BuildPrim], extent: Vec3A) -> Proposal {
    let Some(axis) = (0..3).find(|&a| extent[a] > 0.0) else {
        return Proposal::None; // both centroids coincide
    };
    let weighted = prims[0].bounds().area() + prims[1].bounds().area();
    if prims[0].centroid()[axis] > prims[1].centroid()[axis] {
        prims.swap(0, 1);
    }
    let plane = (prims[0].centroid()[axis] + prims[1].centroid()[axis]) * 0.5;
    Proposal::Split { axis: axis as u8, mid: 1, weighted: Some(weighted), plane }
}

#[cfg(test)]
mod tests {
    use super::{bin_indices, goes_left};
    use crate::bvh::node::Bvh;
    use crate::bvh::params::Strategy;
    use crate::bvh::params::{BuildParams, Layout};
    use crate::bvh::stats::TreeStats;
    use crate::mesh::generate;

    #[test]
    fn bin_indices_truncate_and_clamp_like_the_partition_test() {
        let top = glam::Vec3A::splat(15.0);
        let at = |x: f32, y: f32, z: f32| bin_indices(glam::Vec3A::new(x, y, z), top);
        assert_eq!(at(0.0, 0.99, 1.0)[..3], [0, 0, 1]);
        assert_eq!(at(14.999, 15.0, 15.5)[..3], [14, 15, 15], "the last bin takes the far edge");
        assert_eq!(at(-0.5, -1e30, 1e30)[..3], [0, 0, 15], "outside the bounds: the nearest end bin");
        assert_eq!(
            at(f32::NAN, 3.5, f32::INFINITY)[..3],
            [0, 3, 15],
            "NaN goes to bin 0, as the partition sends it left"
        );
        // The partition's test agrees with the bins for every plane, at, between and beyond bin edges.
        let values = [f32::NAN, f32::NEG_INFINITY, -1.0, -0.0, 0.0, 0.5, 0.999, 1.0, 7.0, 7.5, 14.999, 15.0, 15.5, 1e9];
        for x in values {
            for plane in 1..=15 {
                let bin = bin_indices(glam::Vec3A::splat(x), top)[0];
                assert_eq!(bin < plane, goes_left(x, plane as f32), "x = {x}, plane {plane}");
            }
        }
    }

    /// The binned SAH's trees against the exact sweep's, on meshes where the planes matter: a
    /// wrong cost, a wrong side count or a plane off by one costs far more than 3%.
    #[test]
    fn binned_sah_trees_come_close_to_the_exact_sweep() {
        for mesh in [generate::torus_knot(3, 5, 0.3, 256, 12), generate::stadium(), generate::builtin_scene()] {
            let cost = |strategy| {
                let bvh = Bvh::build(&mesh, &BuildParams { strategy, layout: Layout::Binary, ..Default::default() });
                let stats = TreeStats::of(&bvh);
                if strategy == Strategy::SahBinned {
                    assert_eq!(stats.fallback_splits, 0, "every node had a plane with triangles on both sides");
                }
                stats.sah_cost
            };
            let (binned, sweep) = (cost(Strategy::SahBinned), cost(Strategy::SahSweep));
            let midpoint = cost(Strategy::Midpoint);
            eprintln!("{}: binned {binned:.3}, sweep {sweep:.3}, midpoint {midpoint:.3}", mesh.triangle_count());
            assert!(binned <= sweep * 1.03, "binned {binned} against the sweep's {sweep}");
            assert!(binned < midpoint, "binned {binned} against midpoint's {midpoint}");
        }
    }
}
