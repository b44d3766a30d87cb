//! An indexed triangle mesh and the handout's `fillIntersection` step: turning a hit's primitive id
//! and barycentrics into a world-space surface point.

use crate::geometry::{Aabb, Ray, TriangleHit};
use glam::{Vec2, Vec3};
use std::ops::Range;

/// A named part of a mesh (an OBJ `o` or `g`): a contiguous range of triangles.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshGroup {
    pub name: String,
    pub triangles: Range<u32>,
}

/// An indexed triangle mesh. `normals` and `uvs` are either empty or one per position.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    pub name: String,
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    pub uvs: Vec<Vec2>,
    pub triangles: Vec<[u32; 3]>,
    pub groups: Vec<MeshGroup>,
    /// For a mesh read from an OBJ: each triangle's number in the file, counting the faces in
    /// order, fan-triangulated, zero-area ones included (the loader drops those): what a BVH dump's
    /// primitives refer to. Empty otherwise (a triangle's number is its index).
    pub file_numbers: Vec<u32>,
    /// How many triangles the file has, zero-area ones included (0: as many as `triangles`). A
    /// file may end with zero-area faces, so this is not the largest of `file_numbers` plus one.
    pub file_triangles: usize,
}

/// Everything a shading step needs about a hit, in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceInteraction {
    pub t: f32,
    pub position: Vec3,
    /// Unit normal of the triangle's plane (`(v1-v0)×(v2-v0)`, as wound in the file).
    pub geometric_normal: Vec3,
    /// Unit normal interpolated from the file's vertex normals, or the geometric normal.
    pub shading_normal: Vec3,
    pub uv: Vec2,
    pub prim: u32,
}

impl Mesh {
    /// A mesh from positions and triangles only (no normals, no uvs, one group).
    pub fn from_triangles(name: &str, positions: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Self {
        let n = triangles.len() as u32;
        Self {
            name: name.to_string(),
            positions,
            normals: Vec::new(),
            uvs: Vec::new(),
            triangles,
            groups: vec![MeshGroup { name: name.to_string(), triangles: 0..n }],
            file_numbers: Vec::new(),
            file_triangles: 0,
        }
    }

    /// The file's number of triangle `t` (see `file_numbers`).
    pub fn file_number(&self, t: u32) -> u32 {
        self.file_numbers.get(t as usize).copied().unwrap_or(t)
    }

    /// How many triangles the file has (`file_triangles`), zero-area ones included: what a BVH
    /// dump's primitives may number.
    pub fn file_triangle_count(&self) -> usize {
        let last = self.file_numbers.iter().copied().max().map_or(0, |m| m as usize + 1);
        self.file_triangles.max(last).max(if self.file_numbers.is_empty() { self.triangles.len() } else { 0 })
    }

    /// For each file number, the triangle it became, or `None` for a zero-area triangle the loader
    /// dropped; `len` is the file's triangle count (`file_triangle_count`).
    pub fn triangles_by_file_number(&self) -> Vec<Option<u32>> {
        if self.file_numbers.is_empty() {
            let mut out: Vec<Option<u32>> = (0..self.triangles.len() as u32).map(Some).collect();
            out.resize(self.file_triangle_count(), None);
            return out;
        }
        let mut out = vec![None; self.file_triangle_count()];
        for (t, &f) in self.file_numbers.iter().enumerate() {
            out[f as usize] = Some(t as u32);
        }
        out
    }

    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    #[inline]
    pub fn triangle(&self, prim: u32) -> [Vec3; 3] {
        let [a, b, c] = self.triangles[prim as usize];
        [self.positions[a as usize], self.positions[b as usize], self.positions[c as usize]]
    }

    pub fn bounds(&self) -> Aabb {
        self.triangles.iter().flatten().fold(Aabb::EMPTY, |b, &i| b.grow(self.positions[i as usize]))
    }

    /// The handout's `fillIntersection`: position, normals and uv of a hit.
    pub fn fill_intersection(&self, ray: &Ray, prim: u32, hit: TriangleHit) -> SurfaceInteraction {
        let idx = self.triangles[prim as usize];
        let [p0, p1, p2] = self.triangle(prim);
        let w = 1.0 - hit.u - hit.v;
        let geometric_normal = (p1 - p0).cross(p2 - p0).normalize_or_zero();
        let shading_normal = if self.normals.is_empty() {
            geometric_normal
        } else {
            let [n0, n1, n2] = idx.map(|i| self.normals[i as usize]);
            // A zero or cancelling vertex normal falls back to the plane's normal.
            (n0 * w + n1 * hit.u + n2 * hit.v).try_normalize().unwrap_or(geometric_normal)
        };
        let uv = if self.uvs.is_empty() {
            Vec2::new(hit.u, hit.v)
        } else {
            let [t0, t1, t2] = idx.map(|i| self.uvs[i as usize]);
            t0 * w + t1 * hit.u + t2 * hit.v
        };
        let si = SurfaceInteraction {
            t: hit.t,
            // Interpolating the vertices is more accurate than o + t·d far from the origin.
            position: p0 * w + p1 * hit.u + p2 * hit.v,
            geometric_normal,
            shading_normal,
            uv,
            prim,
        };
        debug_assert!(
            (ray.at(si.t) - si.position).length() <= 1e-3 * (1.0 + si.position.length() + si.t * ray.dir().length()),
            "hit point disagrees with the ray"
        );
        si
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad() -> Mesh {
        let mut m = Mesh::from_triangles(
            "quad",
            vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y],
            vec![[0, 1, 2], [0, 2, 3]],
        );
        m.normals = vec![Vec3::Z, Vec3::Z, Vec3::new(0.0, 1.0, 1.0), Vec3::Z];
        m.uvs = vec![Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::Y];
        m
    }

    #[test]
    fn fill_interpolates_position_normal_and_uv() {
        let m = quad();
        let r = Ray::new(Vec3::new(0.75, 0.25, 1.0), -Vec3::Z);
        // (0.75, 0.25) = 0.25·v0 + 0.5·v1 + 0.25·v2 in triangle 0.
        let si = m.fill_intersection(&r, 0, TriangleHit { t: 1.0, u: 0.5, v: 0.25 });
        assert!((si.position - Vec3::new(0.75, 0.25, 0.0)).length() < 1e-6);
        assert_eq!(si.geometric_normal, Vec3::Z);
        let expect_n = (Vec3::Z * 0.75 + Vec3::new(0.0, 1.0, 1.0) * 0.25).normalize();
        assert!((si.shading_normal - expect_n).length() < 1e-6);
        assert!((si.uv - Vec2::new(0.75, 0.25)).length() < 1e-6);
    }

    #[test]
    fn fill_without_normals_uses_geometric_normal() {
        let mut m = quad();
        m.normals.clear();
        let r = Ray::new(Vec3::new(0.25, 0.75, 1.0), -Vec3::Z);
        let si = m.fill_intersection(&r, 1, TriangleHit { t: 1.0, u: 0.25, v: 0.5 });
        assert_eq!(si.shading_normal, Vec3::Z);
        assert_eq!(si.prim, 1);
    }
}
