//! End-point overlap (EPO; Aila, Karras & Laine, "On Quality Metrics of Bounding Volume
//! Hierarchies", HPG 2013): how much of the scene's surface lies inside boxes of nodes that do not
//! hold it. A ray that starts or ends on a triangle (every secondary ray does) must visit every
//! node whose box contains that point; the nodes not above the triangle's leaf are pure overhead,
//! which the SAH, counting only box areas, does not see.
//!
//! EPO = Σ over nodes n of C(n) · Σ over triangles t outside n's subtree of A(t ∩ box(n)),
//! divided by the total surface area, with C(n) weighting nodes as the SAH does: C_trav for an
//! interior node, C_isect·(its triangles) for a leaf. A(t ∩ box) is the area of the triangle
//! clipped to the box (Sutherland & Hodgman's polygon clipping, 1974).

use super::Bvh;
use super::Hierarchy;
use crate::geometry::Aabb;
use glam::{DVec3, Vec3};
use rayon::prelude::*;

/// The area of the part of `tri` inside `b` (boundary included).
pub fn clipped_area(tri: &[Vec3; 3], b: &Aabb) -> f64 {
    // A triangle clipped by six planes has at most 9 corners.
    let mut poly = [DVec3::ZERO; 9];
    let mut len = 3;
    for (i, v) in tri.iter().enumerate() {
        poly[i] = v.as_dvec3();
    }
    let (lo, hi) = (Vec3::from(b.min).as_dvec3(), Vec3::from(b.max).as_dvec3());
    for axis in 0..3 {
        for (bound, keep_above) in [(lo[axis], true), (hi[axis], false)] {
            // Signed distance inside the half-space: >= 0 is kept.
            let inside = |p: DVec3| if keep_above { p[axis] - bound } else { bound - p[axis] };
            let mut out = [DVec3::ZERO; 9];
            let mut n = 0;
            for k in 0..len {
                let (p, q) = (poly[k], poly[(k + 1) % len]);
                let (dp, dq) = (inside(p), inside(q));
                if dp >= 0.0 {
                    out[n] = p;
                    n += 1;
                }
                if (dp >= 0.0) != (dq >= 0.0) {
                    let mut x = p + (q - p) * (dp / (dp - dq));
                    x[axis] = bound; // exactly on the plane, whatever the rounding
                    out[n] = x;
                    n += 1;
                }
            }
            if n < 3 {
                return 0.0;
            }
            (poly, len) = (out, n);
        }
    }
    let mut twice = DVec3::ZERO;
    for k in 1..len - 1 {
        twice += (poly[k] - poly[0]).cross(poly[k + 1] - poly[0]);
    }
    0.5 * twice.length()
}

fn triangle_area(t: &[Vec3; 3]) -> f64 {
    0.5 * (t[1] - t[0]).as_dvec3().cross((t[2] - t[0]).as_dvec3()).length()
}

fn overlaps(a: &Aabb, b: &Aabb) -> bool {
    !(a.max.cmplt(b.min).any() || b.max.cmplt(a.min).any())
}

fn total_area(bvh: &Bvh) -> f64 {
    bvh.tris.iter().map(triangle_area).sum()
}

/// Each node's term of the EPO sum (its share of the total; they add up to `of`). The triangles a
/// node's box meets are found through the tree itself, so the cost is about that of one box query
/// per node; nodes are done in parallel.
pub fn node_terms(bvh: &Bvh, h: &Hierarchy) -> Vec<f64> {
    let total = total_area(bvh);
    (0..bvh.nodes.len()).into_par_iter().map(|n| term(bvh, h, total, n)).collect()
}

/// One node's term (the node inspector's "EPO share").
pub fn node_term(bvh: &Bvh, h: &Hierarchy, node: usize) -> f64 {
    term(bvh, h, total_area(bvh), node)
}

fn term(bvh: &Bvh, h: &Hierarchy, total: f64, n: usize) -> f64 {
    if total <= 0.0 {
        return 0.0;
    }
    let c = bvh.params.cost;
    let node = &bvh.nodes[n];
    let b = node.bounds();
    let mut sum = 0f64;
    let mut stack = vec![0usize];
    while let Some(m) = stack.pop() {
        let other = &bvh.nodes[m];
        // The node's own subtree holds only its own triangles.
        if m == n || !overlaps(&other.bounds(), &b) {
            continue;
        }
        if other.is_leaf() {
            for s in other.prims() {
                if !h.holds(n, s as u32) && overlaps(&Aabb::from_points(&bvh.tris[s]), &b) {
                    sum += clipped_area(&bvh.tris[s], &b);
                }
            }
        } else {
            stack.extend([other.index as usize, other.index as usize + 1]);
        }
    }
    let weight = if node.is_leaf() { c.intersection as f64 * node.count as f64 } else { c.traversal as f64 };
    weight * sum / total
}

