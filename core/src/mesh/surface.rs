//! What a hit looks like to the renderer: the shading normal where a ray met triangle `prim`. A
//! mesh answers for its own triangles; a scene's BVH (`bvh::SceneBvh`) for the global triangle
//! ids of its placed meshes, through each placement's transform, so two levels shade without a
//! flattened copy of the scene.

use crate::geometry::{Ray, TriangleHit};
use crate::mesh::mesh::Mesh;
use glam::Vec3;

pub trait Surface: Sync {
    /// The world-space shading normal of `ray`'s hit `hit` on triangle `prim`.
    fn shading_normal(&self, ray: &Ray, prim: u32, hit: TriangleHit) -> Vec3;
}

impl Surface for Mesh {
    #[inline]
    fn shading_normal(&self, ray: &Ray, prim: u32, hit: TriangleHit) -> Vec3 {
        self.fill_intersection(ray, prim, hit).shading_normal
    }
}
