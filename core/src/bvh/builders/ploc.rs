//! PLOC: Meister & Bittner, "Parallel Locally-Ordered Clustering for Bounding Volume Hierarchy
//! Construction" (IEEE TVCG 2018). The primitives, sorted by Morton code (`morton::sort`), start as
//! one cluster each; every round, each cluster finds its nearest neighbour among the `radius`
//! clusters before and after it in that order (the one whose union with it has the smallest
//! surface area), mutual nearest neighbours merge, and the clusters are compacted, keeping the
//! order; until one is left. The whole round runs on all threads: the neighbour search, and the
//! merges and compaction by prefix sums over fixed chunks (the paper's §4.3), so the tree does not
//! depend on the thread count.
//!
//! The tree has a primitive per leaf; each merge also decides whether its subtree of at most
//! `max_leaf_size` primitives is cheaper under the SAH as one leaf than as its split, and then
//! is one (as the paper's leaves of several primitives, and obvhs's, are made). Bottom-up, the
//! tree cannot be cut off at a leaf size before it is built: the clusters do not know their size
//! when they meet. The layout then places big subtrees in parallel: each merge knows its size.

use super::common::Progress;
use super::subtree::Subtree;
use crate::bvh::builders::split::splitter::BuildPrim;
use crate::bvh::node::BvhNode;
use crate::bvh::params::BuildParams;
use crate::geometry::Aabb;
use crate::parallel::region;
use crate::work::Cancelled;
use rayon::prelude::*;

/// A node while clustering: a primitive (`left == LEAF`, `right` its slot in the sorted array) or
/// the merge of two nodes, with what the layout needs of its subtree, worked out when it is made
/// (its children are made in earlier rounds): primitives, SAH cost, whether it becomes one leaf,
/// and how many nodes it lays out as.
#[derive(Clone, Copy)]
struct Cluster {
    bounds: Aabb,
    left: u32,
    right: u32,
    count: u32,
    size: u32,
    cost: f64,
    leaf: bool,
}

const LEAF: u32 = u32::MAX;

/// Clusters per task of a round (its search and its compaction): a 64th of the round, within
/// `MIN_CHUNK..=MAX_CHUNK`, so that rounds of a mid-sized mesh (the bunny's are all under 70k
/// clusters) still give 16 threads a task each. Any cutting gives the same round (each chunk
/// writes its part in order); it follows the round's size, never the thread count.
const MIN_CHUNK: usize = 256;
const MAX_CHUNK: usize = 1 << 12;

fn chunk_of(len: usize) -> usize {
    (len / 64).clamp(MIN_CHUNK, MAX_CHUNK)
}

/// Subtrees of at least this many primitives are laid out in parallel (`rayon::join`), down to
/// `PARALLEL_MAX_DEPTH`; the rest with an explicit stack, however deep.
const PARALLEL_MIN: u32 = 1 << 14;
const PARALLEL_MAX_DEPTH: u32 = 48;

