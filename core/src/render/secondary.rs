//! The rays after the first hit: shadow rays to a point light, ambient-occlusion rays and diffuse
//! bounces, made from a primary hit the same way everywhere (the renderer's heatmaps, `compare`'s
//! table, the app), so every strategy and every front end sees the same rays for one seed.
//!
//! A renderer spends most of its rays after the first hit, and those rays are incoherent: they are
//! where split strategies differ most (the reason for EPO: Aila, Karras & Laine, "On Quality
//! Metrics of Bounding Volume Hierarchies", HPG 2013). Directions over the hemisphere are
//! cosine-weighted (Malley's method: a uniform point on the unit disc lifted to the hemisphere),
//! around an orthonormal basis built from the normal alone (Duff et al., "Building an Orthonormal
//! Basis, Revisited", JCGT 2017).

use crate::bvh::{Accelerator, RayCounters, TraceOptions, TraversalStats};
use crate::geometry::{Aabb, Ray};
use crate::random::Rng;
use crate::render::camera::Camera;
use glam::Vec3;

/// Which rays a frame's heatmap is of.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum RayKind {
    /// The camera's rays: closest hit.
    #[default]
    Primary,
    /// From each primary hit to the point light: any hit within the distance to it.
    Shadow,
    /// Cosine-weighted hemisphere rays of a fixed length: any hit.
    Ao,
    /// One cosine-weighted diffuse bounce: closest hit.
    Bounce,
}

impl RayKind {
    pub fn is_secondary(self) -> bool {
        self != RayKind::Primary
    }

    /// Whether the kind's rays ask only whether anything is hit (stop at the first hit found).
    pub fn any_hit(self) -> bool {
        matches!(self, RayKind::Shadow | RayKind::Ao)
    }

    /// Trace `ray` as the kind asks (any hit for shadow and ao rays, else the closest), counting
    /// into `stats`: whether it hit. The one place a kind's query is chosen.
    #[inline]
    pub fn trace<A: Accelerator + ?Sized, S: TraversalStats>(
        self,
        accel: &A,
        ray: &Ray,
        opts: TraceOptions,
        stats: &mut S,
    ) -> bool {
        match self.any_hit() {
            true => accel.any_hit(ray, opts, stats),
            false => accel.closest_hit(&mut ray.clone(), opts, stats).is_some(),
        }
    }
}

/// Rays per pixel of ambient occlusion and bounces unless told otherwise.
pub const DEFAULT_SAMPLES: u32 = 4;
/// The most rays per pixel (a 4K frame of them is 2 billion rays).
pub const MAX_SAMPLES: u32 = 256;
/// The length of ambient-occlusion rays unless told otherwise, as a share of the scene's diagonal.
pub const DEFAULT_AO_LENGTH: f32 = 0.1;
/// The seed every front end uses unless told otherwise.
pub const DEFAULT_SEED: u64 = 0x5EC0_4DA7_2026;

/// What secondary rays to trace: the kind and its parameters. `Copy`, so render settings that
/// carry it stay plain values.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct SecondarySpec {
    pub kind: RayKind,
    /// Rays per hit pixel for `Ao` and `Bounce` (a shadow ray is one per light).
    pub samples: u32,
    /// Length of `Ao` rays, as a share of the scene's diagonal.
    pub ao_length: f32,
    /// The point light of `Shadow` rays; `None`: above the camera (`SecondaryRays::new`).
    pub light: Option<Vec3>,
    pub seed: u64,
}

impl Default for SecondarySpec {
    fn default() -> Self {
        Self {
            kind: RayKind::Primary,
            samples: DEFAULT_SAMPLES,
            ao_length: DEFAULT_AO_LENGTH,
            light: None,
            seed: DEFAULT_SEED,
        }
    }
}

impl SecondarySpec {
    /// The same parameters for another kind.
    pub fn of_kind(self, kind: RayKind) -> Self {
        Self { kind, ..self }
    }

    /// Rays traced from each pixel whose primary ray hit: 0 for primary frames.
    pub fn rays_per_hit(&self) -> u32 {
        match self.kind {
            RayKind::Primary => 0,
            RayKind::Shadow => 1,
            RayKind::Ao | RayKind::Bounce => self.samples.max(1),
        }
    }

    /// A line for captions and tables: "ao, 4 rays of 10% of the diagonal per pixel".
    pub fn describe(&self) -> String {
        match self.kind {
            RayKind::Primary => "primary rays".into(),
            RayKind::Shadow => match self.light {
                Some(l) => format!("shadow rays to a light at {:.3},{:.3},{:.3} (any hit)", l.x, l.y, l.z),
                None => "shadow rays to a light above the camera (any hit)".into(),
            },
            RayKind::Ao => format!(
                "ambient-occlusion rays, {} per pixel, {}% of the scene's diagonal long (any hit)",
                self.rays_per_hit(),
                self.ao_length * 100.0
            ),
            RayKind::Bounce => format!("diffuse bounces, {} per pixel (closest hit)", self.rays_per_hit()),
        }
    }
}

