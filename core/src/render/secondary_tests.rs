//! Secondary rays: the same rays for the same seed, leaving the side the camera sees; any-hit
//! walks of every layout answering as the linear scan does on adversarial rays and segments; a
//! frame of secondary rays whose counters are its rays' sums and whose missed pixels are marked.

use super::*;
use crate::bvh::{AnyBvh, BuildParams, Layout, LinearScan, NoStats, Strategy, TreeNode, TreeView};
use crate::geometry::TriangleTest;
use crate::mesh::{generate, Mesh};
use crate::render::colormap::ColorMap;
use crate::render::raycast::{render, RenderSettings};
use crate::render::views::{view_image, HeatRange, View};

fn knot() -> Mesh {
    generate::torus_knot(2, 3, 0.25, 96, 12)
}

fn camera(mesh: &Mesh) -> Camera {
    Camera::framing(&mesh.bounds(), 48, 36)
}

fn spec(kind: RayKind) -> SecondarySpec {
    SecondarySpec { kind, samples: 3, ..SecondarySpec::default() }
}

#[test]
fn the_same_seed_gives_the_same_rays_and_another_seed_others() {
    let mesh = knot();
    let cam = camera(&mesh);
    let rays = |s: SecondarySpec| {
        let sec = SecondaryRays::new(s, &mesh.bounds(), &cam);
        sec.rays(77, Vec3::new(0.1, 0.2, 0.3), Vec3::Z, Vec3::new(0.0, 0.3, -1.0).normalize()).collect::<Vec<_>>()
    };
    for kind in [RayKind::Shadow, RayKind::Ao, RayKind::Bounce] {
        let a = rays(spec(kind));
        assert_eq!(a.len() as u32, spec(kind).rays_per_hit());
        assert_eq!(a, rays(spec(kind)), "{kind:?}");
        if kind != RayKind::Shadow {
            assert_ne!(a, rays(SecondarySpec { seed: 1, ..spec(kind) }), "{kind:?}");
        }
    }
    assert_eq!(spec(RayKind::Primary).rays_per_hit(), 0);
}

#[test]
fn hemisphere_rays_leave_the_side_the_camera_sees_and_ao_rays_have_their_length() {
    let mesh = knot();
    let cam = camera(&mesh);
    let sec = SecondaryRays::new(spec(RayKind::Ao), &mesh.bounds(), &cam);
    let diagonal = mesh.bounds().extent().length();
    // The camera looks down -z at a surface whose normal was stored pointing away from it.
    let (p, stored, dir) = (Vec3::ZERO, -Vec3::Z, Vec3::new(0.0, 0.0, 1.0));
    for pixel in 0..200 {
        for r in sec.rays(pixel, p, stored, dir) {
            assert!(r.dir().dot(-Vec3::Z) > 0.0, "towards the camera's side");
            assert!((r.dir().length() - 1.0).abs() < 1e-5);
            assert!((r.t_max - 0.1 * diagonal).abs() < 1e-4 * diagonal);
        }
    }
    // Cosine-weighted: the mean cosine is 2/3 (uniform would give 1/2).
    let n = Vec3::new(0.3, -0.5, 0.8).normalize();
    let mut rng = crate::random::Rng::new(5);
    let mean: f32 = (0..20000).map(|_| cosine_direction(n, rng.unit(), rng.unit()).dot(n)).sum::<f32>() / 20000.0;
    assert!((mean - 2.0 / 3.0).abs() < 0.01, "mean cosine {mean}");
}

#[test]
fn a_shadow_ray_ends_at_the_light() {
    let mesh = knot();
    let cam = camera(&mesh);
    let light = Vec3::new(3.0, 4.0, 5.0);
    let sec = SecondaryRays::new(SecondarySpec { light: Some(light), ..spec(RayKind::Shadow) }, &mesh.bounds(), &cam);
    let r: Vec<_> = sec.rays(0, Vec3::ZERO, Vec3::Y, -Vec3::Y).collect();
    assert_eq!(r.len(), 1);
    assert!((r[0].origin() + r[0].dir() * r[0].t_max - light).length() < 1e-4);
}

