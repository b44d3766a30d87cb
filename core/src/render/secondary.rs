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

use super::Camera;
use crate::bvh::{Accelerator, RayCounters, TraceOptions, TraversalStats};
use crate::geometry::{Aabb, Ray};
use crate::random::Rng;
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
    /// The default light is half the scene's diagonal above the camera (along its up vector).
    pub fn new(spec: SecondarySpec, bounds: &Aabb, camera: &Camera) -> Self {
        let diagonal = if bounds.is_empty() { 1.0 } else { bounds.extent().length().max(1e-30) };
        let up = camera.up.try_normalize().unwrap_or(Vec3::Y);
        let light = spec.light.unwrap_or(camera.position + up * 0.5 * diagonal);
        Self { spec, light, ao_length: spec.ao_length * diagonal, offset: diagonal * 1e-4 }
    }

    /// The secondary rays of pixel `pixel` (its index in the frame, row by row) whose primary ray
    /// `dir` hit at `point` with shading normal `normal`: the same rays for the same pixel, hit and
    /// seed whatever traces them. Empty for primary frames.
    pub fn rays(&self, pixel: u64, point: Vec3, normal: Vec3, dir: Vec3) -> impl Iterator<Item = Ray> + '_ {
        // The side the camera sees: rays leave from there.
        let n = if normal.dot(dir) > 0.0 { -normal } else { normal };
        let n = n.try_normalize().unwrap_or(-dir);
        let origin = point + n * self.offset;
        let count = self.spec.rays_per_hit();
        // Two numbers per ray, each pixel its own stretch of the seed's stream.
        let mut rng = Rng::at(self.spec.seed, pixel.wrapping_mul(2 * count as u64));
        (0..count).map(move |_| match self.spec.kind {
            RayKind::Shadow => {
                let to = self.light - origin;
                let d = to.length();
                // Up to the light: nothing beyond it shadows.
                Ray::segment(origin, to / d.max(1e-30), 0.0, d)
            }
            RayKind::Ao | RayKind::Bounce => {
                let (u1, u2) = (rng.unit(), rng.unit());
                let length = if self.spec.kind == RayKind::Ao { self.ao_length } else { f32::INFINITY };
                Ray::segment(origin, cosine_direction(n, u1, u2), 0.0, length)
            }
            RayKind::Primary => unreachable!("no rays are made for primary frames"),
        })
    }

    /// Every secondary ray of a complete frame of primary rays on `camera` (its pixels row by
    /// row, each hit pixel's `rays`): the rays a heatmap of this kind traces, as a list, so a
    /// table can count and time each tree on exactly them.
    pub fn frame_rays(&self, frame: &super::Frame, camera: &Camera) -> Vec<Ray> {
        assert!(frame.is_complete() && frame.width() == camera.width, "a complete frame of this camera");
        let gen = camera.ray_gen();
        let mut out = Vec::new();
        for y in 0..camera.height {
            for x in 0..camera.width {
                let s = frame.sample(x, y);
                if s.is_hit() {
                    let ray = gen.pixel_ray(x, y);
                    let pixel = y as u64 * camera.width as u64 + x as u64;
                    out.extend(self.rays(pixel, ray.origin() + ray.dir() * s.t, s.normal, ray.dir()));
                }
            }
        }
        out
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
