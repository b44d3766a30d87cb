//! Meshes made by code: the app's built-in scene and the small assets in `assets/`.

use super::{Mesh, MeshGroup};
use glam::{Vec2, Vec3};
use std::f32::consts::TAU;

/// A tube of `radius` around a closed curve sampled at `segments` points, `sides` vertices around.
/// Normals are analytic (radial from the curve), uvs run along and around the tube.
fn tube(name: &str, curve: impl Fn(f32) -> Vec3, radius: f32, segments: u32, sides: u32) -> Mesh {
    let (segments, sides) = (segments.max(3), sides.max(3));
    let mut m = Mesh { name: name.to_string(), ..Default::default() };
    let h = 1e-3;
    for i in 0..segments {
        let t = i as f32 / segments as f32;
        let p = curve(t);
        let tangent = (curve(t + h) - curve(t - h)).normalize();
        // Frenet normal from the second difference; torus knots never straighten, so it is defined.
        let bend = curve(t + h) + curve(t - h) - 2.0 * p;
        let normal = (bend - tangent * bend.dot(tangent)).normalize();
        let binormal = tangent.cross(normal);
        for j in 0..sides {
            let phi = j as f32 / sides as f32 * TAU;
            let n = normal * phi.cos() + binormal * phi.sin();
            m.positions.push(p + n * radius);
            m.normals.push(n);
            m.uvs.push(Vec2::new(t, j as f32 / sides as f32));
        }
    }
    for i in 0..segments {
        let i1 = (i + 1) % segments;
        for j in 0..sides {
            let j1 = (j + 1) % sides;
            let (a, b, c, d) = (i * sides + j, i1 * sides + j, i1 * sides + j1, i * sides + j1);
            m.triangles.push([a, b, c]);
            m.triangles.push([a, c, d]);
        }
    }
    let n = m.triangles.len() as u32;
    m.groups.push(MeshGroup { name: name.to_string(), triangles: 0..n });
    m
}

/// A torus around the y axis: ring radius `major`, tube radius `minor`.
pub fn torus(major: f32, minor: f32, segments: u32, sides: u32) -> Mesh {
    tube("torus", |t| Vec3::new((t * TAU).cos() * major, 0.0, -(t * TAU).sin() * major), minor, segments, sides)
}

/// A (p, q) torus knot tube in the xy plane (p = 2, q = 3 is the trefoil).
pub fn torus_knot(p: u32, q: u32, tube_radius: f32, segments: u32, sides: u32) -> Mesh {
    let (p, q) = (p as f32, q as f32);
    tube(
        "torus knot",
        |t| {
            let a = t * TAU;
            let r = (q * a).cos() + 2.0;
            Vec3::new(r * (p * a).cos(), r * (p * a).sin(), -(q * a).sin()) * 0.5
        },
        tube_radius,
        segments,
        sides,
    )
}

/// The scene the app opens with when no file is given: a trefoil knot, ~25k triangles.
pub fn builtin_scene() -> Mesh {
    let mut m = torus_knot(2, 3, 0.22, 512, 24);
    m.name = "built-in trefoil knot".to_string();
    m
}

/// A stadium: an open ring of large wall quads around a wide floor disk, 200 units across — the
/// huge, sparse half of "teapot in a stadium" (the benchmark and `scenes/teapot-in-stadium.json`).
pub fn stadium() -> Mesh {
    let mut m = Mesh { name: "stadium".into(), ..Default::default() };
    let (r, h, n) = (100.0f32, 30.0f32, 128u32);
    m.positions.push(Vec3::ZERO);
    for i in 0..n {
        let a = i as f32 / n as f32 * TAU;
        let (x, z) = (a.cos() * r, a.sin() * r);
        m.positions.push(Vec3::new(x, 0.0, z));
        m.positions.push(Vec3::new(x * 1.2, h, z * 1.2));
    }
    for i in 0..n {
        let j = (i + 1) % n;
        let (b0, t0, b1, t1) = (1 + 2 * i, 2 + 2 * i, 1 + 2 * j, 2 + 2 * j);
        m.triangles.push([0, b1, b0]); // floor
        m.triangles.push([b0, b1, t1]); // stands
        m.triangles.push([b0, t1, t0]);
    }
    let t = m.triangles.len() as u32;
    m.groups.push(MeshGroup { name: "stadium".into(), triangles: 0..t });
    m
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::triangle_double_area;

    #[test]
    fn torus_is_closed_and_has_outward_normals() {
        let m = torus(2.0, 0.5, 32, 12);
        assert_eq!(m.triangles.len(), 2 * 32 * 12);
        // Every edge is shared by exactly two triangles: a closed surface.
        let mut edges = std::collections::HashMap::new();
        for t in &m.triangles {
            for k in 0..3 {
                let (a, b) = (t[k].min(t[(k + 1) % 3]), t[k].max(t[(k + 1) % 3]));
                *edges.entry((a, b)).or_insert(0) += 1;
            }
        }
        assert!(edges.values().all(|&c| c == 2));
        for (p, n) in m.positions.iter().zip(&m.normals) {
            let ring = Vec3::new(p.x, 0.0, p.z).normalize() * 2.0;
            assert!((*p - ring).normalize().dot(*n) > 0.999, "normal points away from the ring");
        }
    }

    /// Every triangle has a positive area and finite corners.
    fn assert_no_degenerate(m: &Mesh) {
        for (i, t) in m.triangles.iter().enumerate() {
            let tri = t.map(|v| m.positions[v as usize]);
            assert!(tri.iter().all(|p| p.is_finite()), "{}: triangle {i} is not finite", m.name);
            assert!(triangle_double_area(&tri) > 1e-6, "{}: triangle {i} is degenerate: {tri:?}", m.name);
        }
    }

    fn normal(m: &Mesh, t: &[u32; 3]) -> Vec3 {
        let [a, b, c] = t.map(|v| m.positions[v as usize]);
        (b - a).cross(c - a).normalize()
    }

    #[test]
    fn stadium_is_a_floor_and_stands_200_units_across() {
        let m = stadium();
        assert_eq!(m.triangle_count(), 3 * 128);
        assert_no_degenerate(&m);
        let b = m.bounds();
        assert!((b.min - Vec3::new(-120.0, 0.0, -120.0)).abs().max_element() < 0.1, "{b:?}");
        assert!((b.max - Vec3::new(120.0, 30.0, 120.0)).abs().max_element() < 0.1, "{b:?}");
        // The floor faces up, the stands face the middle.
        for (i, t) in m.triangles.iter().enumerate() {
            let n = normal(&m, t);
            let centroid = t.iter().map(|&v| m.positions[v as usize]).sum::<Vec3>() / 3.0;
            if i % 3 == 0 {
                assert!(n.y > 0.999, "floor triangle {i}: {n}");
            } else {
                assert!(n.dot(-Vec3::new(centroid.x, 0.0, centroid.z)) > 0.0, "stand triangle {i}: {n}");
            }
        }
    }

    #[test]
    fn builtin_scene_has_no_degenerate_triangles() {
        let m = builtin_scene();
        assert!(m.triangle_count() > 20_000);
        assert!(m.triangles.iter().all(|t| triangle_double_area(&t.map(|i| m.positions[i as usize])) > 0.0));
        assert!(m.positions.iter().all(|p| p.is_finite()));
    }
}
