//! A pinhole camera (position, look-at, up, vertical field of view, image size) and its rays.
//! Pixel (0, 0) is the top-left corner; a pixel's ray passes through its centre.

use crate::geometry::{Aabb, Ray};
use crate::mesh::MAX_COORDINATE;
use glam::Vec3;

#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Camera {
    pub position: Vec3,
    pub look_at: Vec3,
    pub up: Vec3,
    /// Vertical field of view in degrees.
    pub vfov_deg: f32,
    pub width: u32,
    pub height: u32,
}

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum CameraError {
    #[error("camera position, look-at and up must be finite numbers")]
    NotFinite,
    #[error("camera position and look-at point are the same")]
    NoDirection,
    #[error("camera up vector is zero or parallel to the viewing direction")]
    BadUp,
    #[error("vertical field of view must be between {lo} and {hi} degrees (got {0})", lo = Camera::MIN_VFOV_DEG, hi = Camera::MAX_VFOV_DEG)]
    BadFov(f32),
    #[error("the camera is {0:e} from {1}, farther than {MAX_COORDINATE:e}: rays from so far cannot be traced in single precision")]
    TooFar(f32, &'static str),
    #[error("image size must be at least 1x1, at most 16384 on a side and 40 megapixels (got {0}x{1})")]
    BadSize(u32, u32),
}

/// Which world axis points up. Most formats (and the handout) are Y-up; CAD tools, Blender's own
/// coordinates and many scans are Z-up, and a Z-up mesh framed as Y-up is seen from below.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum UpAxis {
    #[default]
    Y,
    Z,
}

impl UpAxis {
    pub fn vector(self) -> Vec3 {
        match self {
            UpAxis::Y => Vec3::Y,
            UpAxis::Z => Vec3::Z,
        }
    }

    /// A direction written in the Y-up convention (x right, y up, +z towards a viewer in front),
    /// in world coordinates of this convention. Z-up: y up becomes z up, and the front (+z) is
    /// -y, so a front view looks along +y, as in Blender's front view.
    pub fn from_y_up(self, v: Vec3) -> Vec3 {
        match self {
            UpAxis::Y => v,
            UpAxis::Z => Vec3::new(v.x, -v.z, v.y),
        }
    }

    /// The inverse of `from_y_up`.
    pub fn to_y_up(self, v: Vec3) -> Vec3 {
        match self {
            UpAxis::Y => v,
            UpAxis::Z => Vec3::new(v.x, v.z, -v.y),
        }
    }
}

/// The camera's ray generator: a basis computed once per frame.
#[derive(Clone, Copy, Debug)]
pub struct RayGen {
    origin: Vec3,
    forward: Vec3,
    right: Vec3,
    up: Vec3,
    inv_w: f32,
    inv_h: f32,
}

/// What a `RayGen` is made of, for code that makes the same rays elsewhere (the GPU path finishes
/// each pixel's ray in a shader from these, so its rays follow any change to `Camera::ray_gen`).
/// A pixel's ray is `normalize(forward + right·sx + up·sy)` from `origin`, with
/// `sx = 2·x·inv_w − 1` and `sy = 1 − 2·y·inv_h` at the pixel's centre (x + 0.5, y + 0.5).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayGenParts {
    pub origin: Vec3,
    pub forward: Vec3,
    /// Scaled by the tangent of half the field of view and the aspect.
    pub right: Vec3,
    /// Scaled by the tangent of half the field of view.
    pub up: Vec3,
    pub inv_w: f32,
    pub inv_h: f32,
}

impl RayGen {
    pub fn parts(&self) -> RayGenParts {
        let RayGen { origin, forward, right, up, inv_w, inv_h } = *self;
        RayGenParts { origin, forward, right, up, inv_w, inv_h }
    }

