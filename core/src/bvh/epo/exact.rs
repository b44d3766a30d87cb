//! One node's EPO sum, exactly: the triangles outside its subtree that meet its box, found by
//! walking the tree itself from the root (the tree is a spatial index of its own triangles).
//! Subtrees whose geometry misses the box are skipped; subtrees whose geometry lies inside it add
//! their area without a clip (prefix sums over the leaf order give any subtree's area at once);
//! only triangles that cross the box's boundary are clipped (not those that only touch it). A walk stops, unfinished, once it
//! has done `cap` units of work.

use super::clip::{clipped_area, inside, meets_only_in_a_plane, overlaps, tri_box, triangle_area};
use crate::bvh::hierarchy::Hierarchy;
use crate::bvh::node::Bvh;
use crate::geometry::Aabb;
use rayon::prelude::*;

/// Whether a pass over `items` nodes, triangles or points gives 16 threads work: then it is
/// marked a parallel region (issue 37's serial fraction), else it counts as serial.
pub(super) fn wide(items: usize) -> bool {
    items >= 1 << 12
}

/// Work units: a node visited or a triangle's box tested is one; a clip costs this many more.
pub(super) const CLIP_WORK: u64 = 8;

/// What every walk reads: the tree, its hierarchy, the surface's prefix sums and, where the
/// nodes' own boxes do not bound their subtrees' triangles, boxes that do.
pub(super) struct Prepared<'a> {
    pub bvh: &'a Bvh,
    pub h: &'a Hierarchy,
    /// `prefix[s]`: the area of the triangles in slots `0..s` of the leaf order.
    pub prefix: Vec<f64>,
    /// Per node, a box around its subtree's nodes' boxes and triangles: only where some node's
    /// box does not hold its children's boxes and its triangles (an SBVH's leaves hold cut
    /// triangles; an imported tree may have any boxes). `None`: the nodes' boxes do.
    cover: Option<Vec<Aabb>>,
}

/// `prefix[s]`: the area of triangles `0..s` (`parallel::exclusive_scan`: the same on any
/// thread count).
fn running_areas(tris: &[[glam::Vec3; 3]]) -> Vec<f64> {
    let mut prefix: Vec<f64> = tris.par_iter().map(triangle_area).chain(rayon::iter::once(0.0)).collect();
    crate::parallel::exclusive_scan(&mut prefix);
    prefix
}

impl<'a> Prepared<'a> {
    pub fn new(bvh: &'a Bvh, h: &'a Hierarchy) -> Prepared<'a> {
        // Passes over every triangle and node: parallel regions where they give 16 threads work.
        let wide = wide(bvh.tris.len());
        let prefix = crate::parallel::region_if(wide, || running_areas(&bvh.tris));
        let nodes = &bvh.nodes;
        let sound = crate::parallel::region_if(wide, || {
            (0..nodes.len()).into_par_iter().all(|i| {
                let (node, b) = (&nodes[i], nodes[i].bounds());
                if node.is_leaf() {
                    node.prims().all(|s| bvh.tris.get(s).is_some_and(|t| inside(&tri_box(t), &b)))
                } else {
                    [node.index as usize, node.index as usize + 1]
                        .iter()
                        .all(|&c| c > i && nodes.get(c).is_some_and(|c| inside(&c.bounds(), &b)))
                }
            })
        });
        let cover = (!sound).then(|| {
            let mut cover: Vec<Aabb> = nodes.iter().map(|n| n.bounds()).collect();
            // Children come after their parents (`Hierarchy::of` reads the array so too).
            for i in (0..nodes.len()).rev() {
                let node = &nodes[i];
                if node.is_leaf() {
                    for s in node.prims() {
                        cover[i] = cover[i].union(tri_box(&bvh.tris[s]));
                    }
                } else {
                    for c in [node.index as usize, node.index as usize + 1] {
                        if c > i && c < nodes.len() {
                            cover[i] = cover[i].union(cover[c]);
                        }
                    }
                }
            }
            cover
        });
        Prepared { bvh, h, prefix, cover }
    }

    /// The whole surface (every slot of the leaf order, as the definition counts it).
    pub fn total(&self) -> f64 {
        *self.prefix.last().unwrap_or(&0.0)
    }

    /// The area of the slots `a..b` of the leaf order.
    #[inline]
    pub fn range_area(&self, a: u32, b: u32) -> f64 {
        self.prefix[b as usize] - self.prefix[a as usize]
    }

    /// A box around everything in `m`'s subtree: its nodes' boxes and its triangles.
    #[inline(always)]
    pub fn cover(&self, m: usize) -> Aabb {
        match &self.cover {
            Some(c) => c[m],
            None => self.bvh.nodes[m].bounds(),
        }
    }

    /// Node `n`'s weight in the sum: the SAH's cost of visiting it.
    pub fn weight(&self, n: usize) -> f64 {
        let (c, node) = (self.bvh.params.cost, &self.bvh.nodes[n]);
        if node.is_leaf() {
            c.intersection as f64 * node.count as f64
        } else {
            c.traversal as f64
        }
    }

    /// Σ over the slots s outside `n`'s subtree of the area of triangle s inside `n`'s box, and
    /// the work it took; `None` for the sum where the walk passed `cap` units of work.
    pub fn walk(&self, n: usize, cap: u64, stack: &mut Vec<u32>) -> (Option<f64>, u64) {
        let (bvh, h) = (self.bvh, self.h);
        let b = bvh.nodes[n].bounds();
        let (first, end) = (h.first[n], h.first[n] + h.count[n]);
        let mut sum = 0f64;
        let mut work = 0u64;
        stack.clear();
        stack.push(0);
        while let Some(m) = stack.pop() {
            work += 1;
            if work > cap {
                return (None, work);
            }
            let m = m as usize;
            // The node's own subtree holds only its own triangles.
            if m == n {
                continue;
            }
            let g = self.cover(m);
            if !overlaps(&g, &b) {
                continue;
            }
            if inside(&g, &b) {
                let (f, e) = (h.first[m], h.first[m] + h.count[m]);
                sum += if f <= first && end <= e {
                    // An ancestor (with n's box): all of its surface but n's own.
                    self.range_area(f, first) + self.range_area(end, e)
                } else {
                    self.range_area(f, e)
                };
                continue;
            }
            let node = &bvh.nodes[m];
            if node.is_leaf() {
                work += node.count as u64;
                for s in node.prims() {
                    if h.holds(n, s as u32) {
                        continue;
                    }
                    let t = &bvh.tris[s];
                    let tb = tri_box(t);
                    if !overlaps(&tb, &b) || meets_only_in_a_plane(&tb, &b) {
                        continue;
                    }
                    if inside(&tb, &b) {
                        sum += triangle_area(t);
                    } else {
                        sum += clipped_area(t, &b);
                        work += CLIP_WORK;
                    }
                }
            } else if node.index as usize > m {
                // (Forward only, as children lie: a malformed array's loop is not walked for ever
                // by `node_term`, whose walk has no cap.)
                stack.extend([node.index, node.index + 1]);
            }
        }
        (Some(sum), work)
    }
}
