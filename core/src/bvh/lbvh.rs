//! LBVH: the linear BVH of Lauterbach et al., "Fast BVH Construction on GPUs" (Eurographics 2009).
//! Each primitive's centroid gets a 30-bit Morton code (10 bits per axis of the centroid bounds,
//! interleaved x, y, z from the top), the codes are radix sorted (rdst, all threads), and the
//! hierarchy follows from the sorted codes alone: a range of codes is split where its highest
//! differing bit flips (the same tree as Karras, "Maximizing Parallelism in the Construction of
//! BVHs, Octrees, and k-d Trees", HPG 2012, builds node by node; here top-down with `rayon::join`).
//! No box is priced: the build is a sort and a pass of binary searches, and the tree is blocky,
//! each split an axis-aligned plane of the Morton grid. A range of at most `max_leaf_size`
//! primitives is a leaf; one of equal codes (centroids in one grid cell) above that is cut in the
//! middle (counted as a fallback split). Boxes are made bottom-up, once per node.

use super::build::{BuildParams, Progress};
use super::node::BvhNode;
use super::split::BuildPrim;
use super::subtree::Subtree;
use crate::geometry::Aabb;
use crate::work::Cancelled;
use glam::Vec3A;
use rayon::prelude::*;

/// Ranges at least this long are split in parallel.
const PARALLEL_MIN: usize = 1 << 14;

/// Bits per axis of the 30-bit code.
const BITS: u32 = 10;

/// Spread the low 21 bits of `v` so that bit i lands on bit 3i (the code uses the low `BITS`).
fn spread(v: u64) -> u64 {
    let mut x = v & 0x1f_ffff;
    x = (x | x << 32) & 0x001f_0000_0000_ffff;
    x = (x | x << 16) & 0x001f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}

/// The Morton code of point `p` in the grid over `lo` with `scale` cells per unit.
fn morton(p: Vec3A, lo: Vec3A, scale: Vec3A) -> u64 {
    let max = ((1u32 << BITS) - 1) as f32;
    let q = ((p - lo) * scale).clamp(Vec3A::ZERO, Vec3A::splat(max));
    spread(q.x as u64) << 2 | spread(q.y as u64) << 1 | spread(q.z as u64)
}

/// The axis a code bit belongs to (x on bits 3i + 2, y on 3i + 1, z on 3i).
fn axis_of(bit: u32) -> u8 {
    2 - (bit % 3) as u8
}

/// A sort record: the code in the high half, where the primitive was in the low half (8 bytes:
/// half the memory traffic of a 16-byte record in each of the sort's passes).
#[derive(Clone, Copy)]
struct Keyed(u64);

impl Keyed {
    fn code(self) -> u64 {
        self.0 >> 32
    }
    fn slot(self) -> usize {
        self.0 as u32 as usize
    }
}

impl rdst::RadixKey for Keyed {
    /// Only the code's bytes are sorted on (`in_triangle_order` then orders equal codes).
    const LEVELS: usize = 4;
    #[inline]
    fn get_level(&self, level: usize) -> u8 {
        (self.0 >> (32 + level * 8)) as u8
    }
}

/// Records sorted by code, with each run of equal codes put in triangle (slot) order. The radix
/// sort is unstable and multi-threaded: on its own it left equal codes in an order that could
/// change with the thread count, and the tree with it. With this the tree is the same on any
/// machine, and it is the GPU's LBVH's (a stable sort) node for node. Sorting on all eight bytes
/// instead did the same at 15 % more build time on a 2M-triangle mesh; runs of equal codes are
/// short, so this pass costs little next to the sort.
fn in_triangle_order(keyed: &mut [Keyed]) {
    keyed.par_chunk_by_mut(|a, b| a.code() == b.code()).for_each(|run| {
        if run.len() > 1 {
            run.sort_unstable_by_key(|k| k.0);
        }
    });
}

