//! The two ray sets: a primary pinhole frame, and incoherent rays leaving the surface.

use bvhscope::bvh::packet::packet_position;
use bvhscope::mesh::Mesh;
use bvhscope::render::{incoherent_rays, Camera};
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

/// `count` incoherent rays from seed `seed` (core's `incoherent_rays`: the GPU's benchmark and
/// tests trace the same).
pub fn incoherent(mesh: &Mesh, count: usize, seed: u64) -> Vec<RaySpec> {
    incoherent_rays(mesh, count, seed).into_iter().map(|r| RaySpec { origin: r.origin(), dir: r.dir() }).collect()
}
