//! PLOC: Meister & Bittner, "Parallel Locally-Ordered Clustering for Bounding Volume Hierarchy
//! Construction" (IEEE TVCG 2018). The primitives, sorted by Morton code (`morton::sort`), start as
//! one cluster each; every round, each cluster finds its nearest neighbour among the `radius`
//! clusters before and after it in that order (the one whose union with it has the smallest
//! surface area), mutual nearest neighbours merge, and the clusters are compacted, keeping the
//! order; until one is left. The neighbour search, the round's work, runs on all threads.
//!
//! The tree has a primitive per leaf; a bottom-up pass then makes a leaf of every subtree of at
//! most `max_leaf_size` primitives that is cheaper under the SAH as one leaf than as its split
//! (as the paper's leaves of several primitives, and obvhs's, are made). Bottom-up, the tree
//! cannot be cut off at a leaf size before it is built: the clusters do not know their size
//! when they meet.

use super::common::Progress;
use super::split::BuildPrim;
use super::subtree::Subtree;
use crate::bvh::node::BvhNode;
use crate::bvh::BuildParams;
use crate::geometry::Aabb;
use crate::work::Cancelled;
use rayon::prelude::*;

/// A node while clustering: a primitive (`left == LEAF`, `right` its slot in the sorted array) or
/// the merge of two nodes.
#[derive(Clone, Copy)]
struct Cluster {
    bounds: Aabb,
    left: u32,
    right: u32,
}

const LEAF: u32 = u32::MAX;

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
    let mut nodes: Vec<Cluster> = prims
        .par_iter()
        .enumerate()
        .map(|(i, p)| Cluster { bounds: p.bounds(), left: LEAF, right: i as u32 })
        .collect();
    nodes.reserve(n.saturating_sub(1));
    let mut clusters: Vec<u32> = (0..n as u32).collect();
    // The clusters' boxes side by side in cluster order: the search reads them in a row.
    let mut boxes: Vec<Aabb> = nodes.iter().map(|c| c.bounds).collect();
    let radius = radius.max(1);
    while clusters.len() > 1 {
        progress.check()?;
        let mut nearest = nearest_neighbours(&boxes, radius);
        // The closest pair of the whole list is always mutual, but equal areas could make a
        // round without one: then the first cluster and its nearest are made mutual.
        if !(0..clusters.len()).any(|i| nearest[nearest[i]] == i) {
            let j = nearest[0];
            nearest[j] = 0;
        }
        let mut next = Vec::with_capacity(clusters.len());
        let mut next_boxes = Vec::with_capacity(clusters.len());
        for (i, &c) in clusters.iter().enumerate() {
            let j = nearest[i];
            if nearest[j] == i {
                // Mutual: the first of the pair makes the merged cluster, in its place.
                if i < j {
                    let bounds = boxes[i].union(boxes[j]);
                    nodes.push(Cluster { bounds, left: c, right: clusters[j] });
                    next.push(nodes.len() as u32 - 1);
                    next_boxes.push(bounds);
                }
            } else {
                next.push(c);
                next_boxes.push(boxes[i]);
            }
        }
        (clusters, boxes) = (next, next_boxes);
    }
    let root = clusters[0];
    Ok((Subtree::Flat(layout(&nodes, root, prims, params, progress)?), 0))
}

/// For each cluster (by its box in `boxes`), the index of the one within `radius` whose union
/// with it has the smallest area. Ties go to the nearer in order; at equal distance d, a cluster in an even
/// block of d (i / d even) takes the one after it, in an odd block the one before, so that equal
/// boxes (a million copies of one triangle) pair up, all of them each round, instead of one pair.
fn nearest_neighbours(boxes: &[Aabb], radius: usize) -> Vec<usize> {
    const CHUNK: usize = 2048;
    let len = boxes.len();
    let mut out = vec![0usize; len];
    // Each pair's area is computed once: a chunk of clusters first works out, for every cluster
    // from `radius` before the chunk to its end, the areas with the `radius` clusters after it,
    // then each cluster of the chunk reads its pairs both ways from that table.
    out.par_chunks_mut(CHUNK).enumerate().for_each(|(c, out)| {
        let start = c * CHUNK;
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
    out
}

/// The clustered tree in bvhscope's layout (each node's children a pair, parents before
/// children), the subtrees worth one leaf made leaves, and `prims` put into leaf order.
fn layout(
    nodes: &[Cluster],
    root: u32,
    prims: &mut [BuildPrim],
    params: &BuildParams,
    progress: &Progress,
) -> Result<Vec<BvhNode>, Cancelled> {
    // Bottom-up (merged nodes come after their children): primitives and SAH cost per node.
    let ci = params.cost.intersection as f64;
    let mut count = vec![0u32; nodes.len()];
    let mut cost = vec![0f64; nodes.len()];
    let mut leaf = vec![false; nodes.len()];
    for (k, c) in nodes.iter().enumerate() {
        let area = c.bounds.area() as f64;
        if c.left == LEAF {
            (count[k], cost[k], leaf[k]) = (1, ci * area, true);
            continue;
        }
        let (l, r) = (c.left as usize, c.right as usize);
        count[k] = count[l] + count[r];
        (cost[k], leaf[k]) = params.cost.leaf_or_split(area, count[k], cost[l] + cost[r], params.max_leaf_size);
    }
    // Top-down, depth first: the layout, and the leaves' primitives gathered in order.
    let mut out = vec![BvhNode::leaf(Aabb::EMPTY, 0, 0)];
    let mut order: Vec<BuildPrim> = Vec::with_capacity(prims.len());
    let mut stack = vec![(root, 0usize, 0u32)];
    let mut under = Vec::new();
    let mut done = 0u64;
    while let Some((k, slot, depth)) = stack.pop() {
        let c = nodes[k as usize];
        if leaf[k as usize] {
            let first = order.len() as u32;
            under.clear();
            under.push(k);
            while let Some(u) = under.pop() {
                let cu = nodes[u as usize];
                if cu.left == LEAF {
                    order.push(prims[cu.right as usize]);
                } else {
                    under.extend([cu.right, cu.left]);
                }
            }
            out[slot] = BvhNode::leaf(c.bounds, first, count[k as usize] as u16);
            done += progress.leaf_units(count[k as usize] as usize, depth);
            continue;
        }
        let left = out.len();
        out.extend([BvhNode::leaf(Aabb::EMPTY, 0, 0); 2]);
        let e = c.bounds.max - c.bounds.min;
        let axis = if e.x >= e.y && e.x >= e.z {
            0
        } else if e.y >= e.z {
            1
        } else {
            2
        };
        out[slot] = BvhNode::interior(c.bounds, left as u32, axis);
        done += progress.split_units(count[k as usize] as usize, depth);
        stack.push((c.right, left + 1, depth + 1));
        stack.push((c.left, left, depth + 1));
    }
    progress.add(done);
    prims.copy_from_slice(&order);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::SplitStrategy;

    /// Every primitive in exactly one leaf of at most the leaf size, each box its subtree's union,
    /// and merging only ever joins neighbours in Morton order, so a row of boxes is paired in order.
    #[test]
    fn the_tree_holds_every_primitive_once_in_tight_boxes() {
        let mesh = crate::mesh::generate::torus(2.0, 0.5, 64, 40);
        let control = crate::work::WorkControl::new();
        let progress = Progress::new(&control, 1);
        let params = BuildParams { strategy: SplitStrategy::Ploc, max_leaf_size: 4, ..BuildParams::default() };
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
