//! What the watertight test keeps per ray and what its four-lane form returns: shared by the
//! one-triangle test (`triangle`) and the four-triangle one (`triangle4`).

use glam::Vec3;

/// The hits of `intersect4`: lane k of each array is ray k's hit when bit k of `mask` is set.
#[derive(Clone, Copy, Debug)]
pub struct Hits4 {
    pub mask: u32,
    pub t: [f32; 4],
    pub u: [f32; 4],
    pub v: [f32; 4],
}

/// The per-ray shear of the watertight test as three rows: for a vertex relative to the origin
/// `a`, the sheared coordinates are `(a·rx, a·ry, a·rz)` = `(a[kx] - Sx·a[kz], a[ky] - Sy·a[kz],
/// Sz·a[kz])`. The extra terms are products with exactly 0 or 1, so the results are bit-identical
/// to the paper's indexed form, without indexing by a run-time axis in the inner loop.
#[derive(Clone, Copy, Debug)]
pub struct WatertightRay {
    pub(super) rx: Vec3,
    pub(super) ry: Vec3,
    pub(super) rz: Vec3,
}

impl WatertightRay {
    /// The same rows as `Watertight::prepare`, the axes chosen with branches as the paper writes
    /// the rule: for packets, whose rays share a direction, the branches are predicted and cheaper
    /// than the table (`prepare`'s, for single rays in any direction; a table cost packets a
    /// seventh of their speed).
    #[inline(always)]
    pub(super) fn with_branches(d: Vec3) -> WatertightRay {
        let a = d.abs();
        let kz = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        let (mut kx, mut ky) = ((kz + 1) % 3, (kz + 2) % 3);
        // Keep the winding of the sheared triangle independent of the direction's sign.
        if d[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        let (sx, sy, sz) = (d[kx] / d[kz], d[ky] / d[kz], 1.0 / d[kz]);
        let unit = |k: usize| Vec3::from_array(std::array::from_fn(|i| if i == k { 1.0 } else { 0.0 }));
        let rz_axis = unit(kz);
        WatertightRay { rx: unit(kx) - rz_axis * sx, ry: unit(ky) - rz_axis * sy, rz: rz_axis * sz }
    }
}