/// Where a range of sorted codes is split, and on which axis: `None` when all codes are equal.
fn split_of(codes: &[u64]) -> Option<(usize, u8)> {
    let (a, b) = (codes[0], codes[codes.len() - 1]);
    if a == b {
        return None;
    }
    let bit = 63 - (a ^ b).leading_zeros();
    let mask = 1u64 << bit;
    // The codes share every bit above `bit`: those without it come first.
    Some((codes.partition_point(|c| c & mask == 0), axis_of(bit)))
}

/// Sort `prims` into Morton order and build the hierarchy over them (left in leaf order). The
/// subtree and the number of ranges of equal codes cut in the middle.
pub(super) fn build(
    prims: &mut Vec<BuildPrim>,
    params: &BuildParams,
    progress: &Progress,
) -> Result<(Subtree, u32), Cancelled> {
    if prims.is_empty() {
        return Ok((Subtree::Flat(vec![BvhNode::leaf(Aabb::EMPTY, 0, 0)]), 0));
    }
    let codes = sort(prims);
    progress.check()?;
    let leaf = params.max_leaf_size as usize;
    subtree(prims.as_slice(), &codes, 0, 0, leaf, progress)
}

/// The LBVH of a mesh without the general build's records: the centroids (as the records would
/// give them, the centres of the triangles' boxes) are coded and sorted as slot numbers, the
/// triangles gathered into that order once, and the leaves' boxes made from them as they lie in
/// memory. The general path also gathered its 32-byte records into the sorted order and read them
/// back for the boxes, a fifth of the build on the 2M knot (BENCHMARKS.md); the tree is the same
/// (a test builds both).
pub(super) fn build_mesh(
    mesh: &crate::mesh::Mesh,
    params: &BuildParams,
    progress: &Progress,
) -> Result<super::Bvh, Cancelled> {
    let t0 = std::time::Instant::now();
    let n = mesh.triangle_count();
    let centroids: Vec<Vec3A> = (0..n as u32)
        .into_par_iter()
        .with_min_len(4096)
        .map(|i| {
            let b = Aabb::from_points(&mesh.triangle(i));
            (b.min + b.max) * 0.5
        })
        .collect();
    let setup_time = t0.elapsed();
    progress.check()?;
    let t1 = std::time::Instant::now();
    let (lo, scale) = grid(centroids.par_iter().copied());
    let mut keyed: Vec<Keyed> = centroids
        .par_iter()
        .with_min_len(4096)
        .enumerate()
        .map(|(i, &c)| Keyed(morton(c, lo, scale) << 32 | i as u64))
        .collect();
    drop(centroids);
    rdst::RadixSort::radix_sort_unstable(&mut keyed);
    in_triangle_order(&mut keyed);
    let codes: Vec<u64> = keyed.par_iter().with_min_len(4096).map(|k| k.code()).collect();
    let prim_ids: Vec<u32> = keyed.par_iter().with_min_len(4096).map(|k| k.slot() as u32).collect();
    drop(keyed);
    progress.check()?;
    let sort_time = t1.elapsed();
    let t2 = std::time::Instant::now();
    let tris: Vec<[glam::Vec3; 3]> = prim_ids.par_iter().with_min_len(4096).map(|&i| mesh.triangle(i)).collect();
    let reorder_time = t2.elapsed();
    let t3 = std::time::Instant::now();
    let (tree, fallback) = if tris.is_empty() {
        (Subtree::Flat(vec![BvhNode::leaf(Aabb::EMPTY, 0, 0)]), 0)
    } else {
        subtree(tris.as_slice(), &codes, 0, 0, params.max_leaf_size as usize, progress)?
    };
    let nodes = tree.into_nodes();
    let report = super::BuildReport {
        setup_time,
        split_time: sort_time + t3.elapsed(),
        reorder_time,
        fallback_splits: fallback,
        ..Default::default()
    };
    Ok(super::Bvh { nodes, prim_ids, tris, params: *params, report })
}

