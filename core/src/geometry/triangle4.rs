//! One ray against up to four triangles in one SIMD pass: the watertight test (Woop, Benthin &
//! Wald 2013) with one lane per triangle, for the leaves of the wide BVHs. The arithmetic is
//! `Watertight::intersect`'s in the same order (glam's dot is `(x·x' + y·y') + z·z'`), each
//! operation rounded as the scalar one is and nothing fused, so lane k is the scalar test of
//! triangle k bit for bit, the double-precision fallback for an exactly-zero edge function
//! included. The triangles are read from the leaf's array (three vertices each, in leaf order)
//! and turned into lanes here: nine loads of four lanes.

use super::shear::{Hits4, WatertightRay};
use crate::geometry::ray::Ray;
use glam::Vec3;
use wide::f32x4;

/// Triangle `k` of a leaf of `count` triangles whose coordinates are `coords` (its `9·count`
/// floats, coordinate by coordinate).
#[inline(always)]
pub(crate) fn leaf_triangle(coords: &[f32], count: usize, k: usize) -> [Vec3; 3] {
    let c = |j: usize| coords[j * count + k];
    [Vec3::new(c(0), c(1), c(2)), Vec3::new(c(3), c(4), c(5)), Vec3::new(c(6), c(7), c(8))]
}

/// The watertight test of `tris` (at most four) against one ray: the mask of the triangles hit
/// within `[ray.t_min, ray.t_max)` and, per lane, the hit's `t`, `u`, `v`.
#[inline(always)]
pub(super) fn watertight_group(p: &WatertightRay, ray: &Ray, tris: &[[Vec3; 3]]) -> Hits4 {
    let n = tris.len().min(4);
    if n == 0 {
        return Hits4 { mask: 0, t: [0.0; 4], u: [0.0; 4], v: [0.0; 4] };
    }
    let lanes = (1u32 << n) - 1;
    // Lane k reads triangle k; lanes past `n` repeat the last one (masked off below).
    let t: [&[Vec3; 3]; 4] = [&tris[0], &tris[1.min(n - 1)], &tris[2.min(n - 1)], &tris[3.min(n - 1)]];
    let coord = |j: usize| f32x4::new(t.map(|t| t[j / 3][j % 3]));
    one_ray_four(p, ray, coord, lanes)
}

/// `watertight_group` of triangles `4g..4g + 4` (those below `count`) of a leaf stored coordinate
/// by coordinate (`coords`, the wide layouts' leaves): each of the nine lanes is one load of four
/// consecutive floats (past the leaf's last triangle they belong to the next coordinate or leaf,
/// or are zero at the array's end, and are masked off). The same arithmetic as `watertight_group`.
#[inline(always)]
pub(super) fn watertight_group_coords(p: &WatertightRay, ray: &Ray, coords: &[f32], count: usize, g: usize) -> Hits4 {
    let n = count.saturating_sub(4 * g).min(4);
    if n == 0 {
        return Hits4 { mask: 0, t: [0.0; 4], u: [0.0; 4], v: [0.0; 4] };
    }
    let lanes = (1u32 << n) - 1;
    let load = |j: usize| {
        let at = j * count + 4 * g;
        match coords.get(at..at + 4) {
            Some(four) => f32x4::new([four[0], four[1], four[2], four[3]]),
            None => f32x4::new(std::array::from_fn(|k| coords.get(at + k).copied().unwrap_or(0.0))),
        }
    };
    one_ray_four(p, ray, load, lanes)
}

/// The watertight test of four triangles against one ray, given `coord(j)`: coordinate j of each
/// triangle (v0.x, v0.y, v0.z, v1.x, …, v2.z; lane k for triangle k). The vertices relative to the
/// origin, sheared, then `edge_test4`: `Watertight::intersect`'s arithmetic, lane by lane.
#[inline(always)]
fn one_ray_four(p: &WatertightRay, ray: &Ray, coord: impl Fn(usize) -> f32x4, lanes: u32) -> Hits4 {
    let o = ray.origin();
    let vertex = |v: usize| {
        [coord(3 * v) - f32x4::splat(o.x), coord(3 * v + 1) - f32x4::splat(o.y), coord(3 * v + 2) - f32x4::splat(o.z)]
    };
    let (a, b, c) = (vertex(0), vertex(1), vertex(2));
    let dot = |v: &[f32x4; 3], r: Vec3| v[0] * f32x4::splat(r.x) + v[1] * f32x4::splat(r.y) + v[2] * f32x4::splat(r.z);
    let (ax, ay) = (dot(&a, p.rx), dot(&a, p.ry));
    let (bx, by) = (dot(&b, p.rx), dot(&b, p.ry));
    let (cx, cy) = (dot(&c, p.rx), dot(&c, p.ry));
    let z = [dot(&a, p.rz), dot(&b, p.rz), dot(&c, p.rz)];
    edge_test4([ax, ay, bx, by, cx, cy], z, f32x4::splat(ray.t_min), f32x4::splat(ray.t_max), lanes)
}

