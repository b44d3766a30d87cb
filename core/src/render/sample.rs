//! What one primary ray found: the sample a frame keeps per pixel, made from a hit the same way
//! by the renderer, the frame's hit import and the secondary rays (which leave from it).

use crate::bvh::Hit;
use crate::geometry::Ray;
use crate::mesh::Surface;
use glam::Vec3;

/// What one primary ray found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelSample {
    /// Hit distance (the ray direction is unit length, so this is the distance to the camera);
    /// `f32::INFINITY` for a miss.
    pub t: f32,
    /// Shading normal at the hit (world space), zero for a miss.
    pub normal: Vec3,
    /// The mesh's triangle index, `u32::MAX` for a miss.
    pub prim: u32,
}

impl PixelSample {
    pub const MISS: PixelSample = PixelSample { t: f32::INFINITY, normal: Vec3::ZERO, prim: u32::MAX };

    pub fn is_hit(&self) -> bool {
        self.prim != u32::MAX
    }

    /// The sample of `ray`'s `hit` on `surface`: the distance, the shading normal, the triangle.
    pub(crate) fn of(surface: &(impl Surface + ?Sized), ray: &Ray, hit: Option<Hit>) -> PixelSample {
        match hit {
            Some(hit) => {
                let normal = surface.shading_normal(ray, hit.prim, hit.triangle_hit());
                PixelSample { t: hit.t, normal, prim: hit.prim }
            }
            None => PixelSample::MISS,
        }
    }
}