/// Build the tree over `prims` (left in leaf order) with a neighbour search `radius` each side.
pub(super) fn build(
    prims: &mut Vec<BuildPrim>,
    params: &BuildParams,
    radius: usize,
    progress: &Progress,
) -> Result<(Subtree, u32), Cancelled> {
    let n = prims.len();
    if n == 0 {
        return Ok((Subtree::Flat(vec![BvhNode::leaf(Aabb::EMPTY, 0, 0)]), 0));
    }
    super::morton::sort(prims);
    progress.check()?;
    let ci = params.cost.intersection as f64;
    let (mut nodes, mut clusters, mut boxes) = region(|| {
        let mut nodes: Vec<Cluster> = Vec::with_capacity(2 * n - 1);
        nodes.par_extend(prims.par_iter().enumerate().map(|(i, p)| {
            let bounds = p.bounds();
            let cost = ci * bounds.area() as f64;
            Cluster { bounds, left: LEAF, right: i as u32, count: 1, size: 1, cost, leaf: true }
        }));
        let clusters: Vec<u32> = (0..n as u32).into_par_iter().collect();
        // The clusters' boxes side by side in cluster order: the search reads them in a row.
        let boxes: Vec<Aabb> = nodes.par_iter().map(|c| c.bounds).collect();
        (nodes, clusters, boxes)
    });
    let radius = radius.max(1);
    // The next round's lists are written into the last round's buffers: freeing the first
    // rounds' lists (hundreds of megabytes) took a serial tenth of the rounds' time.
    let (mut spare, mut spare_boxes, mut nearest) = (Vec::new(), Vec::new(), Vec::new());
    while clusters.len() > 1 {
        progress.check()?;
        // A round too small to give 16 threads a chunk each is not marked parallel: issue 37's
        // serial fraction, for a 16-thread projection, counts it as serial.
        let small = clusters.len() < 16 * MIN_CHUNK;
        let mut round = || {
            nearest_into(&boxes, radius, &mut nearest);
            // The closest pair of the whole list is always mutual, but equal areas could make a
            // round without one: then the first cluster and its nearest are made mutual.
            if !(0..clusters.len()).into_par_iter().any(|i| nearest[nearest[i]] == i) {
                let j = nearest[0];
                nearest[j] = 0;
            }
            compact(&mut nodes, &clusters, &boxes, &nearest, params, &mut spare, &mut spare_boxes);
        };
        if small {
            round()
        } else {
            region(round)
        }
        std::mem::swap(&mut clusters, &mut spare);
        std::mem::swap(&mut boxes, &mut spare_boxes);
    }
    let root = clusters[0];
    let (out, order) = layout(&nodes, root, prims, progress)?;
    *prims = order;
    Ok((Subtree::Flat(out), 0))
}

/// One round's merges and compaction, in parallel over fixed chunks of clusters (Meister &
/// Bittner §4.3): each chunk counts the clusters it keeps and the merges it makes, prefix sums
/// give each chunk its places, and every chunk writes its part of the next round's clusters and
/// boxes and its merged nodes, in order. Mutual nearest neighbours merge into the first of the
/// pair's place; the merged nodes are numbered in cluster order.
fn compact(
    nodes: &mut Vec<Cluster>,
    clusters: &[u32],
    boxes: &[Aabb],
    nearest: &[usize],
    params: &BuildParams,
    next: &mut Vec<u32>,
    next_boxes: &mut Vec<Aabb>,
) {
    let len = clusters.len();
    let chunk = chunk_of(len);
    let chunks = len.div_ceil(chunk);
    let range = |c: usize| c * chunk..((c + 1) * chunk).min(len);
    // Each cluster is kept (alone or as the first of a merged pair) or dropped (the second).
    let kept = |i: usize| nearest[nearest[i]] != i || i < nearest[i];
    let merges = |i: usize| nearest[nearest[i]] == i && i < nearest[i];
    let counts: Vec<(usize, usize)> = (0..chunks)
        .into_par_iter()
        .map(|c| range(c).fold((0, 0), |(k, m), i| (k + kept(i) as usize, m + merges(i) as usize)))
        .collect();
    let old = nodes.len();
    let (kept_total, merged_total) = counts.iter().fold((0, 0), |(k, m), &(a, b)| (k + a, m + b));
    next.clear();
    next.par_extend(rayon::iter::repeat_n(0, kept_total));
    next_boxes.clear();
    next_boxes.par_extend(rayon::iter::repeat_n(Aabb::EMPTY, kept_total));
    let placeholder = nodes[0];
    nodes.par_extend(rayon::iter::repeat_n(placeholder, merged_total));
    let (done, fresh) = nodes.split_at_mut(old);
    let done: &[Cluster] = done;
    // Each chunk's slices of the outputs, cut in order.
    let mut parts = Vec::with_capacity(chunks);
    let (mut rest, mut rest_boxes, mut rest_fresh) = (&mut next[..], &mut next_boxes[..], fresh);
    for (c, &(k, m)) in counts.iter().enumerate() {
        let (a, more) = std::mem::take(&mut rest).split_at_mut(k);
        let (b, more_boxes) = std::mem::take(&mut rest_boxes).split_at_mut(k);
        let (f, more_fresh) = std::mem::take(&mut rest_fresh).split_at_mut(m);
        (rest, rest_boxes, rest_fresh) = (more, more_boxes, more_fresh);
        parts.push((c, a, b, f));
    }
    let first_merge: Vec<usize> =
        counts.iter().scan(old, |sum, &(_, m)| Some(std::mem::replace(sum, *sum + m))).collect();
    parts.into_par_iter().for_each(|(c, next, next_boxes, fresh)| {
        let (mut k, mut m) = (0, 0);
        for i in range(c) {
            let j = nearest[i];
            if nearest[j] == i {
                if i < j {
                    // Mutual: the first of the pair makes the merged cluster, in its place.
                    let (l, r) = (clusters[i], clusters[j]);
                    fresh[m] = merged(node(done, l), node(done, r), l, r, boxes[i].union(boxes[j]), params);
                    (next[k], next_boxes[k]) = ((first_merge[c] + m) as u32, fresh[m].bounds);
                    (k, m) = (k + 1, m + 1);
                }
            } else {
                (next[k], next_boxes[k]) = (clusters[i], boxes[i]);
                k += 1;
            }
        }
    });
}