/// The tree's EPO.
pub fn of(bvh: &Bvh) -> f64 {
    node_terms(bvh, &Hierarchy::of(bvh)).iter().sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::{BuildParams, BvhNode, Layout, SplitStrategy};
    use crate::mesh::generate;

    /// Two leaves under a root, both triangles in the plane z = 0 and overlapping in x:
    /// T0 = (0,0) (2,0) (0,2), area 2, in leaf 1 with box x 0..2; T1 = (1,0) (3,0) (3,2), area 2, in
    /// leaf 2 with box x 1..3. Leaf 1's box holds the part of T1 with x ≤ 2: the triangle (1,0)
    /// (2,0) (2,1), area 1/2; leaf 2's box the part of T0 with x ≥ 1: (1,0) (2,0) (1,1), area 1/2.
    /// The root holds both. EPO = (1·½ + 1·½) / 4 = 0.25 with C_isect = 1 and one triangle a leaf.
    #[test]
    fn two_overlapping_leaves_by_hand() {
        let tris = vec![
            [Vec3::new(0.0, 0.0, 0.0), Vec3::new(2.0, 0.0, 0.0), Vec3::new(0.0, 2.0, 0.0)],
            [Vec3::new(1.0, 0.0, 0.0), Vec3::new(3.0, 0.0, 0.0), Vec3::new(3.0, 2.0, 0.0)],
        ];
        let b = |t: &[Vec3; 3]| Aabb::from_points(t);
        let bvh = Bvh {
            nodes: vec![
                BvhNode::interior(b(&tris[0]).union(b(&tris[1])), 1, 0),
                BvhNode::leaf(b(&tris[0]), 0, 1),
                BvhNode::leaf(b(&tris[1]), 1, 1),
            ],
            prim_ids: vec![0, 1],
            tris,
            params: BuildParams { layout: Layout::Binary, ..BuildParams::default() },
            report: Default::default(),
        };
        assert_eq!(clipped_area(&bvh.tris[1], &bvh.nodes[1].bounds()), 0.5);
        assert_eq!(clipped_area(&bvh.tris[0], &bvh.nodes[2].bounds()), 0.5);
        assert_eq!(node_terms(&bvh, &Hierarchy::of(&bvh)), vec![0.0, 0.125, 0.125]);
        assert_eq!(of(&bvh), 0.25);
    }

    #[test]
    fn clipping_keeps_what_is_inside() {
        let t = [Vec3::ZERO, Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0)];
        let unit = Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0));
        assert_eq!(clipped_area(&t, &unit), 0.5, "all inside");
        assert_eq!(clipped_area(&t, &Aabb::new(Vec3::splat(2.0), Vec3::splat(3.0))), 0.0, "all outside");
        // The square 0..0.5 in x and y cuts the corner x, y ≤ 0.5: all of it below x + y ≤ 1.
        let corner = Aabb::new(Vec3::new(0.0, 0.0, -1.0), Vec3::new(0.5, 0.5, 1.0));
        assert!((clipped_area(&t, &corner) - 0.25).abs() < 1e-12);
        // A tilted triangle through a box: the part inside has the area of the box's cross-section.
        let tilted = [Vec3::new(-4.0, -4.0, -4.0), Vec3::new(4.0, -4.0, 4.0), Vec3::new(0.0, 8.0, 0.0)];
        let a = clipped_area(&tilted, &unit); // the plane z = x, cut by |x|,|y| ≤ 1: a 2 by 2√2 rectangle
        assert!((a - 4.0 * 2f64.sqrt()).abs() < 1e-9, "{a}");
    }

    /// The tree-guided sum equals the brute-force one (every node against every triangle).
    #[test]
    fn node_terms_match_a_brute_force_sum() {
        for strategy in [SplitStrategy::Midpoint, SplitStrategy::SahBinned] {
            let mesh = generate::torus_knot(2, 3, 0.3, 48, 6);
            let bvh = Bvh::build(&mesh, &BuildParams { strategy, layout: Layout::Binary, ..BuildParams::default() });
            let h = Hierarchy::of(&bvh);
            let fast = node_terms(&bvh, &h);
            let total: f64 = bvh.tris.iter().map(triangle_area).sum();
            let c = bvh.params.cost;
            for (n, node) in bvh.nodes.iter().enumerate() {
                let sum: f64 = (0..bvh.tris.len())
                    .filter(|&s| !h.holds(n, s as u32))
                    .map(|s| clipped_area(&bvh.tris[s], &node.bounds()))
                    .sum();
                let w = if node.is_leaf() { c.intersection as f64 * node.count as f64 } else { c.traversal as f64 };
                let brute = w * sum / total;
                assert!(
                    (fast[n] - brute).abs() <= 1e-12 + 1e-9 * brute,
                    "{strategy:?} node {n}: {} vs {brute}",
                    fast[n]
                );
            }
            let epo: f64 = fast.iter().sum();
            assert!(epo > 0.0, "a knot's boxes overlap its other turns");
        }
    }
}
