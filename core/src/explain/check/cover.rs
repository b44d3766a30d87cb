//! Whether boxes cover a triangle, exactly: the triangle is cut by each box into the part inside
//! and the convex pieces outside (Sutherland & Hodgman, "Reentrant polygon clipping", CACM 1974,
//! one plane at a time), and what is left outside every box is uncovered. In f64, boxes grown by
//! the tolerance: a gap between two leaves' boxes is found wherever it is, however thin the
//! triangle, where sampling points of the triangle would miss a gap between its samples.

use crate::geometry::Aabb;
use glam::{DVec3, Vec3};

/// What `uncovered` found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Coverage {
    Covered,
    /// A point of the triangle in none of the boxes.
    Uncovered(Vec3),
    /// The parts outside grew past `MAX_PIECES`: not decided.
    TooComplex,
}

/// Convex pieces kept at once; a triangle cut among a few dozen leaves needs far fewer.
const MAX_PIECES: usize = 4096;

/// The part of convex polygon `poly` on one side of the plane `p[axis] = value`: below it
/// (`keep_below`) or above it, the plane's points on both sides.
fn clip(poly: &[DVec3], axis: usize, value: f64, keep_below: bool) -> Vec<DVec3> {
    let inside = |p: &DVec3| if keep_below { p[axis] <= value } else { p[axis] >= value };
    let mut out = Vec::with_capacity(poly.len() + 1);
    for (i, a) in poly.iter().enumerate() {
        let b = &poly[(i + 1) % poly.len()];
        let (ia, ib) = (inside(a), inside(b));
        if ia {
            out.push(*a);
        }
        if ia != ib {
            let t = (value - a[axis]) / (b[axis] - a[axis]);
            let mut q = *a + (*b - *a) * t;
            q[axis] = value;
            out.push(q);
        }
    }
    out
}

/// The convex pieces of `poly` outside box `b` (from `b.min[axis]` and `b.max[axis]`).
fn outside(poly: Vec<DVec3>, lo: DVec3, hi: DVec3, out: &mut Vec<Vec<DVec3>>) {
    let mut rest = poly;
    for axis in 0..3 {
        let below = clip(&rest, axis, lo[axis], true);
        if !below.is_empty() {
            out.push(below);
        }
        rest = clip(&rest, axis, lo[axis], false);
        let above = clip(&rest, axis, hi[axis], false);
        if !above.is_empty() {
            out.push(above);
        }
        rest = clip(&rest, axis, hi[axis], true);
        if rest.is_empty() {
            return;
        }
    }
}

/// Whether `boxes`, each grown by `tol`, cover triangle `t`; if not, a point they leave out.
pub fn uncovered(t: &[Vec3; 3], boxes: &[Aabb], tol: f32) -> Coverage {
    let grown: Vec<(DVec3, DVec3)> = boxes
        .iter()
        .map(|b| {
            let d = DVec3::splat(tol as f64);
            (DVec3::from(Vec3::from(b.min)) - d, DVec3::from(Vec3::from(b.max)) + d)
        })
        .collect();
    let mut pieces = vec![t.map(DVec3::from).to_vec()];
    for &(lo, hi) in &grown {
        let mut next = Vec::new();
        for p in pieces {
            outside(p, lo, hi, &mut next);
        }
        if next.len() > MAX_PIECES {
            return Coverage::TooComplex;
        }
        pieces = next;
        if pieces.is_empty() {
            return Coverage::Covered;
        }
    }
    // A piece left is outside every box, or lies on a box's face (the planes' points count on
    // both sides of a cut): its centroid tells them apart, strictly outside every box or not.
    let strictly_outside = |c: DVec3| grown.iter().all(|(lo, hi)| (0..3).any(|a| c[a] < lo[a] || c[a] > hi[a]));
    pieces
        .iter()
        .map(|p| p.iter().copied().sum::<DVec3>() / p.len() as f64)
        .find(|&c| strictly_outside(c))
        .map_or(Coverage::Covered, |c| Coverage::Uncovered(c.as_vec3()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri() -> [Vec3; 3] {
        [Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0)]
    }

    fn b(min: [f32; 3], max: [f32; 3]) -> Aabb {
        Aabb::new(Vec3::from(min), Vec3::from(max))
    }

    #[test]
    fn a_box_around_the_triangle_covers_it_and_none_leaves_it_out() {
        assert_eq!(uncovered(&tri(), &[b([0.0; 3], [1.0, 1.0, 0.0])], 0.0), Coverage::Covered);
        assert!(matches!(uncovered(&tri(), &[], 0.0), Coverage::Uncovered(_)));
    }

    /// Two boxes split at x = 0.5 cover it; with a gap between x = 0.51 and 0.56 a point in
    /// the gap is named, however far apart any sample grid would be.
    #[test]
    fn a_gap_between_two_boxes_is_found_inside_it() {
        let (l, r) = (b([0.0; 3], [0.5, 1.0, 0.0]), b([0.5, 0.0, 0.0], [1.0, 0.5, 0.0]));
        assert_eq!(uncovered(&tri(), &[l, r], 1e-7), Coverage::Covered);
        let (l, r) = (b([0.0; 3], [0.51, 1.0, 0.0]), b([0.56, 0.0, 0.0], [1.0, 0.44, 0.0]));
        let Coverage::Uncovered(q) = uncovered(&tri(), &[l, r], 1e-7) else { panic!("the gap") };
        assert!(q.x > 0.51 && q.x < 0.56, "{q}");
        // A gap thinner than a sample spacing of 1/16: still found.
        let (l, r) = (b([0.0; 3], [0.5, 1.0, 0.0]), b([0.5001, 0.0, 0.0], [1.0, 0.5, 0.0]));
        assert!(matches!(uncovered(&tri(), &[l, r], 1e-7), Coverage::Uncovered(_)));
        // ... but not one within the tolerance.
        assert_eq!(uncovered(&tri(), &[l, r], 1e-4), Coverage::Covered);
    }

    /// A sliver triangle entirely outside its box is uncovered, however thin.
    #[test]
    fn a_thin_triangle_outside_is_uncovered() {
        let t = [Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.5, 1e-9, 0.0)];
        assert!(matches!(uncovered(&t, &[b([0.0, 1.0, 0.0], [1.0, 2.0, 0.0])], 1e-7), Coverage::Uncovered(_)));
        assert_eq!(uncovered(&t, &[b([0.0, 0.0, 0.0], [1.0, 1.0, 0.0])], 1e-7), Coverage::Covered);
    }

    /// Many boxes that tile the triangle cover it; remove one and its tile is named.
    #[test]
    fn a_tiling_covers_and_a_missing_tile_is_named() {
        let n = 8;
        let tiles: Vec<Aabb> = (0..n)
            .flat_map(|i| (0..n).map(move |j| (i, j)))
            .map(|(i, j)| {
                let (x, y) = (i as f32 / n as f32, j as f32 / n as f32);
                b([x, y, 0.0], [x + 1.0 / n as f32, y + 1.0 / n as f32, 0.0])
            })
            .collect();
        assert_eq!(uncovered(&tri(), &tiles, 1e-7), Coverage::Covered);
        let mut some = tiles.clone();
        some.remove(9); // (1, 1): x, y in 0.125..0.25
        let Coverage::Uncovered(q) = uncovered(&tri(), &some, 1e-7) else { panic!("the missing tile") };
        assert!((0.125..0.25).contains(&q.x) && (0.125..0.25).contains(&q.y), "{q}");
    }
}