/// Sort `prims` by the Morton codes of their centroids in the grid over the centroid bounds;
/// the codes in that order.
pub(super) fn sort(prims: &mut Vec<BuildPrim>) -> Vec<u64> {
    let (lo, scale) = grid(prims.par_iter().map(|p| p.centroid()));
    let mut keyed: Vec<Keyed> = prims
        .par_iter()
        .with_min_len(4096)
        .enumerate()
        .map(|(i, p)| Keyed(morton(p.centroid(), lo, scale) << 32 | i as u64))
        .collect();
    rdst::RadixSort::radix_sort_unstable(&mut keyed);
    in_triangle_order(&mut keyed);
    // The sorted records replace the vector (a copy back into it cost a pass over all of them).
    *prims = keyed.par_iter().with_min_len(4096).map(|k| prims[k.slot()]).collect();
    keyed.par_iter().with_min_len(4096).map(|k| k.code()).collect()
}

/// The Morton grid over the centroids' bounds: its lower corner and cells per unit.
fn grid(centroids: impl rayon::iter::IndexedParallelIterator<Item = Vec3A>) -> (Vec3A, Vec3A) {
    let centroids =
        centroids.with_min_len(4096).fold(|| Aabb::EMPTY, |b, c| b.grow(c)).reduce(|| Aabb::EMPTY, |a, b| a.union(b));
    let extent = centroids.max - centroids.min;
    let cells = ((1u32 << BITS) - 1) as f32;
    (centroids.min, Vec3A::select(extent.cmpgt(Vec3A::ZERO), Vec3A::splat(cells) / extent, Vec3A::ZERO))
}

/// An LBVH tree's Morton order, for the build replay: its leaf order *is* the sort, so each leaf
/// slot's triangle centroid and code (computed again with the build's grid and `morton`), in slot
/// order, are the curve the build followed, and each split is where a bit of the codes flips.
pub struct MortonOrder {
    /// The triangle centroids in leaf order: the Morton curve.
    pub centroids: Vec<glam::Vec3>,
    /// Their codes (non-decreasing: `of` checks).
    pub codes: Vec<u64>,
    /// Running sums of the centroids (`sums[i]`: of slots `..i`), for `mean`.
    sums: Vec<glam::DVec3>,
}

/// Where the codes of a range split: the bit, its axis (0 = x) and its level of the grid (1 =
/// halves, 2 = quarters, … down to `BITS`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MortonSplit {
    pub bit: u32,
    pub axis: u8,
    pub level: u32,
    /// Slots before the flip (the left child's).
    pub left: u32,
}

impl MortonOrder {
    /// The order of an LBVH tree as built (`None` for other strategies, or after reinsertion,
    /// which moves subtrees out of Morton order).
    pub fn of(bvh: &super::Bvh) -> Option<MortonOrder> {
        if bvh.params.strategy != super::SplitStrategy::Lbvh || bvh.report.reinsertion.is_some() {
            return None;
        }
        let prims: Vec<BuildPrim> =
            bvh.tris.iter().zip(&bvh.prim_ids).map(|(t, &i)| BuildPrim::new(Aabb::from_points(t), i)).collect();
        let (lo, scale) = grid(prims.par_iter().map(|p| p.centroid()));
        let codes: Vec<u64> = prims.iter().map(|p| morton(p.centroid(), lo, scale)).collect();
        if !codes.windows(2).all(|w| w[0] <= w[1]) {
            return None;
        }
        let centroids: Vec<glam::Vec3> = prims.iter().map(|p| p.centroid().into()).collect();
        let mut sums = Vec::with_capacity(centroids.len() + 1);
        sums.push(glam::DVec3::ZERO);
        for c in &centroids {
            sums.push(*sums.last().expect("pushed above") + c.as_dvec3());
        }
        Some(MortonOrder { centroids, codes, sums })
    }

    /// The mean centroid of slots `first..first + count`: where a stretch of the curve (a node of
    /// the tree) sits, so the frontier's means in order are the curve at the replay's resolution.
    pub fn mean(&self, first: u32, count: u32) -> glam::Vec3 {
        let (a, b) = (first as usize, (first + count) as usize);
        ((self.sums[b] - self.sums[a]) / count.max(1) as f64).as_vec3()
    }

