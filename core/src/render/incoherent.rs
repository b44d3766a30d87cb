//! Incoherent rays: the second ray set of every throughput figure (benches/versus, gpu_bench,
//! `compare --device gpu`) and of the GPU tests, so that all of them trace the same rays. Unlike
//! a camera's rays, neighbours share nothing: each leaves a random point of a random triangle in
//! a random direction, which is what secondary rays of a path tracer look like to a BVH.

use crate::geometry::Ray;
use crate::mesh::Mesh;
use crate::random::Rng;
use glam::Vec3;

/// `count` rays from uniformly chosen points on uniformly chosen triangles of `mesh`, in uniformly
/// random directions, from seed `seed`. Each starts a hair off the surface (the same offset for
/// every ray), so it needs no t_min to leave its own triangle. None for a mesh without triangles.
pub fn incoherent_rays(mesh: &Mesh, count: usize, seed: u64) -> Vec<Ray> {
    let triangles = mesh.triangle_count() as u64;
    if triangles == 0 {
        return Vec::new();
    }
    let mut rng = Rng::new(seed);
    let eps = mesh.bounds().extent().length() * 1e-4;
    (0..count)
        .map(|_| {
            // A modulo, not `Rng::below`: the rays of the runs published in BENCHMARKS.md.
            let tri = mesh.triangle((rng.next_u64() % triangles) as u32);
            let (mut u, mut v) = (rng.unit(), rng.unit());
            if u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
            let p = tri[0] * (1.0 - u - v) + tri[1] * u + tri[2] * v;
            // Uniform on the sphere: z uniform in [-1, 1], the angle around it uniform.
            let z = 2.0 * rng.unit() - 1.0;
            let phi = rng.unit() * std::f32::consts::TAU;
            let s = (1.0 - z * z).max(0.0).sqrt();
            let dir = Vec3::new(s * phi.cos(), s * phi.sin(), z);
            Ray::new(p + dir * eps, dir)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate;

    #[test]
    fn rays_leave_the_surface_in_unit_directions_and_repeat() {
        let mesh = generate::torus_knot(2, 3, 0.2, 64, 8);
        let rays = incoherent_rays(&mesh, 500, 9);
        assert_eq!(rays.len(), 500);
        assert!(rays.iter().all(|r| (r.dir().length() - 1.0).abs() < 1e-5));
        let again = incoherent_rays(&mesh, 500, 9);
        assert!(rays.iter().zip(&again).all(|(a, b)| a.origin() == b.origin() && a.dir() == b.dir()));
        assert!(incoherent_rays(&Mesh::default(), 5, 9).is_empty());
    }
}