    /// The ray through continuous pixel coordinates (x right, y down; pixel centres at +0.5).
    #[inline]
    pub fn ray(&self, x: f32, y: f32) -> Ray {
        let sx = 2.0 * x * self.inv_w - 1.0;
        let sy = 1.0 - 2.0 * y * self.inv_h;
        let dir = (self.forward + self.right * sx + self.up * sy).normalize();
        Ray::new(self.origin, dir)
    }

    /// The ray through the centre of pixel (px, py).
    #[inline]
    pub fn pixel_ray(&self, px: u32, py: u32) -> Ray {
        self.ray(px as f32 + 0.5, py as f32 + 0.5)
    }

    /// The rays through the centres of pixels `xs` of row `py` (at most `ROW_RAYS`), into `out`:
    /// bit for bit `pixel_ray`'s (the same operations in the same order), the directions made
    /// lane by lane in arrays the compiler turns into SIMD. Made one at a time between two walks,
    /// each ray's square root and divisions waited on the previous ones (BENCHMARKS.md, "The
    /// counted frame's camera rays").
    pub fn row_rays(&self, py: u32, xs: &[u32], out: &mut [Ray]) {
        const N: usize = ROW_RAYS;
        assert!(xs.len() <= N && out.len() >= xs.len(), "at most {N} rays a call");
        let sy = 1.0 - 2.0 * (py as f32 + 0.5) * self.inv_h;
        let mut sx = [0.0f32; N];
        for (s, &x) in sx.iter_mut().zip(xs) {
            *s = 2.0 * (x as f32 + 0.5) * self.inv_w - 1.0;
        }
        let (f, r, u) = (self.forward, self.right, self.up);
        let (mut dx, mut dy, mut dz, mut len) = ([0.0f32; N], [0.0f32; N], [0.0f32; N], [0.0f32; N]);
        for i in 0..N {
            // `forward + right * sx + up * sy`, component by component as glam adds them.
            dx[i] = f.x + r.x * sx[i] + u.x * sy;
            dy[i] = f.y + r.y * sx[i] + u.y * sy;
            dz[i] = f.z + r.z * sx[i] + u.z * sy;
            // `normalize`: times 1 / sqrt(dot), the dot product summed x, y, z.
            len[i] = 1.0 / (dx[i] * dx[i] + dy[i] * dy[i] + dz[i] * dz[i]).sqrt();
        }
        for (i, ray) in out.iter_mut().enumerate().take(xs.len()) {
            *ray = Ray::new(self.origin, Vec3::new(dx[i] * len[i], dy[i] * len[i], dz[i] * len[i]));
        }
    }
}

/// The most rays `RayGen::row_rays` makes in one call.
pub const ROW_RAYS: usize = 16;

impl Camera {
    /// The narrowest and widest vertical field of view (a narrower one would frame a mesh from
    /// farther than single precision traces; 180 degrees sees nothing).
    pub const MIN_VFOV_DEG: f32 = 0.01;
    pub const MAX_VFOV_DEG: f32 = 179.9;

    pub fn validate(&self) -> Result<(), CameraError> {
        if !(self.position.is_finite() && self.look_at.is_finite() && self.up.is_finite()) {
            return Err(CameraError::NotFinite);
        }
        if !(self.vfov_deg >= Self::MIN_VFOV_DEG && self.vfov_deg <= Self::MAX_VFOV_DEG) {
            return Err(CameraError::BadFov(self.vfov_deg));
        }
        for (p, what) in [(self.position, "the origin"), (self.look_at, "the origin (its look-at point)")] {
            let d = p.abs().max_element();
            if d > MAX_COORDINATE {
                return Err(CameraError::TooFar(d, what));
            }
        }
        let f = self.look_at - self.position;
        if f.length_squared() == 0.0 {
            return Err(CameraError::NoDirection);
        }
        if f.normalize().cross(self.up.normalize_or_zero()).length_squared() < 1e-12 {
            return Err(CameraError::BadUp);
        }
        let pixels = self.width as u64 * self.height as u64;
        if self.width == 0 || self.height == 0 || self.width > 16384 || self.height > 16384 || pixels > Self::MAX_PIXELS
        {
            return Err(CameraError::BadSize(self.width, self.height));
        }
        Ok(())
    }