    /// How slots `first..first + count` split: at the highest bit where their codes differ
    /// (`None` when all are equal: the build then cut the range in the middle).
    pub fn split(&self, first: u32, count: u32) -> Option<MortonSplit> {
        let codes = self.codes.get(first as usize..(first + count) as usize)?;
        let (mid, axis) = split_of(codes)?;
        let bit = 63 - (codes[0] ^ codes[codes.len() - 1]).leading_zeros();
        Some(MortonSplit { bit, axis, level: BITS - bit / 3, left: mid as u32 })
    }
}

/// What a leaf's box is made of: build records, or (the mesh path) triangles in leaf order.
trait Bounded: Sync {
    fn bounds(&self) -> Aabb;
}

impl Bounded for BuildPrim {
    #[inline]
    fn bounds(&self) -> Aabb {
        BuildPrim::bounds(self)
    }
}

impl Bounded for [glam::Vec3; 3] {
    #[inline]
    fn bounds(&self) -> Aabb {
        Aabb::from_points(self)
    }
}

/// The subtree over `prims` (with their `codes`), which start at `offset` in the full array.
fn subtree<T: Bounded>(
    prims: &[T],
    codes: &[u64],
    offset: u32,
    depth: u32,
    leaf: usize,
    progress: &Progress,
) -> Result<(Subtree, u32), Cancelled> {
    if prims.len() < PARALLEL_MIN {
        return sequential(prims, codes, offset, depth, leaf, progress).map(|(n, f)| (Subtree::Flat(n), f));
    }
    progress.check()?;
    let (mid, axis, fallback) = match split_of(codes) {
        Some((mid, axis)) => (mid, axis, 0),
        None => (prims.len() / 2, 0, 1),
    };
    progress.split(prims.len(), depth);
    let ((lp, rp), (lc, rc)) = (prims.split_at(mid), codes.split_at(mid));
    let (left, right) = rayon::join(
        || subtree(lp, lc, offset, depth + 1, leaf, progress),
        || subtree(rp, rc, offset + mid as u32, depth + 1, leaf, progress),
    );
    let ((left, lf), (right, rf)) = (left?, right?);
    let bounds = root_bounds(&left).union(root_bounds(&right));
    let len = 1 + left.len() + right.len();
    Ok((Subtree::Split { bounds, axis, left: Box::new(left), right: Box::new(right), len }, fallback + lf + rf))
}

fn root_bounds(t: &Subtree) -> Aabb {
    match t {
        Subtree::Flat(nodes) => nodes[0].bounds(),
        Subtree::Split { bounds, .. } => *bounds,
    }
}

/// One thread's subtree, laid out as `build::build_sequential` lays out its nodes (each node's
/// children a pair, the left subtree right after it): the topology top-down, then the boxes from
/// the leaves up (children come after their parent, so one pass backwards).
fn sequential<T: Bounded>(
    prims: &[T],
    codes: &[u64],
    offset: u32,
    depth0: u32,
    leaf: usize,
    progress: &Progress,
) -> Result<(Vec<BvhNode>, u32), Cancelled> {
    let mut nodes = Vec::with_capacity(2 * prims.len() / leaf.max(1) + 1);
    nodes.push(BvhNode::leaf(Aabb::EMPTY, offset, 0));
    let mut fallback = 0;
    // (node, start, end, depth)
    let mut stack = vec![(0usize, 0usize, prims.len(), depth0)];
    let (mut steps, mut done) = (0u32, 0u64);
    while let Some((node, start, end, depth)) = stack.pop() {
        steps += 1;
        if steps.is_multiple_of(256) {
            progress.add(std::mem::take(&mut done));
            progress.check()?;
        }
        let n = end - start;
        if n <= leaf {
            let b = prims[start..end].iter().fold(Aabb::EMPTY, |b, p| b.union(p.bounds()));
            nodes[node] = BvhNode::leaf(b, offset + start as u32, n as u16);
            done += progress.leaf_units(n, depth);
            continue;
        }
        let (mid, axis) = split_of(&codes[start..end]).unwrap_or_else(|| {
            fallback += 1;
            (n / 2, 0)
        });
        let left = nodes.len();
        nodes.extend([BvhNode::leaf(Aabb::EMPTY, 0, 0); 2]);
        nodes[node] = BvhNode::interior(Aabb::EMPTY, left as u32, axis);
        done += progress.split_units(n, depth);
        stack.push((left + 1, start + mid, end, depth + 1));
        stack.push((left, start, start + mid, depth + 1));
    }
    progress.add(done);
    for i in (0..nodes.len()).rev() {
        let n = nodes[i];
        if !n.is_leaf() {
            let b = nodes[n.index as usize].bounds().union(nodes[n.index as usize + 1].bounds());
            nodes[i] = BvhNode::interior(b, n.index, n.axis);
        }
    }
    Ok((nodes, fallback))
}