/// Rays and segments that stress an any-hit walk: from far away at every corner of the tree's
/// boxes, at every vertex and edge midpoint (segments ending exactly there, and a hair short),
/// axis-parallel through vertices, and the secondary rays of a real frame (from the surface).
fn adversarial(mesh: &Mesh, tree: &AnyBvh) -> Vec<Ray> {
    let mut rays = Vec::new();
    let far = mesh.bounds().center() + Vec3::new(3.0, 2.5, 4.0) * mesh.bounds().extent().length();
    tree.visit_nodes(&mut |n: &TreeNode| {
        let b = n.bounds;
        for c in 0..8 {
            let corner = Vec3::new(
                if c & 1 == 0 { b.min.x } else { b.max.x },
                if c & 2 == 0 { b.min.y } else { b.max.y },
                if c & 4 == 0 { b.min.z } else { b.max.z },
            );
            rays.push(Ray::new(far, corner - far));
        }
        rays.len() < 2000
    });
    for t in (0..mesh.triangle_count() as u32).step_by(7) {
        let [a, b, c] = mesh.triangle(t);
        for target in [a, (a + b) * 0.5, (b + c) * 0.5, (a + b + c) / 3.0] {
            let d = target - far;
            rays.push(Ray::segment(far, d, 0.0, 1.0));
            rays.push(Ray::segment(far, d, 0.0, 1.0 - 1e-6));
            rays.push(Ray::new(target + Vec3::X, -Vec3::X));
            rays.push(Ray::new(target + Vec3::Y * 0.5, Vec3::new(0.0, -1.0, -0.0)));
        }
    }
    let cam = camera(mesh);
    for kind in [RayKind::Shadow, RayKind::Ao, RayKind::Bounce] {
        let sec = SecondaryRays::new(spec(kind), &mesh.bounds(), &cam);
        let frame = render(tree, mesh, &cam, &RenderSettings::default());
        let gen = cam.ray_gen();
        for (i, s) in frame.full_samples().unwrap().iter().enumerate().filter(|(_, s)| s.is_hit()).step_by(5) {
            let (x, y) = ((i as u32) % cam.width, (i as u32) / cam.width);
            let primary = gen.pixel_ray(x, y);
            rays.extend(sec.rays(i as u64, primary.origin() + primary.dir() * s.t, s.normal, primary.dir()));
        }
    }
    rays
}

#[test]
fn any_hit_walks_of_every_layout_answer_as_the_linear_scan_does() {
    let mesh = knot();
    let linear = LinearScan::new(&mesh);
    for layout in Layout::ALL {
        for strategy in [Strategy::Midpoint, Strategy::SahBinned, Strategy::Sbvh] {
            let tree = AnyBvh::build(&mesh, &BuildParams { layout, ..BuildParams::with_strategy(strategy) });
            let rays = adversarial(&mesh, &tree);
            assert!(rays.len() > 1000);
            let opts = crate::bvh::TraceOptions { test: TriangleTest::Watertight, ..Default::default() };
            let mut occluded = 0;
            for r in &rays {
                let want = linear.any_hit(r, opts, &mut NoStats);
                assert_eq!(tree.any_hit(r, opts, &mut NoStats), want, "{layout:?} {strategy:?} {r:?}");
                occluded += want as usize;
            }
            assert!(occluded > 100 && occluded < rays.len() - 100, "both answers are tested: {occluded}");
        }
    }
}

/// Packets of any-hit rays (`Accelerator::any_hits`: the packet walk letting each ray go at its
/// first hit) answer as the linear scan does, in packets of every size the walk sees: the
/// adversarial set in its order (mixed directions), and a frame's ao and shadow rays block by
/// block (coherent origins).
#[test]
fn any_hit_packets_of_every_layout_answer_as_the_linear_scan_does() {
    let mesh = knot();
    let linear = LinearScan::new(&mesh);
    let opts = crate::bvh::TraceOptions { test: TriangleTest::Watertight, ..Default::default() };
    for layout in Layout::ALL {
        for strategy in [Strategy::Midpoint, Strategy::SahBinned] {
            let tree = AnyBvh::build(&mesh, &BuildParams { layout, ..BuildParams::with_strategy(strategy) });
            assert!(tree.traces_packets());
            let mut rays = adversarial(&mesh, &tree);
            let cam = camera(&mesh);
            let frame = render(&tree, &mesh, &cam, &RenderSettings::default());
            for kind in [RayKind::Shadow, RayKind::Ao] {
                let sec = SecondaryRays::new(spec(kind), &mesh.bounds(), &cam);
                rays.extend(sec.frame_rays(&frame, &cam, usize::MAX).rays);
            }
            let (mut occluded, mut packets) = (0, 0);
            for size in [64, 37, 1] {
                for chunk in rays.chunks(size) {
                    let mut got = vec![false; chunk.len()];
                    tree.any_hits(chunk, &mut got, opts);
                    packets += 1;
                    for (r, g) in chunk.iter().zip(&got) {
                        let want = linear.any_hit(r, opts, &mut NoStats);
                        assert_eq!(*g, want, "{layout:?} {strategy:?} packet of {size}: {r:?}");
                        occluded += want as usize;
                    }
                }
            }
            assert!(occluded > 300 && occluded < 3 * rays.len() - 300, "both answers: {occluded} in {packets} packets");
        }
    }
}