/// A node made in an earlier round.
#[inline]
fn node(done: &[Cluster], k: u32) -> &Cluster {
    &done[k as usize]
}

/// The merge of `a` (node `l`) and `b` (node `r`): primitives, cost, leaf or not (a subtree of at
/// most `max_leaf_size` primitives cheaper under the SAH as one leaf than as its split becomes
/// one), and its size in nodes once laid out.
fn merged(a: &Cluster, b: &Cluster, l: u32, r: u32, bounds: Aabb, params: &BuildParams) -> Cluster {
    let count = a.count + b.count;
    let (cost, leaf) = params.cost.leaf_or_split(bounds.area() as f64, count, a.cost + b.cost, params.max_leaf_size);
    let size = if leaf { 1 } else { 1 + a.size + b.size };
    Cluster { bounds, left: l, right: r, count, size, cost, leaf }
}

/// For each cluster (by its box in `boxes`), into `out`, the index of the one within `radius` whose union
/// with it has the smallest area. Ties go to the nearer in order; at equal distance d, a cluster in an even
/// block of d (i / d even) takes the one after it, in an odd block the one before, so that equal
/// boxes (a million copies of one triangle) pair up, all of them each round, instead of one pair.
fn nearest_into(boxes: &[Aabb], radius: usize, out: &mut Vec<usize>) {
    let len = boxes.len();
    let chunk = chunk_of(len);
    out.clear();
    out.par_extend(rayon::iter::repeat_n(0, len));
    // Each pair's area is computed once: a chunk of clusters first works out, for every cluster
    // from `radius` before the chunk to its end, the areas with the `radius` clusters after it,
    // then each cluster of the chunk reads its pairs both ways from that table.
    out.par_chunks_mut(chunk).enumerate().for_each(|(c, out)| {
        let start = c * chunk;
        let from = start.saturating_sub(radius);
        let end = start + out.len();
        let mut ahead = vec![f32::INFINITY; (end - from) * radius];
        for i in from..end {
            for k in 1..=radius.min(len - 1 - i.min(len - 1)) {
                ahead[(i - from) * radius + k - 1] = boxes[i].union(boxes[i + k]).area();
            }
        }
        for (o, i) in out.iter_mut().zip(start..end) {
            let rank = |j: usize| {
                let d = j.abs_diff(i);
                let toward = if (i / d).is_multiple_of(2) { j > i } else { j < i };
                (d, !toward)
            };
            let mut best = (f32::INFINITY, usize::MAX);
            let mut consider = |a: f32, j: usize| {
                if best.1 == usize::MAX || a < best.0 || (a == best.0 && rank(j) < rank(best.1)) {
                    best = (a, j);
                }
            };
            for k in 1..=radius.min(i) {
                consider(ahead[(i - k - from) * radius + k - 1], i - k);
            }
            for k in 1..=radius.min(len - 1 - i) {
                consider(ahead[(i - from) * radius + k - 1], i + k);
            }
            *o = best.1;
        }
    });
}

