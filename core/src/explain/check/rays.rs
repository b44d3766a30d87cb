//! The checker's rays group: the tree traced by bvhscope's own traversal against the linear scan,
//! on a camera's primary rays and random rays at the mesh. The rays are made from their number
//! (`RaySet::ray`), never stored: they are traced in batches on every thread, so memory does not
//! grow with their count, and the same rays come out whatever the number of threads.

use super::{defect, Finding, Group};
use crate::bvh::{Accelerator, BuildParams, Bvh, Hit, LinearScan, NoStats, TraceOptions};
use crate::geometry::Ray;
use crate::mesh::Mesh;
use crate::random::Rng;
use crate::render::{Camera, RayGen};
use crate::work::{Cancelled, WorkControl};
use glam::Vec3;
use rayon::prelude::*;
use serde::Serialize;

/// Meshes up to this many triangles are checked against the linear scan itself.
pub const LINEAR_REFERENCE_MAX: usize = 4096;

/// The most random rays a check traces (`check --rays`): a few minutes on a laptop.
pub const MAX_RAYS: u64 = 100_000_000;

/// Rays traced per batch: enough to keep every thread busy, small enough to stop soon when asked.
const BATCH: u64 = 1 << 16;

/// Wrong rays kept as examples (the count goes on).
const EXAMPLES: usize = 16;

const SEED: u64 = 0x9E37_79B9_7F4A_7C15;

/// A camera's primary rays (pixel by pixel, row by row), then (for a check, `checking`) rays
/// aimed at the triangles' corners, edge midpoints and centres, then `random` rays from random
/// points around the mesh (a box three times its size) towards random points in its box.
pub struct RaySet<'a> {
    gen: RayGen,
    width: u32,
    pixels: u64,
    /// The mesh whose triangles the aimed rays go for, and how many there are.
    aimed_at: Option<&'a Mesh>,
    aimed: u64,
    random: u64,
    center: Vec3,
    extent: Vec3,
}

/// Points aimed at per triangle: its three corners, its three edge midpoints, its centre.
const AIMS: u64 = 7;

/// Aimed rays at most: every triangle of a mesh of up to 9,362 triangles, an even spread of them
/// beyond. Where a box misses a triangle it misses it at a corner or along an edge, which random
/// rays hit rarely: a few thousand aimed rays find what a million random ones took 12 s to (the
/// lab's monkey), and the exact bounds and coverage tests find it before either.
pub const MAX_AIMED: u64 = 65_536;

impl<'a> RaySet<'a> {
    /// The camera's primary rays and `random` rays, nothing aimed (the app's wrong pixels).
    pub fn new(mesh: &Mesh, camera: &Camera, random: u64) -> RaySet<'a> {
        let b = mesh.bounds();
        RaySet {
            gen: camera.ray_gen(),
            width: camera.width,
            pixels: camera.width as u64 * camera.height as u64,
            aimed_at: None,
            aimed: 0,
            random,
            center: b.center(),
            extent: b.extent().max(Vec3::splat(1e-6)),
        }
    }

    /// A check's rays: `new`'s, and rays aimed at the triangles (`MAX_AIMED`).
    pub fn checking(mesh: &'a Mesh, camera: &Camera, random: u64) -> RaySet<'a> {
        let aimed = (AIMS * mesh.triangle_count() as u64).min(MAX_AIMED);
        RaySet { aimed_at: Some(mesh), aimed, ..RaySet::new(mesh, camera, random) }
    }

    pub fn len(&self) -> u64 {
        self.pixels + self.aimed + self.random
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Ray `i`, and its pixel when it is a primary ray.
    pub fn ray(&self, i: u64) -> (Ray, Option<(u32, u32)>) {
        if i < self.pixels {
            let (x, y) = ((i % self.width as u64) as u32, (i / self.width as u64) as u32);
            return (self.gen.pixel_ray(x, y), Some((x, y)));
        }
        let j = i - self.pixels;
        if let (Some(mesh), true) = (self.aimed_at, j < self.aimed) {
            // Triangle by triangle (spread evenly when there are more than the cap allows), each
            // point from its own random origin around the mesh.
            let tris = mesh.triangle_count() as u64;
            let per = self.aimed / AIMS;
            let t = if per >= tris { j / AIMS } else { (j / AIMS) * tris / per.max(1) };
            let v = mesh.triangle(t.min(tris - 1) as u32);
            let target = match j % AIMS {
                k @ 0..=2 => v[k as usize],
                k @ 3..=5 => (v[(k - 3) as usize] + v[(k - 2) as usize % 3]) * 0.5,
                _ => (v[0] + v[1] + v[2]) / 3.0,
            };
            let (o, _) = Rng::at(AIM_SEED, 6 * j).ray_at(self.center, self.extent);
            return (Ray::new(o, target - o), None);
        }
        let (o, d) = Rng::at(SEED, 6 * (j - self.aimed)).ray_at(self.center, self.extent);
        (Ray::new(o, d), None)
    }
}

const AIM_SEED: u64 = 0xA11E_D0FF_5EED_0001;

/// Every ray of `check_rays`' set, in order (for tests and small frames).
pub fn check_rays(mesh: &Mesh, camera: &Camera, n: usize) -> Vec<(Ray, Option<(u32, u32)>)> {
    let set = RaySet::new(mesh, camera, n as u64);
    (0..set.len()).map(|i| set.ray(i)).collect()
}

/// Where the checker takes a ray's true hit from: the linear scan's hits. Past a few thousand
/// triangles they are found through bvhscope's own SAH tree instead, which returns the linear
/// scan's hit for every ray (core/tests/bvh_matches_linear.rs and watertight_traversal.rs): a
/// million rays over a million triangles one by one would take days. Made once per mesh (the
/// app keeps it for every view of an imported tree).
pub enum Reference {
    Linear(LinearScan),
    Tree(Box<Bvh>),
}

impl Reference {
    pub fn of(mesh: &Mesh) -> Reference {
        if mesh.triangle_count() > LINEAR_REFERENCE_MAX {
            let params = BuildParams { layout: crate::bvh::Layout::Binary, ..BuildParams::default() };
            Reference::Tree(Box::new(Bvh::build(mesh, &params)))
        } else {
            Reference::Linear(LinearScan::new(mesh))
        }
    }

    fn closest_hit(&self, ray: &Ray, opts: TraceOptions) -> Option<Hit> {
        match self {
            Reference::Linear(l) => l.closest_hit(&mut ray.clone(), opts, &mut NoStats),
            Reference::Tree(t) => t.closest_hit(&mut ray.clone(), opts, &mut NoStats),
        }
    }
}

/// A ray whose hit through the imported tree differs from the linear scan's.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct WrongRay {
    pub origin: [f32; 3],
    pub dir: [f32; 3],
    pub pixel: Option<(u32, u32)>,
    /// Triangles by their number in the file.
    pub want: Option<(u32, f32)>,
    pub got: Option<(u32, f32)>,
}

