//! Tests of `packet.rs`: packets against single rays, and the frustum test against the slab test.

use super::walk::*;
use crate::bvh::accel::{Accelerator, Hit, TraceOptions, PACKET};
use crate::bvh::any::AnyBvh;
use crate::bvh::counters::NoStats;
use crate::bvh::packet::lanes::Four;
use crate::bvh::packet::state::Packet;
use crate::bvh::params::{BuildParams, Layout, Strategy};
use crate::geometry::{Aabb, Ray};
use crate::mesh::generate::{builtin_scene, torus_knot};
use crate::mesh::Mesh;
use crate::render::Camera;
use glam::Vec3;
use std::mem::MaybeUninit;

/// `rays` traced in packets of `size` against single rays: the same hit or miss at the same
/// distance, and the same `t_max` left on each ray. Returns the hits.
fn agree(bvh: &AnyBvh, rays: &[Ray], size: usize, what: &str) -> usize {
    let mut hits = 0;
    let opts = TraceOptions::default();
    for (c, chunk) in rays.chunks(size).enumerate() {
        let mut packet = chunk.to_vec();
        let mut got = vec![Some(Hit { t: -1.0, u: 0.0, v: 0.0, prim: 0 }); chunk.len()];
        bvh.closest_hits(&mut packet, &mut got, opts);
        for (k, (&before, got)) in chunk.iter().zip(&got).enumerate() {
            let mut single = before;
            let want = bvh.closest_hit(&mut single, opts, &mut NoStats);
            assert_eq!(got.map(|h| h.t), want.map(|h| h.t), "{what}: ray {k} of packet {c}");
            assert_eq!(packet[k].t_max, single.t_max, "{what}: ray {k} of packet {c}: t_max");
            if let (Some(g), Some(w)) = (got, want) {
                // Two triangles at exactly the same distance may swap; barycentrics then
                // belong to the triangle reported.
                if g.prim == w.prim {
                    assert_eq!((g.u, g.v), (w.u, w.v), "{what}: ray {k} of packet {c}");
                }
            }
            hits += got.is_some() as usize;
        }
    }
    hits
}

/// A `size`×`size` frame's rays in 8×8 blocks, each in `packet_position` order.
fn primary_blocks(mesh: &Mesh, size: u32) -> Vec<Ray> {
    let cam = Camera::framing_from(&mesh.bounds(), size, size, Vec3::new(0.45, 0.35, 1.0), 45.0);
    let g = cam.ray_gen();
    let mut rays = Vec::new();
    for by in (0..size).step_by(8) {
        for bx in (0..size).step_by(8) {
            rays.extend(
                (0..PACKET as u32)
                    .map(packet_position)
                    .filter(|&(x, y)| bx + x < size && by + y < size)
                    .map(|(x, y)| g.pixel_ray(bx + x, by + y)),
            );
        }
    }
    rays
}

/// The seeded generator's floats in [0, 1), as a closure: the same random cases on every run.
fn uniform(seed: u64) -> impl FnMut() -> f32 {
    let mut rng = crate::random::Rng::new(seed);
    move || rng.unit()
}

/// Rays in every direction from points around the mesh: packets whose rays diverge at once
/// (and whose directions differ in sign, which turns the packet's frustum test off).
fn scattered(mesh: &Mesh, count: usize) -> Vec<Ray> {
    let (c, r) = (mesh.bounds().center(), mesh.bounds().extent().length());
    let mut rnd = uniform(0x2545_F491_4F6C_DD1D);
    let mut rnd = move || rnd() - 0.5;
    (0..count)
        .map(|_| {
            let o = c + Vec3::new(rnd(), rnd(), rnd()) * r;
            let d = Vec3::new(rnd(), rnd(), rnd()).normalize_or(Vec3::X);
            Ray::new(o, d)
        })
        .collect()
}

/// Axis-aligned rays, some with zero direction components and origins on box planes: the slab
/// test's NaN and infinity cases, lane by lane.
fn axis_aligned(mesh: &Mesh) -> Vec<Ray> {
    let b = mesh.bounds();
    let mut rays = Vec::new();
    for i in 0..64 {
        let f = i as f32 / 63.0;
        let p = b.min + (b.max - b.min) * f;
        rays.push(Ray::new(Vec3::new(p.x, p.y, b.max.z + 1.0), Vec3::NEG_Z));
        rays.push(Ray::new(Vec3::new(b.min.x - 1.0, p.y, p.z), Vec3::X));
        rays.push(Ray::new(Vec3::new(b.min.x, b.min.y - 1.0, p.z), Vec3::Y));
        rays.push(Ray::new(Vec3::new(p.x, b.max.y, b.min.z - 1.0), Vec3::Z));
    }
    rays
}