/// A `SecondarySpec` resolved for one scene and camera: the light's place, the rays' length and
/// the offset that lifts a ray off the surface it leaves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SecondaryRays {
    pub spec: SecondarySpec,
    pub light: Vec3,
    pub ao_length: f32,
    /// Rays start this far off the surface along its normal (as `incoherent_rays`' rays do), so
    /// none needs a t_min to leave its own triangle.
    pub offset: f32,
}

impl SecondaryRays {
    /// The default light is half the scene's diagonal above the camera (along its up vector). A
    /// light that is not finite (the command line refuses one; the app's saved settings could
    /// hold one) has no direction to it and would shadow nothing: the default light stands in.
    pub fn new(spec: SecondarySpec, bounds: &Aabb, camera: &Camera) -> Self {
        let diagonal = if bounds.is_empty() { 1.0 } else { bounds.extent().length().max(1e-30) };
        let up = camera.up.try_normalize().unwrap_or(Vec3::Y);
        let light = spec.light.filter(|l| l.is_finite()).unwrap_or(camera.position + up * 0.5 * diagonal);
        Self { spec, light, ao_length: spec.ao_length * diagonal, offset: diagonal * 1e-4 }
    }

    /// The secondary rays of pixel `pixel` (its index in the frame, row by row) whose primary ray
    /// `dir` hit at `point` with shading normal `normal`: the same rays for the same pixel, hit and
    /// seed whatever traces them. Empty for primary frames.
    pub fn rays(&self, pixel: u64, point: Vec3, normal: Vec3, dir: Vec3) -> impl Iterator<Item = Ray> + '_ {
        let (n, origin) = self.leave(point, normal, dir);
        (0..self.spec.rays_per_hit()).map(move |j| self.ray(pixel, j, n, origin))
    }

    /// The side of the surface the camera sees at a hit (rays leave from there), and the point
    /// the rays leave from, lifted off the surface on that side.
    fn leave(&self, point: Vec3, normal: Vec3, dir: Vec3) -> (Vec3, Vec3) {
        let n = if normal.dot(dir) > 0.0 { -normal } else { normal };
        let n = n.try_normalize().unwrap_or(-dir);
        (n, point + n * self.offset)
    }

    /// Ray `j` of pixel `pixel`'s rays, leaving `origin` on side `n` (`leave`): made on its own,
    /// without the pixel's rays before it, so a sample of a frame's rays costs its own rays only.
    fn ray(&self, pixel: u64, j: u32, n: Vec3, origin: Vec3) -> Ray {
        match self.spec.kind {
            RayKind::Shadow => shadow_ray(origin, self.light),
            RayKind::Ao | RayKind::Bounce => {
                // Two numbers per ray, each pixel its own stretch of the seed's stream: ray j's
                // are its 2j-th and (2j+1)-th (`Rng::at` enters a stream anywhere).
                let count = self.spec.rays_per_hit() as u64;
                let mut rng = Rng::at(self.spec.seed, pixel.wrapping_mul(2 * count).wrapping_add(2 * j as u64));
                let (u1, u2) = (rng.unit(), rng.unit());
                let length = if self.spec.kind == RayKind::Ao { self.ao_length } else { f32::INFINITY };
                Ray::segment(origin, cosine_direction(n, u1, u2), 0.0, length)
            }
            RayKind::Primary => unreachable!("no rays are made for primary frames"),
        }
    }

    /// At most `max` of the secondary rays of a complete frame of primary rays on `camera`, evenly
    /// spread over them: of the list of every hit pixel's `rays` (pixels row by row), `total`
    /// long, the rays at k·total/n for k in 0..n (n = min(total, max); all of them when
    /// `max >= total`). The rays a heatmap of this kind traces, or a sample of them, so a table
    /// can count and time each tree on exactly them.
    ///
    /// The kept rays are made directly, one pixel at a time, never the whole list: a 2048×1536
    /// frame of the bunny with 256 ao rays per pixel has over a hundred million of them, 6.6 GB listed
    /// (issue 58), where `compare` keeps a quarter million.
    pub fn frame_rays(&self, frame: &super::Frame, camera: &Camera, max: usize) -> FrameRays {
        assert!(frame.is_complete() && frame.width() == camera.width, "a complete frame of this camera");
        let (width, height) = (camera.width, camera.height);
        let pixels = move || (0..height).flat_map(move |y| (0..width).map(move |x| (x, y)));
        let per = self.spec.rays_per_hit() as u64;
        let total = pixels().filter(|&(x, y)| frame.sample(x, y).is_hit()).count() as u64 * per;
        let n = total.min(max as u64);
        // In u128: k·total passes u64 once a frame has four billion rays and all are kept.
        let pick = |k: u64| (k as u128 * total as u128 / n.max(1) as u128) as u64;
        let gen = camera.ray_gen();
        let mut rays = Vec::with_capacity(n as usize);
        // The next ray to keep, and the index in the list of the current pixel's first ray.
        let (mut next, mut first) = (pick(0), 0u64);
        for (x, y) in pixels() {
            if rays.len() as u64 == n {
                break;
            }
            let s = frame.sample(x, y);
            if !s.is_hit() {
                continue;
            }
            if next < first + per {
                let ray = gen.pixel_ray(x, y);
                let pixel = y as u64 * width as u64 + x as u64;
                let (normal, origin) = self.leave(ray.origin() + ray.dir() * s.t, s.normal, ray.dir());
                while (rays.len() as u64) < n && next < first + per {
                    rays.push(self.ray(pixel, (next - first) as u32, normal, origin));
                    next = pick(rays.len() as u64);
                }
            }
            first += per;
        }
        FrameRays { rays, of: total }
    }

    /// Pixel (x, y)'s secondary rays on `camera`, from its camera ray's hit as the renderer finds
    /// it (the same hit, normal and seed): `None` when the camera ray misses.
    pub fn pixel_rays<A: Accelerator + ?Sized, M: crate::mesh::Surface + ?Sized>(
        &self,
        accel: &A,
        surface: &M,
        camera: &Camera,
        opts: TraceOptions,
        (x, y): (u32, u32),
    ) -> Option<Vec<Ray>> {
        let mut ray = camera.ray_gen().pixel_ray(x, y);
        let hit = accel.closest_hit(&mut ray, opts, &mut crate::bvh::NoStats);
        let s = super::PixelSample::of(surface, &ray, hit);
        let pixel = y as u64 * camera.width as u64 + x as u64;
        s.is_hit().then(|| self.rays(pixel, ray.origin() + ray.dir() * s.t, s.normal, ray.dir()).collect())
    }

    /// Trace one pixel's secondary rays (`rays`), counting into `S`: the counters summed over the
    /// rays and how many of them hit something.
    #[allow(clippy::too_many_arguments)]
    pub fn trace<A: Accelerator + ?Sized, S: TraversalStats + Default + Into<RayCounters>>(
        &self,
        accel: &A,
        opts: TraceOptions,
        pixel: u64,
        point: Vec3,
        normal: Vec3,
        dir: Vec3,
    ) -> (RayCounters, u32) {
        let (mut sum, mut hits) = (RayCounters::ZERO, 0);
        for ray in self.rays(pixel, point, normal, dir) {
            let mut s = S::default();
            let hit = self.spec.kind.trace(accel, &ray, opts, &mut s);
            sum.add(&s.into());
            hits += hit as u32;
        }
        (sum, hits)
    }
}