    pub fn aspect(&self) -> f32 {
        self.width as f32 / self.height as f32
    }

    /// Unit forward, right and up vectors of a valid camera (right-handed: right = forward × up).
    pub fn basis(&self) -> (Vec3, Vec3, Vec3) {
        let forward = (self.look_at - self.position).normalize();
        let right = forward.cross(self.up).normalize();
        (forward, right, right.cross(forward))
    }

    /// The ray generator; the camera must be valid (`validate`).
    pub fn ray_gen(&self) -> RayGen {
        let (forward, right, up) = self.basis();
        let tan_half = (self.vfov_deg.to_radians() * 0.5).tan();
        RayGen {
            origin: self.position,
            forward,
            right: right * tan_half * self.aspect(),
            up: up * tan_half,
            inv_w: 1.0 / self.width as f32,
            inv_h: 1.0 / self.height as f32,
        }
    }

    /// Largest image: a frame keeps about 36 bytes per pixel, so this is about 1.4 GB.
    pub const MAX_PIXELS: u64 = 40_000_000;

    /// The direction the default view looks from: front, right, above.
    pub const DEFAULT_VIEW_FROM: Vec3 = Vec3::new(0.45, 0.35, 1.0);
    pub const DEFAULT_VFOV_DEG: f32 = 45.0;

    /// A camera that shows all of `bounds` from a fixed oblique direction (front, right, above),
    /// with +y up and a 45° vertical field of view: the default view of the CLI and the app.
    pub fn framing(bounds: &Aabb, width: u32, height: u32) -> Camera {
        Self::framing_up(bounds, width, height, UpAxis::Y, Self::DEFAULT_VFOV_DEG)
    }

    /// The default view (front, right, above) of a mesh whose up axis is `up`.
    pub fn framing_up(bounds: &Aabb, width: u32, height: u32, up: UpAxis, vfov_deg: f32) -> Camera {
        Self::framing_from_up(bounds, width, height, up.from_y_up(Self::DEFAULT_VIEW_FROM), vfov_deg, up)
    }

    /// Like `framing`, looking along `-from` with the given vertical field of view: the closest
    /// camera distance at which all eight corners of the box lie inside 95% of the image (found by
    /// bisection).
    pub fn framing_from(bounds: &Aabb, width: u32, height: u32, from: Vec3, vfov_deg: f32) -> Camera {
        Self::framing_from_up(bounds, width, height, from, vfov_deg, UpAxis::Y)
    }