/// `nearest_into` a new vector.
#[cfg(test)]
fn nearest_neighbours(boxes: &[Aabb], radius: usize) -> Vec<usize> {
    let mut out = Vec::new();
    nearest_into(boxes, radius, &mut out);
    out
}

/// The clustered tree in bvhscope's layout (each node's children a pair, parents before
/// children, a node's left subtree right after its pair, as the top-down builds lay out theirs)
/// and the primitives in leaf order. Every subtree's place is known from the sizes worked out
/// while clustering, so big subtrees are laid out in parallel.
fn layout(
    nodes: &[Cluster],
    root: u32,
    prims: &[BuildPrim],
    progress: &Progress,
) -> Result<(Vec<BvhNode>, Vec<BuildPrim>), Cancelled> {
    let (mut out, mut order) = region(|| {
        let size = nodes[root as usize].size as usize;
        let mut out = Vec::with_capacity(size);
        out.par_extend(rayon::iter::repeat_n(BvhNode::leaf(Aabb::EMPTY, 0, 0), size));
        let mut order = Vec::with_capacity(prims.len());
        order.par_extend(rayon::iter::repeat_n(prims[0], prims.len()));
        (out, order)
    });
    let (slot, rest) = out.split_first_mut().expect("a root");
    let at = Place { nodes, prims, progress };
    at.subtree(root, slot, rest, 1, &mut order, 0, 0)?;
    Ok((out, order))
}

/// What every subtree's layout reads.
struct Place<'a> {
    nodes: &'a [Cluster],
    prims: &'a [BuildPrim],
    progress: &'a Progress<'a>,
}