#[test]
fn a_frame_of_secondary_rays_counts_its_rays_and_marks_missed_pixels() {
    let mesh = knot();
    let cam = camera(&mesh);
    let tree = AnyBvh::build(&mesh, &BuildParams::default());
    let opts = crate::bvh::TraceOptions::default();
    for kind in [RayKind::Shadow, RayKind::Ao, RayKind::Bounce] {
        let sec = SecondaryRays::new(spec(kind), &mesh.bounds(), &cam);
        let settings = RenderSettings { count: true, secondary: Some(sec), ..Default::default() };
        let frame = render(&tree, &mesh, &cam, &settings);
        let primary = render(&tree, &mesh, &cam, &RenderSettings { count: true, ..Default::default() });
        assert_eq!(frame.ray_kind(), (kind, sec.spec.rays_per_hit()));
        let gen = cam.ray_gen();
        let mut hit_pixels = 0;
        for y in 0..cam.height {
            for x in 0..cam.width {
                let s = frame.sample(x, y);
                assert_eq!(s, primary.sample(x, y), "the same primary hits");
                assert_eq!(frame.primary_counters(x, y), primary.counters(x, y), "the primary ray's own counts kept");
                if !s.is_hit() {
                    assert_eq!(frame.value(View::Visits, s, &frame.counters(x, y), Default::default()), None);
                    continue;
                }
                hit_pixels += 1;
                let ray = gen.pixel_ray(x, y);
                let pixel = (y * cam.width + x) as u64;
                let point = ray.origin() + ray.dir() * s.t;
                let (want, _) = sec.trace::<_, RayCounters>(&tree, opts, pixel, point, s.normal, ray.dir());
                assert_eq!(frame.counters(x, y), want, "{kind:?} pixel {x},{y}: the sum of its rays' counts");
            }
        }
        let summary = frame.ray_summary();
        assert_eq!(summary.rays, hit_pixels * sec.spec.rays_per_hit() as u64);
        assert_eq!(summary.hits, hit_pixels);
        // The image marks the pixels whose camera ray missed; the legend says so.
        let (img, legend) = view_image(&frame, View::Visits, ColorMap::Viridis, HeatRange::Auto, Default::default());
        let corner = img.get_pixel(0, 0).0;
        assert!(!frame.sample(0, 0).is_hit());
        assert_eq!(corner, crate::render::NO_RAYS);
        assert!(legend.unwrap().note.contains("camera ray missed"));
        let csv = frame.counts_csv().unwrap();
        assert!(csv.starts_with("x,y,rays,nodes_visited"));
        assert_eq!(csv.lines().count() as u32, 1 + cam.width * cam.height);
    }
}

/// The listing `compare` made before issue 58, kept as the reference its sample must equal: every
/// hit pixel's rays made from one stream per pixel (two numbers per ray, in order) and listed, then
/// ray k·len/n kept for k in 0..n.
fn listed_then_spread(sec: &SecondaryRays, frame: &crate::render::Frame, camera: &Camera, max: usize) -> Vec<Ray> {
    let gen = camera.ray_gen();
    let mut all = Vec::new();
    for y in 0..camera.height {
        for x in 0..camera.width {
            let s = frame.sample(x, y);
            if !s.is_hit() {
                continue;
            }
            let ray = gen.pixel_ray(x, y);
            let (point, dir) = (ray.origin() + ray.dir() * s.t, ray.dir());
            let n = if s.normal.dot(dir) > 0.0 { -s.normal } else { s.normal };
            let n = n.try_normalize().unwrap_or(-dir);
            let origin = point + n * sec.offset;
            let count = sec.spec.rays_per_hit();
            let pixel = y as u64 * camera.width as u64 + x as u64;
            let mut rng = crate::random::Rng::at(sec.spec.seed, pixel.wrapping_mul(2 * count as u64));
            for _ in 0..count {
                all.push(match sec.spec.kind {
                    RayKind::Shadow => {
                        let to = sec.light - origin;
                        let d = to.length();
                        Ray::segment(origin, to / d.max(1e-30), 0.0, d)
                    }
                    _ => {
                        let (u1, u2) = (rng.unit(), rng.unit());
                        let length = if sec.spec.kind == RayKind::Ao { sec.ao_length } else { f32::INFINITY };
                        Ray::segment(origin, cosine_direction(n, u1, u2), 0.0, length)
                    }
                });
            }
        }
    }
    let n = all.len().min(max);
    (0..n).map(|k| all[k * all.len() / n]).collect()
}