#[test]
fn packets_find_what_single_rays_find() {
    for mesh in [builtin_scene(), torus_knot(2, 3, 0.3, 256, 16)] {
        for layout in Layout::ALL {
            for strategy in Strategy::ALL {
                let bvh = AnyBvh::build(&mesh, &BuildParams { layout, ..BuildParams::with_strategy(strategy) });
                let what = format!("{} {strategy:?} {layout:?}", mesh.name);
                let hits = agree(&bvh, &primary_blocks(&mesh, 64), PACKET, &what);
                assert!(hits > 200 && hits < 64 * 64, "{what}: the frame both hits and misses ({hits})");
                // Partial packets: the last group has padding lanes, or the packet is one ray.
                for size in [1, 3, 5, 33, 63] {
                    agree(&bvh, &primary_blocks(&mesh, 40), size, &what);
                }
                assert!(agree(&bvh, &scattered(&mesh, 2048), PACKET, &what) > 0);
                assert!(agree(&bvh, &axis_aligned(&mesh), PACKET, &what) > 0);
            }
        }
    }
}

/// The same with each kernel forced on the wide trees (`with_simd`): four-ray groups (`Simd4`,
/// `Scalar`), eight-ray groups (`Avx2`) and sixteen-ray groups (`Avx512`), each where the CPU has
/// it, every packet size.
#[test]
fn packets_with_every_kernel_find_what_single_rays_find() {
    use crate::cpu::Simd;
    let mesh = torus_knot(2, 3, 0.3, 256, 16);
    for layout in [Layout::Wide4, Layout::Wide8] {
        let built = AnyBvh::build(&mesh, &BuildParams { layout, ..BuildParams::default() });
        for simd in Simd::ALL.into_iter().filter(|&s| s <= Simd::detected()) {
            let bvh = match &built {
                AnyBvh::Wide(w) => AnyBvh::Wide(w.clone().with_simd(simd)),
                AnyBvh::Wide8(w) => AnyBvh::Wide8(w.clone().with_simd(simd)),
                AnyBvh::Binary(_) => unreachable!("a wide layout"),
            };
            let what = format!("{layout:?} {simd:?}");
            assert!(agree(&bvh, &primary_blocks(&mesh, 64), PACKET, &what) > 200, "{what}");
            for size in [1, 3, 5, 17, 33, 63] {
                agree(&bvh, &primary_blocks(&mesh, 40), size, &what);
            }
            assert!(agree(&bvh, &scattered(&mesh, 2048), PACKET, &what) > 0);
            assert!(agree(&bvh, &axis_aligned(&mesh), PACKET, &what) > 0);
        }
    }
}

/// Rays at the edges of what a ray can be: subnormal and negative-zero direction components,
/// NaN, intervals starting at -inf or ending at -inf, origins inside the mesh; in packets of every
/// size, so the padding lanes of the last group repeat such a ray.
#[test]
fn odd_rays_in_packets_of_every_size_agree_with_single_rays() {
    let mesh = builtin_scene();
    let c = mesh.bounds().center();
    let tiny = f32::MIN_POSITIVE / 4.0; // subnormal: its inverse is infinite
    let dirs = [
        Vec3::new(tiny, -tiny, 1.0),
        Vec3::new(-0.0, 0.0, -1.0),
        Vec3::new(tiny, tiny, tiny),
        Vec3::new(0.3, -0.0, 0.7),
        Vec3::new(f32::NAN, 0.0, 1.0),
        Vec3::new(-0.5, 0.25, -0.0),
    ];
    let mut rays = Vec::new();
    for (i, d) in dirs.iter().cycle().take(96).enumerate() {
        let o = c + Vec3::new((i % 5) as f32 * 0.1, (i % 3) as f32 * -0.1, 0.05);
        rays.push(match i % 4 {
            0 => Ray::segment(o, *d, f32::NEG_INFINITY, f32::INFINITY),
            1 => Ray::segment(o, *d, 0.0, f32::NEG_INFINITY),
            _ => Ray::new(o, *d),
        });
    }
    for layout in Layout::ALL {
        let bvh = AnyBvh::build(&mesh, &BuildParams { layout, ..BuildParams::default() });
        for size in [1, 2, 3, 5, 17, 63, 64] {
            let hits = agree(&bvh, &rays, size, &format!("odd rays, {layout:?}, packets of {size}"));
            assert!(hits > 10 && hits < rays.len(), "{layout:?}: some rays hit, some miss ({hits})");
        }
    }
}