impl Place<'_> {
    /// Lay out node `k` into `slot`, its other nodes into `rest` (the first of which has global
    /// index `rest_base`), its primitives into `order` (the first of which is leaf slot `first`).
    #[allow(clippy::too_many_arguments)]
    fn subtree(
        &self,
        k: u32,
        slot: &mut BvhNode,
        rest: &mut [BvhNode],
        rest_base: u32,
        order: &mut [BuildPrim],
        first: u32,
        depth: u32,
    ) -> Result<(), Cancelled> {
        let c = &self.nodes[k as usize];
        if c.leaf || c.count < PARALLEL_MIN {
            // One of many subtrees laid out side by side (a task of the parallel layout).
            return region(|| self.sequential(k, slot, rest, rest_base, order, first, depth));
        }
        if depth >= PARALLEL_MAX_DEPTH {
            return self.sequential(k, slot, rest, rest_base, order, first, depth);
        }
        self.progress.check()?;
        *slot = BvhNode::interior(c.bounds, rest_base, c.bounds.widest_axis() as u8);
        self.progress.add(self.progress.split_units(c.count as usize, depth));
        let (l, r) = (&self.nodes[c.left as usize], &self.nodes[c.right as usize]);
        let (pair, rests) = rest.split_at_mut(2);
        let (left_slot, right_slot) = pair.split_at_mut(1);
        let (left_rest, right_rest) = rests.split_at_mut(l.size as usize - 1);
        let (left_order, right_order) = order.split_at_mut(l.count as usize);
        let right_base = rest_base + 2 + left_rest.len() as u32;
        let (a, b) = rayon::join(
            || self.subtree(c.left, &mut left_slot[0], left_rest, rest_base + 2, left_order, first, depth + 1),
            || {
                self.subtree(
                    c.right,
                    &mut right_slot[0],
                    right_rest,
                    right_base,
                    right_order,
                    first + l.count,
                    depth + 1,
                )
            },
        );
        debug_assert_eq!(r.size as usize - 1, right_rest.len());
        a.and(b)
    }

    /// `subtree` with an explicit stack (no recursion, however deep the tree): local place 0 is
    /// `slot`, place q ≥ 1 is `rest[q - 1]`.
    #[allow(clippy::too_many_arguments)]
    fn sequential(
        &self,
        root: u32,
        slot: &mut BvhNode,
        rest: &mut [BvhNode],
        rest_base: u32,
        order: &mut [BuildPrim],
        first: u32,
        depth0: u32,
    ) -> Result<(), Cancelled> {
        let (mut next, mut filled, mut done, mut steps) = (1usize, 0usize, 0u64, 0u32);
        let mut stack = vec![(root, 0usize, depth0)];
        let mut under = Vec::new();
        while let Some((k, place, depth)) = stack.pop() {
            steps += 1;
            if steps.is_multiple_of(256) {
                self.progress.check()?;
            }
            let c = &self.nodes[k as usize];
            let node = if c.leaf {
                let start = first + filled as u32;
                under.clear();
                under.push(k);
                while let Some(u) = under.pop() {
                    let cu = &self.nodes[u as usize];
                    if cu.left == LEAF {
                        order[filled] = self.prims[cu.right as usize];
                        filled += 1;
                    } else {
                        under.extend([cu.right, cu.left]);
                    }
                }
                done += self.progress.leaf_units(c.count as usize, depth);
                BvhNode::leaf(c.bounds, start, c.count as u16)
            } else {
                let left = next;
                next += 2;
                done += self.progress.split_units(c.count as usize, depth);
                stack.push((c.right, left + 1, depth + 1));
                stack.push((c.left, left, depth + 1));
                BvhNode::interior(c.bounds, rest_base + left as u32 - 1, c.bounds.widest_axis() as u8)
            };
            if place == 0 {
                *slot = node;
            } else {
                rest[place - 1] = node;
            }
        }
        self.progress.add(done);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::params::Strategy;

    /// Every primitive in exactly one leaf of at most the leaf size, each box its subtree's union,
    /// and merging only ever joins neighbours in Morton order, so a row of boxes is paired in order.
    #[test]
    fn the_tree_holds_every_primitive_once_in_tight_boxes() {
        let mesh = crate::mesh::generate::torus(2.0, 0.5, 64, 40);
        let control = crate::work::WorkControl::new();
        let progress = Progress::new(&control, 1);
        let params = BuildParams { strategy: Strategy::Ploc, max_leaf_size: 4, ..BuildParams::default() };
        let mut prims: Vec<BuildPrim> = (0..mesh.triangle_count())
            .map(|i| BuildPrim::new(Aabb::from_points(&mesh.triangle(i as u32)), i as u32))
            .collect();
        let (tree, _) = build(&mut prims, &params, 8, &progress).unwrap();
        let nodes = tree.into_nodes();
        let mut seen = vec![0u32; prims.len()];
        for n in &nodes {
            if n.is_leaf() {
                assert!(n.count >= 1 && n.count <= 4);
                let b = (n.index..n.index + n.count as u32).fold(Aabb::EMPTY, |b, s| {
                    seen[prims[s as usize].index() as usize] += 1;
                    b.union(prims[s as usize].bounds())
                });
                assert_eq!(n.bounds(), b);
            } else {
                let (l, r) = (nodes[n.index as usize].bounds(), nodes[n.index as usize + 1].bounds());
                assert_eq!(n.bounds(), l.union(r));
            }
        }
        assert!(seen.iter().all(|&s| s == 1));
    }

    /// Equal boxes pair up, every one of them in one round.
    #[test]
    fn equal_boxes_all_pair_up() {
        let b = Aabb::new(glam::Vec3::ZERO, glam::Vec3::ONE);
        let nn = nearest_neighbours(&vec![b; 8], 4);
        assert!((0..8).all(|i| nn[nn[i]] == i), "{nn:?}");
    }

    #[test]
    fn mutual_nearest_neighbours_in_a_row_pair_up() {
        // Boxes at x = 0, 1, 10, 11: (0, 1) and (10, 11) are each other's nearest.
        let boxes: Vec<Aabb> = [0.0f32, 1.0, 10.0, 11.0]
            .iter()
            .map(|&x| Aabb::new(glam::Vec3::new(x, 0.0, 0.0), glam::Vec3::new(x + 0.5, 1.0, 1.0)))
            .collect();
        assert_eq!(nearest_neighbours(&boxes, 2), vec![1, 0, 3, 2]);
    }
}