/// Some of a frame's secondary rays (`SecondaryRays::frame_rays`): `rays`, of the `of` the frame has.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameRays {
    pub rays: Vec<Ray>,
    pub of: u64,
}

/// The shadow ray from `origin` up to the point light at `light` (nothing beyond it shadows).
fn shadow_ray(origin: Vec3, light: Vec3) -> Ray {
    let to = light - origin;
    let d = to.length();
    if d.is_finite() && d > 1e-15 {
        return Ray::segment(origin, to / d, 0.0, d);
    }
    // A far light (1e20 away: its squared distance passes f32, `d` is infinite and the direction
    // was 0, an empty ray that shadowed nothing, issue 58) or one a hair off the surface (its
    // squared distance underflows): in f64, where no f32 input overflows or underflows. Lights in
    // between keep their f32 rays bit for bit.
    let to = light.as_dvec3() - origin.as_dvec3();
    let d = to.length();
    if d == 0.0 {
        // On the light itself: no direction to it, and nothing between.
        return Ray::segment(origin, Vec3::ZERO, 0.0, 0.0);
    }
    Ray::segment(origin, (to / d).as_vec3(), 0.0, d as f32)
}

/// A cosine-weighted direction about unit normal `n` from two uniform numbers in [0, 1).
pub fn cosine_direction(n: Vec3, u1: f32, u2: f32) -> Vec3 {
    let r = u1.sqrt();
    let phi = std::f32::consts::TAU * u2;
    let (x, y, z) = (r * phi.cos(), r * phi.sin(), (1.0 - u1).max(0.0).sqrt());
    // Duff et al.'s branchless basis.
    let sign = 1f32.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    let t = Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
    let bt = Vec3::new(b, sign + n.y * n.y * a, -n.y);
    (t * x + bt * y + n * z).normalize()
}

#[cfg(test)]
#[path = "secondary_tests.rs"]
mod tests;
