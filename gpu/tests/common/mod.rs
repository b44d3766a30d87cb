//! Helpers of the GPU tests: the GPU (or a notice), meshes whose every test is exact, the CPU's
//! trace of the same rays, and the check that explains a ray where GPU and CPU differ.
#![allow(dead_code)]

use bvhscope_core::bvh::{
    Accelerator, BuildParams, Bvh, Hit, Layout, RayCounters, Strategy, TraceOptions, TraversalOrder,
};
use bvhscope_core::geometry::{Ray, TriangleTest};
use bvhscope_core::mesh::Mesh;
use bvhscope_core::render::Camera;
use glam::Vec3;

pub use bvhscope_gpu::gpu_for_tests as gpu;

/// The shared meshes, as every package's tests find them (`../shared/models`, a notice when
/// absent, a failure under CI=true).
#[path = "../../../core/tests/common/mod.rs"]
mod core_helpers;
#[allow(unused_imports)]
pub use core_helpers::shared_mesh;

/// Core's generator (SplitMix64), so every run uses the same scene and rays.
pub use bvhscope_core::random::Rng;
/// The incoherent rays of the benchmarks (core's), for the GPU against the CPU (not every test
/// file traces them).
#[allow(unused_imports)]
pub use bvhscope_core::render::incoherent_rays;

/// A number in 0..n by a modulo (not `Rng::below`): the picks the GPU tests were checked with
/// on a GPU, kept so that the exact mesh and the jittered rays stay those.
pub fn below(rng: &mut Rng, n: u64) -> u64 {
    rng.next_u64() % n
}

/// Unit cubes at integer positions of a 6×6×6 grid (a third of the cells), and slanted triangles
/// with small integer vertices: with dyadic ray origins and directions of few bits, every
/// subtraction and product of the slab and watertight tests is exact, so any correct walk on
/// any IEEE single-precision device finds the same hits and does the same work. Rays aimed at the
/// integer grid meet edges and vertices exactly (the watertight test's double-precision
/// fallback) and lie in box planes (the slab test's NaN rule).
pub fn exact_mesh() -> Mesh {
    let mut rng = Rng::new(7);
    let (mut positions, mut triangles) = (Vec::new(), Vec::new());
    let quad = |p: [Vec3; 4], positions: &mut Vec<Vec3>, triangles: &mut Vec<[u32; 3]>| {
        let b = positions.len() as u32;
        positions.extend(p);
        triangles.push([b, b + 1, b + 2]);
        triangles.push([b, b + 2, b + 3]);
    };
    for x in 0..6 {
        for y in 0..6 {
            for z in 0..6 {
                if below(&mut rng, 3) != 0 {
                    continue;
                }
                let o = Vec3::new(x as f32, y as f32, z as f32);
                let c = |i: u32| o + Vec3::new((i & 1) as f32, (i >> 1 & 1) as f32, (i >> 2 & 1) as f32);
                for [a, b, cc, d] in
                    [[0, 1, 3, 2], [4, 6, 7, 5], [0, 4, 5, 1], [2, 3, 7, 6], [0, 2, 6, 4], [1, 5, 7, 3]]
                {
                    quad([c(a), c(b), c(cc), c(d)], &mut positions, &mut triangles);
                }
            }
        }
    }
    for _ in 0..40 {
        let mut v = || Vec3::new(below(&mut rng, 7) as f32, below(&mut rng, 7) as f32, below(&mut rng, 7) as f32);
        let (a, b, c) = (v(), v(), v());
        if (b - a).cross(c - a).length_squared() > 0.0 {
            let i = positions.len() as u32;
            positions.extend([a, b, c]);
            triangles.push([i, i + 1, i + 2]);
        }
    }
    Mesh::from_triangles("exact", positions, triangles)
}

