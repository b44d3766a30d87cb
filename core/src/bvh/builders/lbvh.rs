//! LBVH: the linear BVH of Lauterbach et al., "Fast BVH Construction on GPUs" (Eurographics 2009).
//! Each primitive's centroid gets a 30-bit Morton code (10 bits per axis of the centroid bounds,
//! interleaved x, y, z from the top), the codes are radix sorted (rdst, all threads), and the
//! hierarchy follows from the sorted codes alone: a range of codes is split where its highest
//! differing bit flips (the same tree as Karras, "Maximizing Parallelism in the Construction of
//! BVHs, Octrees, and k-d Trees", HPG 2012, builds node by node; here top-down with `rayon::join`).
//! No box is priced: the build is a sort and a pass of binary searches, and the tree is blocky,
//! each split an axis-aligned plane of the Morton grid. A range of at most `max_leaf_size`
//! primitives is a leaf; one of equal codes (centroids in one grid cell) above that is split by
//! its places in the sorted order, Karras's tie-break (`morton::tie_split`; counted as a fallback
//! split). Boxes are made bottom-up, once per node.

use super::common::Progress;
use super::morton::{grid, in_triangle_order, morton, sort, split_of, tie_split, Keyed};
use super::subtree::Subtree;
use crate::bvh::builders::split::splitter::BuildPrim;
use crate::bvh::node::{Bvh, BvhNode};
use crate::bvh::params::{BuildParams, BuildReport};
use crate::geometry::Aabb;
use crate::parallel::region;
use crate::work::Cancelled;
use glam::Vec3A;
use rayon::prelude::*;

/// Ranges at least this long are split in parallel.
const PARALLEL_MIN: usize = 1 << 14;

/// Sort `prims` into Morton order and build the hierarchy over them (left in leaf order). The
/// subtree and the number of ranges of equal codes split by their places.
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
) -> Result<Bvh, Cancelled> {
    let t0 = std::time::Instant::now();
    let n = mesh.triangle_count();
    let centroids: Vec<Vec3A> = region(|| {
        (0..n as u32)
            .into_par_iter()
            .with_min_len(4096)
            .map(|i| {
                let b = Aabb::from_points(&mesh.triangle(i));
                (b.min + b.max) * 0.5
            })
            .collect()
    });
    let setup_time = t0.elapsed();
    progress.check()?;
    let t1 = std::time::Instant::now();
    let mut keyed: Vec<Keyed> = region(|| {
        let (lo, scale) = grid(centroids.par_iter().copied());
        centroids
            .par_iter()
            .with_min_len(4096)
            .enumerate()
            .map(|(i, &c)| Keyed(morton(c, lo, scale) << 32 | i as u64))
            .collect()
    });
    drop(centroids);
    // rdst's radix sort splits the keys among the threads (counted parallel: the 16-core
    // LBVH build, mostly this sort, ran 6.1× faster than on two threads).
    region(|| rdst::RadixSort::radix_sort_unstable(&mut keyed));
    let (codes, prim_ids) = region(|| {
        in_triangle_order(&mut keyed);
        let codes: Vec<u64> = keyed.par_iter().with_min_len(4096).map(|k| k.code()).collect();
        let prim_ids: Vec<u32> = keyed.par_iter().with_min_len(4096).map(|k| k.slot() as u32).collect();
        (codes, prim_ids)
    });
    drop(keyed);
    progress.check()?;
    let sort_time = t1.elapsed();
    let t2 = std::time::Instant::now();
    let tris: Vec<[glam::Vec3; 3]> =
        region(|| prim_ids.par_iter().with_min_len(4096).map(|&i| mesh.triangle(i)).collect());
    let reorder_time = t2.elapsed();
    let t3 = std::time::Instant::now();
    let (tree, fallback) = if tris.is_empty() {
        (Subtree::Flat(vec![BvhNode::leaf(Aabb::EMPTY, 0, 0)]), 0)
    } else {
        subtree(tris.as_slice(), &codes, 0, 0, params.max_leaf_size as usize, progress)?
    };
    let nodes = tree.into_nodes();
    let report = BuildReport {
        setup_time,
        split_time: sort_time + t3.elapsed(),
        reorder_time,
        fallback_splits: fallback,
        ..Default::default()
    };
    Ok(Bvh { nodes, prim_ids, tris, params: *params, report })
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
        // One of many subtrees built side by side.
        return region(|| sequential(prims, codes, offset, depth, leaf, progress)).map(|(n, f)| (Subtree::Flat(n), f));
    }
    progress.check()?;
    let (mid, axis, fallback) = match split_of(codes) {
        Some((mid, axis)) => (mid, axis, 0),
        None => (tie_split(offset as usize, prims.len()), 0, 1),
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

/// One thread's subtree, laid out as `builders::build_sequential` lays out its nodes (each node's
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
            let b = Aabb::of(prims[start..end].iter().map(|p| p.bounds()));
            nodes[node] = BvhNode::leaf(b, offset + start as u32, n as u16);
            done += progress.leaf_units(n, depth);
            continue;
        }
        let (mid, axis) = split_of(&codes[start..end]).unwrap_or_else(|| {
            fallback += 1;
            (tie_split(offset as usize + start, n), 0)
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
mod tests {
    use super::*;

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
}
