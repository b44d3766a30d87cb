//! The viewport's orbit camera: yaw and pitch around a target at a distance, about the mesh's up
//! axis (+y, or +z for meshes exported Z-up). Yaw and pitch are kept in the Y-up convention and
//! mapped into the world by `UpAxis`, so both axes orbit, pan and frame alike.

use crate::geometry::Aabb;
use crate::render::{Camera, UpAxis};
use glam::Vec3;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrbitCamera {
    pub target: Vec3,
    /// Which world axis is up.
    pub up: UpAxis,
    /// Rotation about the up axis, radians; 0 looks at the front (along -z for Y-up).
    pub yaw: f32,
    /// Elevation, radians, within ±89°.
    pub pitch: f32,
    pub distance: f32,
    pub vfov_deg: f32,
    /// The camera the orbit was made from, while it has not moved: a scene file's camera is
    /// then used as written (its rays the CLI's, bit for bit), not as rebuilt from yaw and pitch.
    pub exact: Option<Camera>,
}

const MAX_PITCH: f32 = 89.0 * std::f32::consts::PI / 180.0;

impl OrbitCamera {
    /// The default view of `bounds` (the CLI's default camera) for an image of the given aspect.
    pub fn home(bounds: &Aabb, aspect: f32, up: UpAxis) -> Self {
        let (w, h) = aspect_size(aspect);
        Self::from_camera(&Camera::framing_up(bounds, w, h, up, Camera::DEFAULT_VFOV_DEG), up)
    }

    /// The orbit that reproduces a camera, orbiting about `up`.
    pub fn from_camera(c: &Camera, up: UpAxis) -> Self {
        let offset = up.to_y_up(c.position - c.look_at);
        let distance = offset.length();
        let d = offset / distance;
        Self {
            target: c.look_at,
            up,
            yaw: d.x.atan2(d.z),
            pitch: d.y.clamp(-1.0, 1.0).asin().clamp(-MAX_PITCH, MAX_PITCH),
            distance,
            vfov_deg: c.vfov_deg,
            exact: None,
        }
    }

    /// `from_camera`, keeping `c` itself while the orbit does not move (`exact`).
    pub fn exactly(c: &Camera, up: UpAxis) -> Self {
        Self { exact: Some(*c), ..Self::from_camera(c, up) }
    }

    /// Unit vector from the target to the eye (world coordinates).
    pub fn direction(&self) -> Vec3 {
        let d = Vec3::new(self.pitch.cos() * self.yaw.sin(), self.pitch.sin(), self.pitch.cos() * self.yaw.cos());
        self.up.from_y_up(d)
    }

    pub fn camera(&self, width: u32, height: u32) -> Camera {
        if let Some(c) = self.exact {
            return Camera { width, height, ..c };
        }
        Camera {
            position: self.target + self.direction() * self.distance,
            look_at: self.target,
            up: self.up.vector(),
            vfov_deg: self.vfov_deg,
            width,
            height,
        }
    }

    /// Rotate by a mouse drag of (dx, dy) pixels.
    pub fn orbit(&mut self, dx: f32, dy: f32) {
        self.exact = None;
        self.yaw -= dx * 0.008;
        self.pitch = (self.pitch + dy * 0.008).clamp(-MAX_PITCH, MAX_PITCH);
    }

    /// Move the target so the scene follows a drag of (dx, dy) pixels in a view `height` high.
    pub fn pan(&mut self, dx: f32, dy: f32, height: f32) {
        self.exact = None;
        let forward = -self.direction();
        let right = forward.cross(self.up.vector()).normalize_or(Vec3::X);
        let up = right.cross(forward);
        let per_pixel = 2.0 * self.distance * (self.vfov_deg.to_radians() * 0.5).tan() / height.max(1.0);
        self.target += (-right * dx + up * dy) * per_pixel;
    }

    /// Zoom by mouse-wheel steps (positive: closer).
    pub fn zoom(&mut self, steps: f32) {
        self.exact = None;
        self.distance = (self.distance * (-steps * 0.0015).exp()).clamp(1e-6, 1e9);
    }

    /// Keep the direction, fit `bounds` into the view.
    pub fn frame(&mut self, bounds: &Aabb, aspect: f32) {
        let (w, h) = aspect_size(aspect);
        let framed = Camera::framing_from_up(bounds, w, h, self.direction(), self.vfov_deg, self.up);
        *self = Self { yaw: self.yaw, pitch: self.pitch, ..Self::from_camera(&framed, self.up) };
    }
}

/// An image size with the given aspect (for framing, only the ratio matters).
fn aspect_size(aspect: f32) -> (u32, u32) {
    let aspect = if aspect.is_finite() && aspect > 0.0 { aspect.clamp(0.05, 20.0) } else { 1.0 };
    ((1000.0 * aspect).round().max(1.0) as u32, 1000)
}

/// How a given camera (a scene file's, a grade report's) orbits: about the axis its up vector is
/// nearest to (Y or Z).
pub fn up_axis_of(c: &Camera) -> UpAxis {
    if c.up.z.abs() > c.up.y.abs() && c.up.z.abs() >= c.up.x.abs() {
        UpAxis::Z
    } else {
        UpAxis::Y
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn home_matches_the_cli_default_camera() {
        let b = Aabb::new(Vec3::new(-1.0, 0.0, -2.0), Vec3::new(3.0, 1.0, 0.5));
        let o = OrbitCamera::home(&b, 1.6, UpAxis::Y);
        let c = Camera::framing(&b, 1600, 1000);
        let oc = o.camera(1600, 1000);
        assert!((oc.position - c.position).length() < 1e-4 * c.position.length().max(1.0));
        assert_eq!(oc.look_at, c.look_at);
    }

    #[test]
    fn orbit_keeps_distance_and_pan_moves_target_and_eye_together() {
        let mut o = OrbitCamera::home(&Aabb::new(Vec3::splat(-1.0), Vec3::ONE), 1.0, UpAxis::Y);
        let d = o.distance;
        o.orbit(120.0, -40.0);
        let c = o.camera(100, 100);
        assert!(((c.position - c.look_at).length() - d).abs() < 1e-4);
        let before = o.camera(100, 100);
        o.pan(10.0, 5.0, 100.0);
        let after = o.camera(100, 100);
        let moved = after.look_at - before.look_at;
        assert!(moved.length() > 0.0);
        assert!(((after.position - before.position) - moved).length() < 1e-5);
        o.orbit(0.0, 1e6);
        assert!(o.pitch <= MAX_PITCH, "pitch is clamped short of the pole");
        o.camera(10, 10).validate().unwrap();
    }

    #[test]
    fn a_z_up_orbit_matches_the_cli_default_and_orbits_about_z() {
        let b = Aabb::new(Vec3::new(-1.0, -0.5, 0.0), Vec3::new(3.0, 0.5, 2.0));
        let mut o = OrbitCamera::home(&b, 1.6, UpAxis::Z);
        let c = Camera::framing_up(&b, 1600, 1000, UpAxis::Z, Camera::DEFAULT_VFOV_DEG);
        let oc = o.camera(1600, 1000);
        assert!((oc.position - c.position).length() < 1e-4 * c.position.length().max(1.0));
        assert_eq!(oc.up, Vec3::Z);
        let height = oc.position.z;
        o.orbit(200.0, 0.0);
        let turned = o.camera(1600, 1000);
        assert!((turned.position.z - height).abs() < 1e-4, "a sideways drag keeps the height above the z = 0 plane");
        assert!((turned.position - oc.position).length() > 0.1);
        o.frame(&b, 1.6);
        o.camera(1600, 1000).validate().unwrap();
    }
}