/// The watertight test's second half, four lanes at once (one ray and four triangles, or four
/// rays and one triangle): from the vertices' sheared coordinates `[ax, ay, bx, by, cx, cy]` and
/// their distances along the ray `z` (`a·rz`, `b·rz`, `c·rz`), the edge functions (redone in double
/// precision in a lane where one is exactly zero, as the paper says), the inside test and the
/// hit within `[t_min, t_max)`, for the lanes in `lanes`. Lane by lane the scalar test's arithmetic.
#[inline(always)]
pub(super) fn edge_test4(xy: [f32x4; 6], z: [f32x4; 3], t_min: f32x4, t_max: f32x4, lanes: u32) -> Hits4 {
    let [ax, ay, bx, by, cx, cy] = xy;
    let mut u = cx * by - cy * bx;
    let mut v = ax * cy - ay * cx;
    let mut w = bx * ay - by * ax;
    let zero_f = f32x4::ZERO;
    let zero = (u.simd_eq(zero_f) | v.simd_eq(zero_f) | w.simd_eq(zero_f)).to_bitmask() & lanes;
    if zero != 0 {
        let (mut uu, mut vv, mut ww) = (u.to_array(), v.to_array(), w.to_array());
        let f = |x: f32x4, k: usize| x.to_array()[k] as f64;
        let mut m = zero;
        while m != 0 {
            let k = m.trailing_zeros() as usize;
            m &= m - 1;
            let (ax, ay, bx, by, cx, cy) = (f(ax, k), f(ay, k), f(bx, k), f(by, k), f(cx, k), f(cy, k));
            uu[k] = (cx * by - cy * bx) as f32;
            vv[k] = (ax * cy - ay * cx) as f32;
            ww[k] = (bx * ay - by * ax) as f32;
        }
        (u, v, w) = (f32x4::from(uu), f32x4::from(vv), f32x4::from(ww));
    }
    let o = zero_f;
    let outside = (u.simd_lt(o) | v.simd_lt(o) | w.simd_lt(o)) & (u.simd_gt(o) | v.simd_gt(o) | w.simd_gt(o));
    // Every lane outside its triangle: no hit, and no division to wait for.
    if lanes & !outside.to_bitmask() == 0 {
        return Hits4 { mask: 0, t: [0.0; 4], u: [0.0; 4], v: [0.0; 4] };
    }
    let det = u + v + w;
    let t_scaled = u * z[0] + v * z[1] + w * z[2];
    let inv_det = f32x4::ONE / det;
    let t = t_scaled * inv_det;
    let inside = det.simd_ne(o) & t.simd_ge(t_min) & t.simd_lt(t_max);
    let mask = inside.to_bitmask() & !outside.to_bitmask() & lanes;
    Hits4 { mask, t: t.to_array(), u: (v * inv_det).to_array(), v: (w * inv_det).to_array() }
}

#[cfg(test)]
mod tests {
    use super::super::triangle::{TriangleIntersector, Watertight};
    use super::*;
    use crate::geometry::leaf_cases::{by_coordinate, leaf_case};
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(4000))]
        /// Lane k is the scalar test of triangle k, bit for bit.
        #[test]
        fn four_triangles_at_once_are_four_scalar_tests((tris, ray, _) in leaf_case(4)) {
            let p = Watertight::prepare(&ray);
            let got = Watertight::intersect_group(&p, &ray, &tris);
            prop_assert_eq!(got.mask >> tris.len(), 0, "no lane past the triangles");
            for (k, tri) in tris.iter().enumerate() {
                let want = Watertight::intersect(&p, &ray, tri);
                prop_assert_eq!(got.mask & (1 << k) != 0, want.is_some(), "lane {}: hit or miss", k);
                if let Some(h) = want {
                    let bits = |x: f32| x.to_bits();
                    prop_assert_eq!(
                        (bits(got.t[k]), bits(got.u[k]), bits(got.v[k])),
                        (bits(h.t), bits(h.u), bits(h.v)),
                        "lane {}: bit for bit", k
                    );
                }
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(3000))]
        /// Each group of a leaf stored coordinate by coordinate is the scalar test of its
        /// triangles, bit for bit, whether more data follows the leaf or the array ends there.
        #[test]
        fn a_leaf_stored_by_coordinate_tests_as_its_triangles((tris, ray, more) in leaf_case(7)) {
            let count = tris.len();
            let coords = by_coordinate(&tris, more);
            let p = Watertight::prepare(&ray);
            for g in 0..count.div_ceil(4) {
                let got = Watertight::intersect_group_coords(&p, &ray, &coords, count, g);
                let n = (count - 4 * g).min(4);
                prop_assert_eq!(got.mask >> n, 0, "no lane past the leaf");
                for k in 0..n {
                    let want = Watertight::intersect(&p, &ray, &tris[4 * g + k]);
                    prop_assert_eq!(got.mask & (1 << k) != 0, want.is_some(), "group {} lane {}", g, k);
                    if let Some(h) = want {
                        let bits = |x: f32| x.to_bits();
                        prop_assert_eq!((bits(got.t[k]), bits(got.u[k]), bits(got.v[k])), (bits(h.t), bits(h.u), bits(h.v)));
                    }
                }
            }
        }
    }

    /// No triangles: no lanes, nothing hit (a leaf always has some, but the call must not panic).
    #[test]
    fn no_triangles_hit_nothing() {
        let ray = Ray::new(Vec3::ZERO, Vec3::Z);
        assert_eq!(Watertight::intersect_group(&Watertight::prepare(&ray), &ray, &[]).mask, 0);
    }
}
