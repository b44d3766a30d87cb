//! The two ray sets: a primary pinhole frame, and incoherent rays leaving the surface.

use bvhscope::bvh::packet::packet_position;
use bvhscope::mesh::Mesh;
use bvhscope::render::Camera;
use glam::Vec3;

/// A ray every contender traces the same way: origin, unit direction, interval [0, inf).
#[derive(Clone, Copy, Debug)]
pub struct RaySpec {
    pub origin: Vec3,
    pub dir: Vec3,
}

/// One ray per pixel of a `size`×`size` frame (`size` a multiple of 8) that frames the mesh from a
/// fixed oblique direction. The rays come in 8×8 pixel tiles (tile rows top to bottom, tiles left
/// to right), each tile's 64 pixels in the order of `bvhscope::bvh::packet::packet_position`
/// (Z-order): every contender traces this same order, and our packet tracer takes each tile's 64
/// rays as one packet.
pub fn primary(mesh: &Mesh, size: u32) -> Vec<RaySpec> {
    let cam = Camera::framing_from(&mesh.bounds(), size, size, Vec3::new(0.45, 0.35, 1.0), 45.0);
    let g = cam.ray_gen();
    (0..size * size)
        .map(|i| {
            let (tile, k) = (i / 64, i % 64);
            let (tx, ty) = (tile % (size / 8), tile / (size / 8));
            let (x, y) = packet_position(k);
            let r = g.pixel_ray(8 * tx + x, 8 * ty + y);
            RaySpec { origin: r.origin(), dir: r.dir() }
        })
        .collect()
}

/// SplitMix64: a tiny, fixed-seed generator so every run traces the same rays.
struct SplitMix(u64);

impl SplitMix {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn unit(&mut self) -> f32 {
        (self.next() >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// `count` rays from uniformly chosen points on uniformly chosen triangles, in uniformly random
/// directions, starting a hair off the surface (the same offset for everyone, no t_min needed).
pub fn incoherent(mesh: &Mesh, count: usize, seed: u64) -> Vec<RaySpec> {
    let mut rng = SplitMix(seed);
    let eps = mesh.bounds().extent().length() * 1e-4;
    (0..count)
        .map(|_| {
            let tri = mesh.triangle((rng.next() % mesh.triangle_count() as u64) as u32);
            let (mut u, mut v) = (rng.unit(), rng.unit());
            if u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
            let p = tri[0] * (1.0 - u - v) + tri[1] * u + tri[2] * v;
            let z = 2.0 * rng.unit() - 1.0;
            let phi = rng.unit() * std::f32::consts::TAU;
            let s = (1.0 - z * z).max(0.0).sqrt();
            let dir = Vec3::new(s * phi.cos(), s * phi.sin(), z);
            RaySpec { origin: p + dir * eps, dir }
        })
        .collect()
}