#[cfg(test)]
mod morton_order_tests {
    use super::MortonOrder;
    use crate::bvh::inspect::Hierarchy;
    use crate::bvh::{BuildParams, Bvh, Layout, SplitStrategy};
    use crate::mesh::generate;

    /// The leaf order of an LBVH tree is its Morton order, and every split of the tree (not a
    /// fallback) is where the order says: the left child holds the slots before the bit flips.
    #[test]
    fn an_lbvh_trees_leaf_order_is_its_morton_order_and_splits_follow_it() {
        let mesh = generate::torus_knot(2, 3, 0.3, 256, 12);
        let params = BuildParams { strategy: SplitStrategy::Lbvh, layout: Layout::Binary, ..Default::default() };
        let bvh = Bvh::build(&mesh, &params);
        let order = MortonOrder::of(&bvh).expect("an LBVH tree");
        assert_eq!(order.centroids.len(), bvh.prim_ids.len());
        let h = Hierarchy::of(&bvh);
        let mut checked = 0;
        for (i, n) in bvh.nodes.iter().enumerate().filter(|(_, n)| !n.is_leaf()) {
            let s = order.split(h.first[i], h.count[i]).expect("distinct codes");
            assert_eq!((s.left, s.axis), (h.count[n.index as usize], n.axis), "node {i}");
            assert!(s.level >= 1 && s.level <= super::BITS);
            checked += 1;
        }
        assert!(checked > 1000);
        let sah = Bvh::build(&mesh, &BuildParams { layout: Layout::Binary, ..Default::default() });
        assert!(MortonOrder::of(&sah).is_none(), "other strategies have no Morton order");
        let reinserted = Bvh::build(&mesh, &BuildParams { reinsert_passes: 1, ..params });
        assert!(MortonOrder::of(&reinserted).is_none(), "nor has a tree reinsertion changed");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_interleave_x_y_z_from_the_top() {
        assert_eq!(spread(0b101), 0b1_000_001);
        assert_eq!(spread(0x1f_ffff).count_ones(), 21);
        let (lo, scale) = (Vec3A::ZERO, Vec3A::splat(((1u32 << BITS) - 1) as f32));
        // The far corner on x only sets x's bits: 3i + 2.
        let x = morton(Vec3A::new(1.0, 0.0, 0.0), lo, scale);
        assert_eq!(x, spread((1 << BITS) - 1) << 2);
        assert_eq!(axis_of(3 * BITS - 1), 0, "the top bit is x's");
        assert_eq!((axis_of(3 * BITS - 2), axis_of(3 * BITS - 3)), (1, 2));
    }

    /// The parallel build lays out the tree one thread lays out over the same sorted primitives.
    #[test]
    fn the_parallel_build_lays_out_the_same_tree_as_one_thread() {
        let mesh = crate::mesh::generate::torus(2.0, 0.5, 256, 160);
        assert!(mesh.triangle_count() > 4 * PARALLEL_MIN);
        let prims = || -> Vec<BuildPrim> {
            (0..mesh.triangle_count())
                .map(|i| BuildPrim::new(Aabb::from_points(&mesh.triangle(i as u32)), i as u32))
                .collect()
        };
        let control = crate::work::WorkControl::new();
        let progress = Progress::new(&control, 1);
        let params = BuildParams { max_leaf_size: 4, ..BuildParams::default() };
        let mut a = prims();
        let (tree, _) = build(&mut a, &params, &progress).unwrap();
        let mut b = prims();
        let codes = sort(&mut b);
        assert!(codes.windows(2).all(|w| w[0] <= w[1]), "sorted");
        let (nodes, _) = sequential(b.as_slice(), &codes, 0, 0, 4, &progress).unwrap();
        assert!(tree.into_nodes() == nodes);
        assert!(a.iter().map(|p| p.index()).eq(b.iter().map(|p| p.index())));
        // The mesh path (no build records) makes the same tree, with the triangles in its order.
        let b = build_mesh(&mesh, &params, &progress).unwrap();
        assert!(b.nodes == nodes, "the mesh path's tree");
        assert!(b.prim_ids.iter().copied().eq(a.iter().map(|p| p.index())));
        assert!(b.prim_ids.iter().zip(&b.tris).all(|(&i, t)| *t == mesh.triangle(i)));
        // Every leaf holds at most 4, and each interior box is its children's union.
        for n in &nodes {
            if n.is_leaf() {
                assert!(n.count <= 4);
            } else {
                let (l, r) = (nodes[n.index as usize].bounds(), nodes[n.index as usize + 1].bounds());
                assert_eq!(n.bounds(), l.union(r));
            }
        }
    }

    /// Many triangles on few centroids, interleaved (a cloud of copies): the radix sort alone,
    /// on all threads, left equal codes out of triangle order; both sorts keep it.
    #[test]
    fn equal_codes_stay_in_triangle_order() {
        use glam::Vec3;
        let (n, spots) = (300_000u32, 7u32);
        let mut positions = Vec::new();
        let mut triangles = Vec::new();
        for i in 0..n {
            let c = Vec3::new((i % spots) as f32, ((i % spots) * 3 % spots) as f32, 0.5 * (i % 3) as f32);
            let k = positions.len() as u32;
            positions.extend([c, c + Vec3::X * 0.01, c + Vec3::Y * 0.01]);
            triangles.push([k, k + 1, k + 2]);
        }
        let mesh = crate::mesh::Mesh::from_triangles("copies", positions, triangles);
        let control = crate::work::WorkControl::new();
        let progress = Progress::new(&control, 1);
        let bvh = build_mesh(&mesh, &BuildParams { max_leaf_size: 4, ..BuildParams::default() }, &progress).unwrap();
        let mut prims: Vec<BuildPrim> =
            (0..n).map(|i| BuildPrim::new(Aabb::from_points(&mesh.triangle(i)), i)).collect();
        let codes = sort(&mut prims);
        let ids: Vec<u32> = prims.iter().map(|p| p.index()).collect();
        assert_eq!(bvh.prim_ids, ids, "the mesh path and the records' sort agree");
        let runs = codes.chunk_by(|a, b| a == b).count();
        assert!(runs <= 21 && runs > 1, "{runs} runs of equal codes");
        let mut start = 0;
        for run in codes.chunk_by(|a, b| a == b) {
            let run_ids = &ids[start..start + run.len()];
            assert!(run_ids.windows(2).all(|w| w[0] < w[1]), "code {:#x}: triangles out of order", run[0]);
            start += run.len();
        }
    }

    #[test]
    fn a_range_splits_where_its_highest_differing_bit_flips() {
        let codes = [0b0001, 0b0011, 0b0100, 0b0110, 0b0111];
        assert_eq!(split_of(&codes).map(|s| s.0), Some(2), "bit 2 flips between 0b0011 and 0b0100");
        assert_eq!(split_of(&[5, 5, 5]), None);
    }
}