/// `compare`'s sample of a frame's secondary rays, made directly, is the sample of the full list
/// it used to make: the same rays, bit for bit, for every kind and any cap (issue 58).
#[test]
fn the_kept_rays_are_those_of_the_listed_frame_evenly_spread() {
    let mesh = knot();
    let cam = camera(&mesh);
    let tree = AnyBvh::build(&mesh, &BuildParams::default());
    let frame = render(&tree, &mesh, &cam, &RenderSettings::default());
    for kind in [RayKind::Shadow, RayKind::Ao, RayKind::Bounce] {
        for samples in [1, 3, 7] {
            let sec = SecondaryRays::new(SecondarySpec { samples, ..spec(kind) }, &mesh.bounds(), &cam);
            let total = listed_then_spread(&sec, &frame, &cam, usize::MAX).len();
            assert!(total > 100, "{kind:?}: {total}");
            for max in [0, 1, 2, 7, 100, total / 3, total - 1, total, total + 5, usize::MAX] {
                let got = sec.frame_rays(&frame, &cam, max);
                assert_eq!(got.of, total as u64, "{kind:?} ×{samples}");
                assert_eq!(got.rays.len(), total.min(max), "{kind:?} ×{samples} max {max}");
                assert!(got.rays == listed_then_spread(&sec, &frame, &cam, max), "{kind:?} ×{samples} max {max}");
            }
        }
    }
}

/// A light 1e20 away: its squared distance passes f32, and each shadow ray had the direction 0
/// (an empty ray, shadowing nothing, issue 58). Its rays are those of a light 1e19 away along the
/// same line (whose distance f32 still holds), and lights at the ends of f32 give unit directions.
#[test]
fn a_far_light_casts_the_shadows_of_a_near_one_in_its_direction() {
    let mesh = knot();
    let cam = camera(&mesh);
    let tree = AnyBvh::build(&mesh, &BuildParams::default());
    let frame = render(&tree, &mesh, &cam, &RenderSettings::default());
    let rays_to = |light: Option<Vec3>| {
        let sec = SecondaryRays::new(SecondarySpec { light, ..spec(RayKind::Shadow) }, &mesh.bounds(), &cam);
        sec.frame_rays(&frame, &cam, usize::MAX).rays
    };
    let rays = |light: Vec3| rays_to(Some(light));
    let opts = crate::bvh::TraceOptions::default();
    for line in [Vec3::ONE, Vec3::new(-1.0, 0.5, -0.25), Vec3::new(0.0, -1.0, 0.0)] {
        let (near, far) = (rays(line * 1e19), rays(line * 1e20));
        assert_eq!(near.len(), far.len());
        let shadowed = |rays: &[Ray]| rays.iter().map(|r| tree.any_hit(r, opts, &mut NoStats)).collect::<Vec<_>>();
        let (a, b) = (shadowed(&near), shadowed(&far));
        assert_eq!(a, b, "{line}: the same pixels in shadow");
        assert!(a.contains(&true) && a.contains(&false), "{line}: both answers are tested");
        for (n, f) in near.iter().zip(&far) {
            assert!(!f.is_empty(), "{line}: {f:?}");
            assert!((n.dir() - f.dir()).length() < 1e-6, "{line}: {n:?} {f:?}");
            assert!((f.t_max / (line.length() * 1e20) - 1.0).abs() < 1e-5, "{line}: up to the light, {f:?}");
        }
    }
    for light in [Vec3::splat(f32::MAX), Vec3::new(-f32::MAX, f32::MAX, 0.0), Vec3::splat(f32::MIN_POSITIVE)] {
        for r in rays(light) {
            assert!(!r.is_empty() && (r.dir().length() - 1.0).abs() < 1e-5, "{light}: {r:?}");
        }
    }
    // A light that is not finite (from the app's saved settings; the command line refuses one):
    // the default light's rays, not empty ones.
    let default = rays_to(None);
    for light in [Vec3::splat(f32::INFINITY), Vec3::new(f32::NAN, 0.0, 1.0)] {
        assert!(rays_to(Some(light)) == default, "{light}");
    }
}