#[test]
fn packets_keep_the_rays_intervals() {
    let mesh = builtin_scene();
    // Segments that stop short of the surface, or start beyond it, must miss as single rays do.
    let rays: Vec<Ray> = primary_blocks(&mesh, 32)
        .into_iter()
        .enumerate()
        .map(|(i, r)| match i % 3 {
            0 => Ray::segment(r.origin(), r.dir(), 0.0, 1e-3),
            1 => Ray::segment(r.origin(), r.dir(), 1e6, f32::INFINITY),
            _ => r,
        })
        .collect();
    for layout in Layout::ALL {
        let bvh = AnyBvh::build(&mesh, &BuildParams { layout, ..BuildParams::default() });
        assert!(agree(&bvh, &rays, PACKET, &format!("segments, {layout:?}")) > 0);
    }
}

#[test]
fn an_empty_bvh_misses_every_ray() {
    let empty = Mesh::from_triangles("empty", vec![], vec![]);
    for layout in Layout::ALL {
        let bvh = AnyBvh::build(&empty, &BuildParams { layout, ..BuildParams::default() });
        let mut rays = [Ray::new(Vec3::ZERO, Vec3::X); PACKET];
        let mut hits = [Some(Hit { t: 1.0, u: 0.0, v: 0.0, prim: 0 }); PACKET];
        bvh.closest_hits(&mut rays, &mut hits, TraceOptions::default());
        assert_eq!(hits, [None; PACKET]);
        bvh.closest_hits(&mut [], &mut [], TraceOptions::default());
    }
}

#[test]
fn positions_cover_the_block_once_in_two_by_two_groups() {
    let mut seen = [[false; 8]; 8];
    for k in 0..PACKET as u32 {
        let (x, y) = packet_position(k);
        assert!(!seen[y as usize][x as usize], "({x}, {y}) twice");
        seen[y as usize][x as usize] = true;
        let (x0, y0) = packet_position(k & !3);
        assert_eq!((x / 2, y / 2), (x0 / 2, y0 / 2), "ray {k} is in its group's 2×2 block");
    }
}

/// The frustum test may only reject a box that every ray of the packet misses: checked on
/// random packets (a common origin or scattered origins, narrow or wide cones) against random
/// boxes, with the single-ray slab test as the judge.
#[test]
fn the_frustum_rejects_only_boxes_every_ray_misses() {
    let mut rnd = uniform(0x9E37_79B9_7F4A_7C15);
    let (mut rejected, mut valid) = (0, 0);
    for case in 0..4000 {
        let spread = [0.01, 0.1, 0.5][case % 3];
        let centre = Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5).normalize_or(Vec3::Z);
        let eye = Vec3::new(rnd(), rnd(), rnd()) * 4.0 - 2.0;
        let rays: Vec<Ray> = (0..1 + case % PACKET)
            .map(|_| {
                let o = if case % 2 == 0 { eye } else { eye + Vec3::new(rnd(), rnd(), rnd()) * spread };
                let d = centre + (Vec3::new(rnd(), rnd(), rnd()) - 0.5) * spread;
                let mut r = Ray::new(o, d);
                r.t_max = if case % 5 == 0 { rnd() * 4.0 } else { f32::INFINITY };
                r
            })
            .collect();
        let mut traced = rays.clone();
        let mut slot = MaybeUninit::uninit();
        let frustum =
            &Packet::<crate::geometry::Watertight, Four, GROUPS>::new_in(&mut slot, Four, &mut traced).frustum;
        valid += frustum.is_valid() as usize;
        let t_far = rays.iter().fold(f32::NEG_INFINITY, |m, r| m.max(r.t_max));
        for _ in 0..2 {
            // Four boxes, as a wide node holds them: the four-box test must agree with `misses`.
            let boxes: [Aabb; 4] = std::array::from_fn(|_| {
                let c = Vec3::new(rnd(), rnd(), rnd()) * 6.0 - 3.0;
                let h = Vec3::new(rnd(), rnd(), rnd()) * 0.5;
                Aabb::new(c - h, c + h)
            });
            let mut four = crate::geometry::slab::Boxes4::EMPTY;
            for (k, b) in boxes.iter().enumerate() {
                let (lo, hi) = b.planes();
                four.set(k, lo, hi);
            }
            let may_hit = frustum.may_hit4(&four, t_far);
            for (k, b) in boxes.iter().enumerate() {
                assert_eq!(may_hit >> k & 1 == 0, frustum.misses(b, t_far), "case {case}: box {k}, two forms");
                if frustum.misses(b, t_far) {
                    rejected += 1;
                    for r in &rays {
                        assert!(b.intersect(r).is_none(), "case {case}: a rejected box is hit by {r:?}");
                    }
                }
            }
        }
    }
    assert!(valid > 2000 && rejected > 1000, "the test exercised the frustum: {valid} valid, {rejected} rejected");
}