/// What tracing a `RaySet` found: how many rays hit differently, the first few of them, and every
/// pixel whose ray did (at most the frame's size).
#[derive(Debug, Default)]
pub struct WrongRays {
    pub count: u64,
    pub examples: Vec<WrongRay>,
    pub pixels: Vec<(u32, u32)>,
}

impl WrongRays {
    /// The rays group's finding, if any ray of the `total` hit differently.
    pub fn finding(&self, total: u64) -> Option<Finding> {
        // A pixel's ray for the example when there is one (easier to find in the image).
        let w = self.examples.iter().find(|w| w.pixel.is_some()).or(self.examples.first())?;
        let v = |a: [f32; 3]| format!("{},{},{}", a[0], a[1], a[2]);
        let at = match w.pixel {
            Some((x, y)) => format!("pixel {x},{y} (trace MESH --bvh FILE --pixel {x},{y} shows its walk)"),
            None => format!(
                "the ray {}:{} (trace MESH --bvh FILE --ray {}:{} shows its walk)",
                v(w.origin),
                v(w.dir),
                v(w.origin),
                v(w.dir)
            ),
        };
        let show = |h: Option<(u32, f32)>| h.map_or("nothing".to_string(), |(p, t)| format!("triangle {p} at t = {t}"));
        let text = format!(
            "{} of {} rays hit differently from the linear scan; e.g. {at}: the linear scan hits {}, the imported tree {}",
            self.count,
            total,
            show(w.want),
            show(w.got)
        );
        Some(defect(Group::Rays, None, w.got.or(w.want).map(|h| h.0), text))
    }
}

/// Trace every ray of `set` through `bvh` and the `reference`, in batches on every thread (`control`
/// counts them, and stops the work when cancelled); the ones whose hits differ (a different
/// distance; a different triangle only at a different distance).
pub fn wrong_rays(
    bvh: &impl Accelerator,
    mesh: &Mesh,
    reference: &Reference,
    set: &RaySet<'_>,
    opts: TraceOptions,
    control: &WorkControl,
) -> Result<WrongRays, Cancelled> {
    let key = |h: Option<Hit>| h.map(|h| (mesh.file_number(h.prim), h.t));
    let mut out = WrongRays::default();
    control.set_total(set.len());
    let mut start = 0;
    while start < set.len() {
        control.check()?;
        let end = (start + BATCH).min(set.len());
        let wrong: Vec<WrongRay> = (start..end)
            .into_par_iter()
            .filter_map(|i| {
                // A tree whose boxes all overlap costs every node per ray: a batch of such rays
                // takes minutes, so a cancel is heard between rays, not only between batches.
                if control.is_cancelled() {
                    return None;
                }
                let (r, pixel) = set.ray(i);
                let want = reference.closest_hit(&r, opts);
                let got = bvh.closest_hit(&mut r.clone(), opts, &mut NoStats);
                let same = match (want, got) {
                    (None, None) => true,
                    (Some(w), Some(g)) => w.t == g.t,
                    _ => false,
                };
                (!same).then(|| WrongRay {
                    origin: r.origin().to_array(),
                    dir: r.dir().to_array(),
                    pixel,
                    want: key(want),
                    got: key(got),
                })
            })
            .collect();
        control.check()?;
        out.count += wrong.len() as u64;
        out.pixels.extend(wrong.iter().filter_map(|w| w.pixel));
        let room = EXAMPLES.saturating_sub(out.examples.len());
        out.examples.extend(wrong.into_iter().take(room));
        control.add_done(end - start);
        start = end;
    }
    Ok(out)
}