    /// `framing_from` with `up` pointing up in the image.
    pub fn framing_from_up(
        bounds: &Aabb,
        width: u32,
        height: u32,
        from: Vec3,
        vfov_deg: f32,
        up_axis: UpAxis,
    ) -> Camera {
        let vfov_deg = if (Self::MIN_VFOV_DEG..=Self::MAX_VFOV_DEG).contains(&vfov_deg) {
            vfov_deg
        } else {
            Self::DEFAULT_VFOV_DEG
        };
        let (width, height) = (width.max(1), height.max(1));
        let b = if bounds.is_empty() { Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0)) } else { *bounds };
        let center = b.center();
        let radius = (b.extent().length() * 0.5).max(1e-6);
        let world_up = up_axis.vector();
        let dir = from.try_normalize().unwrap_or(up_axis.from_y_up(Vec3::Z));
        let forward = -dir;
        let right = forward.cross(world_up).try_normalize().unwrap_or(Vec3::X);
        let up = right.cross(forward);
        let tan_v = (vfov_deg.to_radians() * 0.5).tan() * 0.95;
        let tan_h = tan_v * width as f32 / height as f32;
        let fits = |d: f32| {
            let eye = center + dir * d;
            (0..8).all(|i| {
                let c = Vec3::new(
                    if i & 1 == 0 { b.min.x } else { b.max.x },
                    if i & 2 == 0 { b.min.y } else { b.max.y },
                    if i & 4 == 0 { b.min.z } else { b.max.z },
                );
                let v = c - eye;
                let z = v.dot(forward);
                z > 0.0 && v.dot(right).abs() <= tan_h * z && v.dot(up).abs() <= tan_v * z
            })
        };
        // The bounding sphere's distance always fits; bisect towards the box.
        let (mut lo, mut hi) = (0.0f32, radius / tan_v.min(tan_h).atan().sin() * 1.02);
        for _ in 0..40 {
            let mid = 0.5 * (lo + hi);
            if fits(mid) {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        Camera { position: center + dir * hi, look_at: center, up: world_up, vfov_deg, width, height }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_pixel_looks_at_the_target_and_corners_span_the_fov() {
        let cam = Camera {
            position: Vec3::new(0.0, 1.0, 5.0),
            look_at: Vec3::ZERO,
            up: Vec3::Y,
            vfov_deg: 45.0,
            width: 1200,
            height: 800,
        };
        cam.validate().unwrap();
        let g = cam.ray_gen();
        let centre = g.ray(600.0, 400.0);
        assert!((centre.dir() - (-cam.position).normalize()).length() < 1e-6);
        // Top and bottom edge rays are 45° apart.
        let top = g.ray(600.0, 0.0).dir();
        let bottom = g.ray(600.0, 800.0).dir();
        assert!((top.angle_between(bottom).to_degrees() - 45.0).abs() < 1e-3);
        assert!(top.y > bottom.y, "row 0 is the top of the image");
        assert!(g.ray(1200.0, 400.0).dir().x > 0.0, "the last column is on the right");
    }

    /// A row's rays made together are `pixel_ray`'s, bit for bit, on cameras of every shape.
    #[test]
    fn row_rays_are_pixel_rays_bit_for_bit() {
        let b = Aabb::new(Vec3::new(-1.0, 0.0, -2.0), Vec3::new(3.0, 1.0, 0.5));
        let bits = |r: &Ray| {
            let v = [r.origin(), r.dir(), r.inv_dir()];
            (v.map(|v| v.to_array().map(f32::to_bits)), r.t_min.to_bits(), r.t_max.to_bits())
        };
        for (w, h, fov, from) in [
            (640, 480, 45.0, Camera::DEFAULT_VIEW_FROM),
            (301, 45, 10.0, Vec3::X),
            (33, 900, 120.0, Vec3::new(0.0, 0.0, -1.0)),
            (1280, 720, 0.01, Vec3::new(0.3, -0.8, 0.2)),
        ] {
            let g = Camera::framing_from(&b, w, h, from, fov).ray_gen();
            let mut out = [g.pixel_ray(0, 0); ROW_RAYS];
            for py in [0, 1, h / 2, h - 1] {
                for start in (0..w).step_by(7) {
                    let xs: Vec<u32> = (start..w).step_by(1 + start as usize % 3).take(ROW_RAYS).collect();
                    g.row_rays(py, &xs, &mut out);
                    for (k, &x) in xs.iter().enumerate() {
                        assert_eq!(bits(&out[k]), bits(&g.pixel_ray(x, py)), "{w}×{h} {fov}°: pixel {x}, {py}");
                    }
                }
            }
        }
    }

    #[test]
    fn framing_contains_the_box() {
        let b = Aabb::new(Vec3::new(-1.0, 0.0, -2.0), Vec3::new(3.0, 1.0, 0.5));
        for (w, h, fov) in [(640, 480, 45.0), (300, 900, 45.0), (640, 480, 10.0), (640, 480, 120.0)] {
            let cam = Camera::framing_from(&b, w, h, Camera::DEFAULT_VIEW_FROM, fov);
            assert_eq!(cam.vfov_deg, fov);
            cam.validate().unwrap();
            // Every box corner projects inside the image, and the box fills it (framed, not lost).
            let mut widest = 0f32;
            let fwd = (cam.look_at - cam.position).normalize();
            let right = fwd.cross(Vec3::Y).normalize();
            let up = right.cross(fwd);
            let t = (cam.vfov_deg.to_radians() / 2.0).tan();
            for i in 0..8 {
                let c = Vec3::new(
                    if i & 1 == 0 { b.min.x } else { b.max.x },
                    if i & 2 == 0 { b.min.y } else { b.max.y },
                    if i & 4 == 0 { b.min.z } else { b.max.z },
                );
                let d = c - cam.position;
                let z = d.dot(fwd);
                assert!(z > 0.0);
                let (sx, sy) = ((d.dot(right) / z).abs() / (t * cam.aspect()), (d.dot(up) / z).abs() / t);
                assert!(sx <= 1.0 && sy <= 1.0, "corner {c} outside for {w}x{h} at {fov}°");
                widest = widest.max(sx).max(sy);
            }
            assert!(widest > 0.9, "the box fills the view at {fov}° ({widest})");
        }
    }

    #[test]
    fn a_z_up_box_is_framed_from_the_front_as_the_same_box_y_up() {
        // The same box written Y-up and Z-up (y ↔ z, front flipped): the default cameras of the
        // two see the same picture, each with its own axis up.
        let y_up = Aabb::new(Vec3::new(-1.0, 0.0, -0.5), Vec3::new(3.0, 2.0, 0.5));
        let z_up = Aabb::new(UpAxis::Z.from_y_up(y_up.min.into()), UpAxis::Z.from_y_up(y_up.max.into()));
        let z_up = Aabb::new(z_up.min.min(z_up.max), z_up.min.max(z_up.max));
        let a = Camera::framing_up(&y_up, 640, 480, UpAxis::Y, 45.0);
        let b = Camera::framing_up(&z_up, 640, 480, UpAxis::Z, 45.0);
        assert_eq!(a, Camera::framing(&y_up, 640, 480));
        assert_eq!(b.up, Vec3::Z);
        b.validate().unwrap();
        let map = |v: Vec3| UpAxis::Z.to_y_up(v);
        assert!((map(b.position) - a.position).length() < 1e-4, "{} vs {}", map(b.position), a.position);
        assert!((map(b.look_at) - a.look_at).length() < 1e-5);
        assert!(b.position.z > b.look_at.z, "seen from above, not from underneath");
        assert!(b.position.y < b.look_at.y, "from the front (-y)");
        for v in [Vec3::X, Vec3::new(0.3, -2.0, 5.0)] {
            assert_eq!(UpAxis::Z.to_y_up(UpAxis::Z.from_y_up(v)), v);
        }
    }

    #[test]
    fn invalid_cameras_are_rejected() {
        let ok = Camera { position: Vec3::Z, look_at: Vec3::ZERO, up: Vec3::Y, vfov_deg: 45.0, width: 8, height: 8 };
        assert_eq!(Camera { look_at: Vec3::Z, ..ok }.validate(), Err(CameraError::NoDirection));
        assert_eq!(Camera { up: Vec3::Z, ..ok }.validate(), Err(CameraError::BadUp));
        assert_eq!(Camera { vfov_deg: 180.0, ..ok }.validate(), Err(CameraError::BadFov(180.0)));
        assert_eq!(Camera { width: 0, ..ok }.validate(), Err(CameraError::BadSize(0, 8)));
        assert_eq!(
            Camera { width: 16384, height: 16384, ..ok }.validate(),
            Err(CameraError::BadSize(16384, 16384)),
            "over the pixel budget"
        );
        assert_eq!(Camera { position: Vec3::NAN, ..ok }.validate(), Err(CameraError::NotFinite));
    }
}
