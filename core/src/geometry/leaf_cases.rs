//! Test cases shared by the leaf tests' proptests (four, eight, sixteen lanes, and the stored
//! form): grid points and leaves of triangles with a ray aimed into them.

use crate::geometry::Ray;
use glam::Vec3;
use proptest::prelude::*;

/// Grid points: shared vertices and edges, axis-parallel rays and exactly-zero edge functions (the
/// watertight test's double-precision fallback) come up often.
pub(crate) fn grid_point() -> impl Strategy<Value = Vec3> {
    [(-4i32..=4), (-4i32..=4), (-4i32..=4)].prop_map(|v| Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32) * 0.5)
}

/// How a ray is aimed at a triangle: the weights of its three vertices (a vertex, an edge point
/// or an inner point), a grid direction, how many steps back it starts, and its interval.
pub(crate) type Aim = (u32, u32, u32, [i32; 3], u32, u32);

pub(crate) fn aim() -> impl Strategy<Value = Aim> {
    (0u32..3, 0u32..3, 0u32..3, [-3i32..=3, -3i32..=3, -3i32..=3], 1u32..4, 0u32..4)
}

/// The ray `aim` names at `t`: from `s` steps back along a grid direction, with an interval that
/// may cut the hit (a hit exactly at `t_max` is excluded, one at `t_min` kept).
pub(crate) fn aimed_ray(t: &[Vec3; 3], (i, j, k, d, s, interval): Aim) -> Ray {
    let w = (i + j + k).max(1) as f32;
    let at = (t[0] * i as f32 + t[1] * j as f32 + t[2] * k as f32) / w;
    let dir = Vec3::new(d[0] as f32, d[1] as f32, d[2] as f32);
    let mut ray = Ray::new(at - dir * s as f32, dir);
    match interval {
        0 => ray.t_max = s as f32,
        1 => ray.t_min = s as f32 + 0.25,
        _ => {}
    }
    ray
}

/// A leaf of 1 to `max` triangles built from six shared grid points (some degenerate), a ray
/// aimed at one of them (`aimed_ray`), and whether more floats follow the leaf in its array (else
/// the array ends with it: the masked loads).
pub(crate) fn leaf_case(max: usize) -> impl Strategy<Value = (Vec<[Vec3; 3]>, Ray, bool)> {
    let pool = proptest::collection::vec(grid_point(), 6);
    let picks = proptest::collection::vec([0usize..6, 0usize..6, 0usize..6], 1..=max);
    (pool, picks, 0..max, aim(), proptest::bool::ANY).prop_map(|(pool, picks, target, aim, more)| {
        let tris: Vec<[Vec3; 3]> = picks.iter().map(|p| p.map(|q| pool[q])).collect();
        let ray = aimed_ray(&tris[target % tris.len()], aim);
        (tris, ray, more)
    })
}

/// A leaf's nine coordinates, each over its triangles (the wide layouts' leaves), and, when
/// `more`, floats of another leaf after it.
pub(crate) fn by_coordinate(tris: &[[Vec3; 3]], more: bool) -> Vec<f32> {
    let mut coords: Vec<f32> = (0..9).flat_map(|j| tris.iter().map(move |t| t[j / 3][j % 3])).collect();
    if more {
        coords.extend([7.0, -3.5, 1e9, f32::NAN, 0.0, -0.0, 1e-30, 2.0]);
    }
    coords
}