/// Rays whose every test on `exact_mesh` is exact: along the six axes and a few directions of
/// small dyadic components, from origins on a quarter-unit grid in front of the scene, over
/// [0, inf) and over segments.
pub fn exact_rays() -> Vec<Ray> {
    let dirs = [
        Vec3::X,
        -Vec3::X,
        Vec3::Y,
        -Vec3::Y,
        Vec3::Z,
        Vec3::new(-0.0, 0.0, -1.0),
        Vec3::new(1.0, 2.0, -4.0),
        Vec3::new(-1.0, 0.5, 2.0),
        Vec3::new(0.25, -1.0, 0.5),
    ];
    let mut rays = Vec::new();
    for (k, &d) in dirs.iter().enumerate() {
        // A plane across the scene, 10 units back along the direction.
        let (a, b) = {
            let m = d.abs();
            if m.x >= m.y && m.x >= m.z {
                (Vec3::Y, Vec3::Z)
            } else if m.y >= m.z {
                (Vec3::X, Vec3::Z)
            } else {
                (Vec3::X, Vec3::Y)
            }
        };
        let back = Vec3::splat(3.0) - d * (10.0 / d.abs().max_element());
        for i in 0..29 {
            for j in 0..29 {
                let o = back + a * (i as f32 * 0.25 - 3.5) + b * (j as f32 * 0.25 - 3.5);
                let t = if (i + j + k) % 5 == 0 { (2.0, 12.0) } else { (0.0, f32::INFINITY) };
                rays.push(Ray::segment(o, d, t.0, t.1));
            }
        }
    }
    rays
}

pub fn build(mesh: &Mesh, strategy: Strategy, max_leaf_size: u32) -> Bvh {
    Bvh::build(mesh, &BuildParams { strategy, max_leaf_size, layout: Layout::Binary, ..BuildParams::default() })
}

pub const ORDERS: [TraversalOrder; 2] = [TraversalOrder::EntryDistance, TraversalOrder::SplitAxisSign];

/// The CPU's closest hit and counts of each ray (core's walk with `RayCounters`).
pub fn cpu_trace(bvh: &Bvh, rays: &[Ray], order: TraversalOrder) -> (Vec<Option<Hit>>, Vec<RayCounters>) {
    let opts = TraceOptions { order, test: TriangleTest::Watertight };
    rays.iter()
        .map(|r| {
            let mut r = *r;
            let mut c = RayCounters::default();
            (bvh.closest_hit(&mut r, opts, &mut c), c)
        })
        .unzip()
}

/// The rays of a camera's pixels, row by row (what the GPU makes of `Rays::Camera`).
pub fn camera_rays(cam: &Camera) -> Vec<Ray> {
    let g = cam.ray_gen();
    (0..cam.height).flat_map(|y| (0..cam.width).map(move |x| g.pixel_ray(x, y))).collect()
}

/// `x` moved by `k` units in the last place.
fn nudge(x: f32, k: i32) -> f32 {
    let mut y = x;
    for _ in 0..k.abs() {
        y = if k > 0 { y.next_up() } else { y.next_down() };
    }
    y
}

/// Why a ray the GPU and CPU answered differently is within a few ulps of a boundary: some ray
/// whose origin and direction differ from it by at most `ulps` units in the last place per
/// component gives the GPU's hit on the CPU, and some gives its counts. That is the size of what
/// WGSL's f32 rules let a device do differently (a fused product, a flushed denormal, a division
/// or square root within 2.5 ulps in Vulkan). `None`: not explained.
pub fn explain(
    bvh: &Bvh,
    ray: &Ray,
    order: TraversalOrder,
    gpu: (Option<Hit>, Option<RayCounters>),
    ulps: i32,
) -> Option<String> {
    let opts = TraceOptions { order, test: TriangleTest::Watertight };
    let mut rng = Rng::new(ray.origin().x.to_bits() as u64 ^ (ray.dir().y.to_bits() as u64) << 32);
    let same_hit = |a: Option<Hit>, b: Option<Hit>| match (a, b) {
        (None, None) => true,
        (Some(a), Some(b)) => a.prim == b.prim && (a.t - b.t).abs() <= 1e-5 * a.t.abs().max(1e-30),
        _ => false,
    };
    let (mut hit_ok, mut counts_ok) = (false, gpu.1.is_none());
    for _ in 0..512 {
        let mut k = || below(&mut rng, 2 * ulps as u64 + 1) as i32 - ulps;
        let o = ray.origin();
        let d = ray.dir();
        let o = Vec3::new(nudge(o.x, k()), nudge(o.y, k()), nudge(o.z, k()));
        let d = Vec3::new(nudge(d.x, k()), nudge(d.y, k()), nudge(d.z, k()));
        let mut r = Ray::segment(o, d, ray.t_min, ray.t_max);
        let mut c = RayCounters::default();
        let h = bvh.closest_hit(&mut r, opts, &mut c);
        hit_ok |= same_hit(h, gpu.0);
        counts_ok |= gpu.1 == Some(c);
        if hit_ok && counts_ok {
            return Some(format!("a ray within {ulps} ulps per component gives the GPU's result on the CPU"));
        }
    }
    None
}
