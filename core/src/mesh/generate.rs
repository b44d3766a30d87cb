//! Meshes made by code: the app's built-in scene and the small assets in `assets/`.

use crate::mesh::mesh::{Mesh, MeshGroup};
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

/// A floor disk and a ring of stands 240 units across: the huge sparse half of "teapot in a stadium".
pub fn stadium() -> Mesh {
    // Used by the benchmark and by scenes/teapot-in-stadium.json (as assets/stadium.obj).
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

/// Adds a quad `a b c d` (counter-clockwise seen from the side it faces) as two triangles.
fn push_quad(m: &mut Mesh, [a, b, c, d]: [Vec3; 4]) {
    let i = m.positions.len() as u32;
    m.positions.extend([a, b, c, d]);
    m.triangles.push([i, i + 1, i + 2]);
    m.triangles.push([i, i + 2, i + 3]);
}

/// Closes the group of the triangles added since the last group.
fn end_group(m: &mut Mesh, name: &str) {
    let start = m.groups.last().map_or(0, |g| g.triangles.end);
    m.groups.push(MeshGroup { name: name.to_string(), triangles: start..m.triangles.len() as u32 });
}

/// A closed box standing on the floor (y = 0): `size` wide, high and deep, turned `degrees` about
/// its vertical axis, centred on (`x`, `z`). Faces point outwards.
fn push_block(m: &mut Mesh, x: f32, z: f32, size: Vec3, degrees: f32) {
    let rot = glam::Quat::from_rotation_y(degrees.to_radians());
    let h = size * 0.5;
    // Corner i takes its x side from bit 0, y from bit 1, z from bit 2.
    let sign = |i: usize, bit: usize| if i & bit == 0 { -1.0 } else { 1.0 };
    let c =
        |i: usize| rot * Vec3::new(sign(i, 1) * h.x, 0.0, sign(i, 4) * h.z) + Vec3::new(x, (sign(i, 2) + 1.0) * h.y, z);
    // Each face counter-clockwise seen from outside: -x, +x, -y, +y, -z, +z.
    for f in [[0, 4, 6, 2], [1, 3, 7, 5], [0, 1, 5, 4], [2, 6, 7, 3], [0, 2, 3, 1], [4, 5, 7, 6]] {
        push_quad(m, f.map(c));
    }
}

/// The classic Cornell box room with its two turned blocks: flat walls give flat node boxes.
pub fn cornell_box() -> Mesh {
    // 5.5 units on a side, open towards +z: x from -2.75 (left wall) to 2.75 (right wall), y from 0
    // (floor) to 5.5, z from -2.75 (back wall) to 2.75. Walls face into the room; each part is a
    // group.
    let mut m = Mesh { name: "cornell box".into(), ..Default::default() };
    let (s, top) = (2.75f32, 5.5f32);
    let p = Vec3::new;
    push_quad(&mut m, [p(-s, 0.0, -s), p(-s, 0.0, s), p(s, 0.0, s), p(s, 0.0, -s)]);
    end_group(&mut m, "floor");
    push_quad(&mut m, [p(-s, top, -s), p(s, top, -s), p(s, top, s), p(-s, top, s)]);
    end_group(&mut m, "ceiling");
    push_quad(&mut m, [p(-s, 0.0, -s), p(s, 0.0, -s), p(s, top, -s), p(-s, top, -s)]);
    end_group(&mut m, "back_wall");
    push_quad(&mut m, [p(-s, 0.0, -s), p(-s, top, -s), p(-s, top, s), p(-s, 0.0, s)]);
    end_group(&mut m, "left_wall");
    push_quad(&mut m, [p(s, 0.0, -s), p(s, 0.0, s), p(s, top, s), p(s, top, -s)]);
    end_group(&mut m, "right_wall");
    // Placed and turned as the blocks of the original (front right and back left, about ±17°).
    push_block(&mut m, 0.93, 1.06, Vec3::new(1.65, 1.65, 1.65), -17.0);
    end_group(&mut m, "short_block");
    push_block(&mut m, -0.9, -0.76, Vec3::new(1.65, 3.3, 1.65), 17.0);
    end_group(&mut m, "tall_block");
    m
}

/// Long thin rods along the (1, 1, 1) diagonal, all sliver triangles: the case where axis-aligned BVHs struggle.
pub fn diagonal_rods(rings: u32, sides: u32, length: f32, radius: f32, spacing: f32) -> Mesh {
    // Rods on a hexagonal lattice (`rings` rings around the middle one, `spacing` apart), each a
    // closed `sides`-gon prism of `radius`, centred on the origin. Every side triangle spans its
    // rod's full `length`, so its axis-aligned box is nearly the whole scene's and all boxes overlap.
    let sides = sides.max(3);
    let mut m = Mesh { name: "diagonal rods".into(), ..Default::default() };
    let axis = Vec3::ONE.normalize();
    let u = Vec3::new(1.0, -1.0, 0.0).normalize();
    let v = axis.cross(u);
    let r = rings as i32;
    for q in -r..=r {
        for s in (-r).max(-q - r)..=r.min(-q + r) {
            let centre = (u * (q as f32 + s as f32 * 0.5) + v * (s as f32 * 0.75f32.sqrt())) * spacing;
            // Rods are staggered a little along the axis so their ends do not line up.
            let shift = ((q * 7 + s * 13).rem_euclid(5) - 2) as f32 * 0.02 * length;
            let ends = [-0.5, 0.5].map(|e| centre + axis * (e * length + shift));
            let base = m.positions.len() as u32;
            for end in ends {
                for j in 0..sides {
                    let phi = j as f32 / sides as f32 * TAU;
                    m.positions.push(end + (u * phi.cos() + v * phi.sin()) * radius);
                }
            }
            let (lo, hi) = (base, base + sides);
            for j in 0..sides {
                let j1 = (j + 1) % sides;
                m.triangles.push([lo + j, lo + j1, hi + j1]);
                m.triangles.push([lo + j, hi + j1, hi + j]);
            }
            for j in 1..sides - 1 {
                m.triangles.push([lo, lo + j + 1, lo + j]);
                m.triangles.push([hi, hi + j, hi + j + 1]);
            }
        }
    }
    end_group(&mut m, "diagonal_rods");
    m
}

/// `count` long thin triangles crossing the box -1..1 diagonally, from seed `seed`: each a
/// sliver about 0.01 wide and 1 to 2.5 long (the box's diagonal is 3.5) centred at a random point
/// and running near the (1, 1, 1) direction, so that they cross one another and every box of a
/// BVH overlaps many others: the messy case for end-point overlap and for tracing.
pub fn needles(count: u32, seed: u64) -> Mesh {
    let mut rng = crate::random::Rng::new(seed);
    let mut positions = Vec::with_capacity(3 * count as usize);
    for _ in 0..count {
        let mut v = |s: f32| Vec3::new(rng.range(-s, s), rng.range(-s, s), rng.range(-s, s));
        let (centre, dir, side) = (v(1.0), (Vec3::ONE + v(0.3)).normalize(), v(1.0));
        let across = dir.cross(side).normalize_or(Vec3::X);
        let (length, along) = (rng.range(1.0, 2.5), rng.range(-0.5, 0.5));
        let width = rng.range(0.002, 0.01);
        positions.push(centre - dir * length * 0.5);
        positions.push(centre + dir * length * 0.5);
        positions.push(centre + dir * length * along + across * width);
    }
    let triangles = (0..count).map(|i| [3 * i, 3 * i + 1, 3 * i + 2]).collect();
    Mesh::from_triangles("needles", positions, triangles)
}

/// `copies` of `one` side by side on a square grid in the xz plane, 1.2 of its size apart: a big
/// mesh made of a real scan (58 bunnies are 4,028,158 triangles), for measuring builds and
/// analyses at the scale of issue 37's table.
pub fn grid_of(one: &Mesh, copies: u32) -> Mesh {
    let b = one.bounds();
    let size = Vec3::from(b.max) - Vec3::from(b.min);
    let side = (copies as f32).sqrt().ceil() as u32;
    let (mut positions, mut triangles) = (Vec::new(), Vec::new());
    for k in 0..copies {
        let shift = Vec3::new((k % side) as f32 * size.x * 1.2, 0.0, (k / side) as f32 * size.z * 1.2);
        let base = positions.len() as u32;
        positions.extend(one.positions.iter().map(|&p| p + shift));
        triangles.extend(one.triangles.iter().map(|t| t.map(|v| v + base)));
    }
    Mesh::from_triangles("grid", positions, triangles)
}

/// A square floor of two triangles in the y = 0 plane, `size` on a side, facing up: the two huge
/// triangles of `scenes/knot-on-floor.json`.
pub fn floor(size: f32) -> Mesh {
    let mut m = Mesh { name: "floor".into(), ..Default::default() };
    let h = size * 0.5;
    push_quad(&mut m, [Vec3::new(-h, 0.0, -h), Vec3::new(-h, 0.0, h), Vec3::new(h, 0.0, h), Vec3::new(h, 0.0, -h)]);
    end_group(&mut m, "floor");
    m
}

/// The meshes in `assets/` (file name, mesh) for the scenes; `cargo run --example make_assets` writes them.
pub fn assets() -> Vec<(&'static str, Mesh)> {
    let mut knot = torus_knot(2, 3, 0.3, 128, 16);
    knot.name = "knot".into();
    vec![
        ("torus.obj", torus(1.0, 0.35, 48, 24)),
        ("cornell-box.obj", cornell_box()),
        ("stadium.obj", stadium()),
        ("diagonal-rods.obj", diagonal_rods(8, 6, 10.0, 0.03, 0.2)),
        ("floor.obj", floor(40.0)),
        ("knot.obj", knot),
    ]
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

    /// Closed and consistently wound, matching corners by position (the generators do not share
    /// vertices between faces): every directed edge a→b is met once, and b→a once.
    fn is_closed(m: &Mesh, triangles: &[[u32; 3]]) -> bool {
        let key = |v: u32| m.positions[v as usize].to_array().map(f32::to_bits);
        let mut edges = std::collections::HashMap::new();
        for t in triangles {
            for k in 0..3 {
                *edges.entry((key(t[k]), key(t[(k + 1) % 3]))).or_insert(0) += 1;
            }
        }
        edges.iter().all(|(&(a, b), &n)| n == 1 && edges.get(&(b, a)) == Some(&1))
    }

    /// The volume enclosed by closed triangles (positive when they face outwards).
    fn signed_volume(m: &Mesh, triangles: &[[u32; 3]]) -> f64 {
        let p = |v: u32| m.positions[v as usize].as_dvec3();
        triangles.iter().map(|t| p(t[0]).dot(p(t[1]).cross(p(t[2]))) / 6.0).sum()
    }

    fn group<'m>(m: &'m Mesh, name: &str) -> &'m [[u32; 3]] {
        let g = m.groups.iter().find(|g| g.name == name).unwrap_or_else(|| panic!("no group {name}"));
        &m.triangles[g.triangles.start as usize..g.triangles.end as usize]
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
        assert!((Vec3::from(b.min) - Vec3::new(-120.0, 0.0, -120.0)).abs().max_element() < 0.1, "{b:?}");
        assert!((Vec3::from(b.max) - Vec3::new(120.0, 30.0, 120.0)).abs().max_element() < 0.1, "{b:?}");
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
    fn cornell_box_has_its_walls_and_two_closed_blocks() {
        let m = cornell_box();
        let names: Vec<&str> = m.groups.iter().map(|g| g.name.as_str()).collect();
        assert_eq!(names, ["floor", "ceiling", "back_wall", "left_wall", "right_wall", "short_block", "tall_block"]);
        assert_eq!(m.triangle_count(), 5 * 2 + 2 * 12);
        assert_eq!(m.groups.last().unwrap().triangles.end as usize, m.triangle_count());
        assert_no_degenerate(&m);
        let b = m.bounds();
        assert_eq!((Vec3::from(b.min), Vec3::from(b.max)), (Vec3::new(-2.75, 0.0, -2.75), Vec3::new(2.75, 5.5, 2.75)));
        // Walls face into the room.
        let middle = Vec3::new(0.0, 2.75, 0.0);
        for wall in ["floor", "ceiling", "back_wall", "left_wall", "right_wall"] {
            for t in group(&m, wall) {
                let n = normal(&m, t);
                let p = m.positions[t[0] as usize];
                assert!(n.dot(middle - p) > 0.0, "{wall} faces away from the room");
                assert!(n.abs().max_element() > 0.9999, "{wall} is axis-aligned");
            }
        }
        for (block, height) in [("short_block", 1.65), ("tall_block", 3.3)] {
            let tris = group(&m, block);
            assert!(is_closed(&m, tris), "{block} is closed");
            let expect = 1.65 * 1.65 * height;
            assert!((signed_volume(&m, tris) - expect).abs() < 1e-4 * expect, "{block} faces outwards");
            let top = tris.iter().flatten().map(|&v| m.positions[v as usize].y).fold(0.0, f32::max);
            assert!((top - height as f32).abs() < 1e-5, "{block} is {top} high");
            // Turned: no face is axis-aligned except top and bottom.
            assert!(tris.iter().map(|t| normal(&m, t)).all(|n| n.y.abs() > 0.999 || n.x.abs() > 0.1));
        }
    }

    #[test]
    fn diagonal_rods_are_closed_slivers_along_the_diagonal() {
        let (rings, sides, length, radius) = (2, 5, 10.0, 0.05);
        let m = diagonal_rods(rings, sides, length, radius, 0.3);
        let rods = 1 + 3 * rings * (rings + 1);
        let per_rod = 2 * sides + 2 * (sides - 2);
        assert_eq!(m.triangle_count() as u32, rods * per_rod);
        assert_eq!(m.positions.len() as u32, rods * 2 * sides);
        assert_no_degenerate(&m);
        // Each rod is a closed prism with outward faces.
        let prism = 0.5 * sides as f64 * (radius as f64).powi(2) * (TAU as f64 / sides as f64).sin() * length as f64;
        for rod in m.triangles.chunks(per_rod as usize) {
            assert!(is_closed(&m, rod));
            assert!((signed_volume(&m, rod) - prism).abs() < 1e-3 * prism);
        }
        // Side triangles span the rod's full length: their boxes are long on every axis.
        let along = length / 3f32.sqrt();
        for rod in m.triangles.chunks(per_rod as usize) {
            for t in &rod[..2 * sides as usize] {
                let tri = t.map(|v| m.positions[v as usize]);
                let extent = crate::geometry::Aabb::EMPTY.grow(tri[0]).grow(tri[1]).grow(tri[2]).extent();
                assert!(extent.min_element() > 0.95 * along, "{extent}");
            }
        }
        // Centred on the origin, laid along (1, 1, 1).
        let b = m.bounds();
        assert!((b.min + b.max).abs().max_element() < 0.2 * along, "{b:?}");
        assert!(b.extent().min_element() > along);
    }

    #[test]
    fn assets_are_named_and_sound() {
        let assets = assets();
        let names: Vec<&str> = assets.iter().map(|(n, _)| *n).collect();
        assert_eq!(
            names,
            ["torus.obj", "cornell-box.obj", "stadium.obj", "diagonal-rods.obj", "floor.obj", "knot.obj"]
        );
        for (name, m) in &assets {
            assert!(m.triangle_count() > 0, "{name}");
            assert_no_degenerate(m);
        }
        let torus = &assets[0].1;
        assert_eq!(torus.normals.len(), torus.positions.len(), "the torus has normals");
        let floor = &assets[4].1;
        assert_eq!(floor.triangle_count(), 2, "the floor is two huge triangles");
        for t in 0..2 {
            let [a, b, c] = floor.triangle(t);
            assert!((b - a).cross(c - a).y > 0.0, "facing up");
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
