//! The ray–box slab tests, every variant in one place: one ray against one box (binary nodes and
//! root boxes), one ray against four boxes (a wide node's children, one SIMD pass), four rays
//! against one box (a packet's group, one SIMD pass), and an interval of rays against one or four
//! boxes (a packet's frustum). They share two rules, stated here once.
//!
//! **Planes and NaN** (Williams, Barrus, Morley & Shirley, "An Efficient and Robust Ray–Box
//! Intersection Algorithm", JGT 2005): the near and far plane of each axis are chosen by the sign
//! of the reciprocal direction, not by min/max of the two distances. A direction component of +0
//! or -0 has a reciprocal of +inf or -inf, so an origin strictly inside the slab gives
//! (-inf, +inf) and one outside an empty interval. An origin exactly on a plane with a zero
//! component gives 0·inf = NaN: the ray lies in the plane, which must not constrain it, and the
//! running minimum and maximum skip a NaN (`f32::min`/`max`, and `max_keep`/`min_keep` in SIMD),
//! which leaves the interval unchanged. A malformed ray cannot hit: it is born empty (`Ray`).
//!
//! **Robustness** (Ize, "Robust BVH Ray Traversal", JCGT 2013; pbrt-v4 §6.1.2): each slab distance
//! (plane − origin)·(1/d) is rounded three times (the subtraction, the reciprocal, the product), so
//! it may be off by a relative γ(3) = 3ε/(1 − 3ε). A box the ray only touches, at a vertex shared
//! with the triangle the ray is aimed at, has equal entry and exit; rounded, the entry can come out
//! above the exit and the box is culled although the watertight triangle test would hit. So, as
//! Ize does, the far planes' distances are computed with a reciprocal direction enlarged by
//! `SLACK` (`inv_far`): every exit comes out a little late, never early. And a box is culled when
//! its entry lies beyond the closest hit so far (`t_max`); but the triangle tests round too, so two
//! triangles meeting at the vertex the ray is aimed at give distances a few units in the last place
//! apart, and the box of the nearer one can start just beyond the farther one's rounded distance.
//! So boxes and stack entries are compared with `t_max` widened by `SLACK` (`widen`), which the
//! traversals compute once per hit rather than per box. Every box the exact ray meets, and every
//! box holding a triangle whose rounded distance beats `t_max`, passes; a few the ray only grazes
//! are visited as well, which costs a little work and never a result (the triangle test decides,
//! against the exact `t_max`). This holds for the watertight test, whose distance is within a few
//! units in the last place; Möller–Trumbore's has no fixed bound (it grows with the origin's
//! distance against the triangle's size), so with it, of two triangles meeting where a ray is
//! aimed, the BVH may return the one whose rounded distance is a few hundred units in the last
//! place farther: the same point, the other triangle (`core/tests/watertight_traversal.rs`). Both widenings stay off the per-node dependency chain: a widening
//! of each exit there cost a fifth of the wide traversal's speed.

use crate::geometry::aabb::Aabb;
use crate::geometry::ray::Ray;
use glam::Vec3;
use wide::f32x4;

/// γ(n) of floating-point error analysis: the relative error bound of n rounded operations.
const fn gamma(n: u32) -> f32 {
    let e = f32::EPSILON * 0.5;
    (n as f32 * e) / (1.0 - n as f32 * e)
}

/// The relative widening of exits (see the module docs): 2⁻¹⁶, about 128 units in the last place,
/// covering the slab test's 2γ(3) and the triangle tests' rounding of `t` with room to spare.
pub const SLACK: f32 = 1.0 / 65536.0;

const _: () = assert!(SLACK > 2.0 * gamma(3));

/// A distance widened by `SLACK` of its magnitude, towards +inf: the `t_max` boxes and stack
/// entries are compared with. ±inf stay as they are (-inf + inf·slack would be NaN, so the larger
/// of the widened value and the original is kept).
#[inline(always)]
pub fn widen(t: f32) -> f32 {
    (t + t.abs() * SLACK).max(t)
}

/// The reciprocal direction enlarged by `SLACK`, for the far planes: the same sign, a larger
/// magnitude, so every exit distance (positive for a box ahead) comes out late, never early.
#[inline(always)]
fn far_inv(inv: Vec3) -> Vec3 {
    inv * (1.0 + SLACK)
}

/// `max(t, acc)` where a NaN `t` (0·inf: the ray lies in a slab plane) leaves `acc` unchanged, the
/// scalar `f32::max` rule in SIMD. SSE's maxps returns its second operand on NaN (the `wide` crate
/// uses it when SSE is enabled, as on every x86-64); elsewhere the NaN-aware `max` is used.
#[inline(always)]
pub fn max_keep(t: f32x4, acc: f32x4) -> f32x4 {
    if cfg!(target_feature = "sse") {
        t.fast_max(acc)
    } else {
        t.max(acc)
    }
}

/// `min(t, acc)` with the same NaN rule as `max_keep`.
#[inline(always)]
pub fn min_keep(t: f32x4, acc: f32x4) -> f32x4 {
    if cfg!(target_feature = "sse") {
        t.fast_min(acc)
    } else {
        t.min(acc)
    }
}

/// `widen` in SIMD.
#[inline(always)]
pub(crate) fn widen4(t: f32x4) -> f32x4 {
    max_keep(t + t.abs() * f32x4::splat(SLACK), t)
}

/// One ray prepared for slab tests against single boxes: origin, reciprocal direction, and the
/// enlarged reciprocal for the far planes.
#[derive(Clone, Copy, Debug)]
pub struct OneRay {
    origin: Vec3,
    inv: Vec3,
    inv_far: Vec3,
}

impl OneRay {
    #[inline(always)]
    pub fn new(ray: &Ray) -> Self {
        Self { origin: ray.origin(), inv: ray.inv_dir(), inv_far: far_inv(ray.inv_dir()) }
    }

    /// The box given by its planes: the clipped interval `(t_enter, t_exit)`, a hit when
    /// `t_enter <= t_exit`. `t_max` is the caller's limit (the closest hit so far, widened).
    #[inline(always)]
    pub fn one_box(&self, lo: &[f32; 3], hi: &[f32; 3], t_min: f32, t_max: f32) -> (f32, f32) {
        interval(lo, hi, self.origin, self.inv, self.inv_far, t_min, t_max)
    }
}

/// The slab test of one box, with `inv_far` the reciprocal for the far planes. The planes are
/// picked by the direction's signs with branches: along one ray's walk they always go the same
/// way, and so are predicted (picking by index instead cost the binary walk 5–10%).
#[inline(always)]
fn interval(lo: &[f32; 3], hi: &[f32; 3], o: Vec3, inv: Vec3, invf: Vec3, t_min: f32, t_max: f32) -> (f32, f32) {
    // Sign-selected planes; `is_sign_negative` distinguishes -inf (from -0) from +inf.
    let pick = |axis: usize, inv: f32| if inv.is_sign_negative() { (hi[axis], lo[axis]) } else { (lo[axis], hi[axis]) };
    let [(nx, fx), (ny, fy), (nz, fz)] = [pick(0, inv.x), pick(1, inv.y), pick(2, inv.z)];
    let (near, far) = (Vec3::new(nx, ny, nz), Vec3::new(fx, fy, fz));
    planes_interval(near, far, o, inv, invf, t_min, t_max)
}

/// `interval` with the near and far planes already picked.
#[inline(always)]
fn planes_interval(near: Vec3, far: Vec3, o: Vec3, inv: Vec3, invf: Vec3, t_min: f32, t_max: f32) -> (f32, f32) {
    let t_enter = t_min.max((near.x - o.x) * inv.x).max((near.y - o.y) * inv.y).max((near.z - o.z) * inv.z);
    let t_exit = t_max.min((far.x - o.x) * invf.x).min((far.y - o.y) * invf.y).min((far.z - o.z) * invf.z);
    (t_enter, t_exit)
}

/// One ray against one box, with nothing prepared (a root box, once per ray): the exit is
/// widened after the fact, which costs a few operations but no setup. Once per ray, so the
/// planes are picked by bit masks from the direction's sign bits, not by branches: for rays in
/// random directions a branch per axis mispredicts half the time here (BENCHMARKS.md).
#[inline(always)]
pub fn box_once(lo: &[f32; 3], hi: &[f32; 3], ray: &Ray) -> (f32, f32) {
    let inv = ray.inv_dir();
    let pick = |axis: usize, inv: f32| {
        // All ones when the sign bit is set: the bits of hi where lo's were, and the reverse.
        let neg = ((inv.to_bits() as i32) >> 31) as u32;
        let (l, h) = (lo[axis].to_bits(), hi[axis].to_bits());
        let swap = (l ^ h) & neg;
        (f32::from_bits(l ^ swap), f32::from_bits(h ^ swap))
    };
    let [(nx, fx), (ny, fy), (nz, fz)] = [pick(0, inv.x), pick(1, inv.y), pick(2, inv.z)];
    let (near, far) = (Vec3::new(nx, ny, nz), Vec3::new(fx, fy, fz));
    let (t_enter, t_exit) = planes_interval(near, far, ray.origin(), inv, inv, ray.t_min, ray.t_max);
    (t_enter, widen(t_exit))
}

/// `W` boxes' planes in SoA order (`min[axis][box]`), for one SIMD slab test of all of them: a
/// wide node's children (four, or eight in `slab8`), or a binary node's two with empty slots.
/// `repr(C)`: the AVX-512 kernel picks a ray's near and far planes by their offsets in it.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Boxes<const W: usize> {
    pub min: [[f32; W]; 3],
    pub max: [[f32; W]; 3],
}

/// Four boxes: the 4-wide node's children and the packet walk's nodes.
pub type Boxes4 = Boxes<4>;

impl<const W: usize> Boxes<W> {
    /// Empty boxes (+inf..-inf), which every slab test misses.
    pub const EMPTY: Self = Self { min: [[f32::INFINITY; W]; 3], max: [[f32::NEG_INFINITY; W]; 3] };

    /// Put box `b`'s planes in slot `k`.
    #[inline(always)]
    pub fn set(&mut self, k: usize, lo: [f32; 3], hi: [f32; 3]) {
        for axis in 0..3 {
            self.min[axis][k] = lo[axis];
            self.max[axis][k] = hi[axis];
        }
    }

    /// Slot `k`'s planes.
    #[inline(always)]
    pub fn planes(&self, k: usize) -> ([f32; 3], [f32; 3]) {
        let (lo, hi) = (&self.min, &self.max);
        ([lo[0][k], lo[1][k], lo[2][k]], [hi[0][k], hi[1][k], hi[2][k]])
    }

    /// Slot `k`'s box.
    pub fn bounds(&self, k: usize) -> Aabb {
        let (lo, hi) = self.planes(k);
        Aabb::new(Vec3::from_array(lo), Vec3::from_array(hi))
    }
}

/// One ray in SIMD form for testing the four child boxes of a wide node at once.
pub struct RayX4 {
    org: [f32x4; 3],
    inv: [f32x4; 3],
    inv_far: [f32x4; 3],
    neg: [bool; 3],
}

impl RayX4 {
    #[inline(always)]
    pub fn new(ray: &Ray) -> Self {
        let (o, i, f) = (ray.origin(), ray.inv_dir(), far_inv(ray.inv_dir()));
        Self {
            org: [f32x4::splat(o.x), f32x4::splat(o.y), f32x4::splat(o.z)],
            inv: [f32x4::splat(i.x), f32x4::splat(i.y), f32x4::splat(i.z)],
            inv_far: [f32x4::splat(f.x), f32x4::splat(f.y), f32x4::splat(f.z)],
            neg: [i.x.is_sign_negative(), i.y.is_sign_negative(), i.z.is_sign_negative()],
        }
    }

    /// Entry distances of the four boxes and the mask of those hit within `[t_min, t_max]`
    /// (`t_max` the caller's limit, the closest hit widened); `valid` masks out empty slots.
    #[inline(always)]
    pub fn four_boxes(&self, boxes: &Boxes4, valid: u32, t_min: f32, t_max: f32) -> ([f32; 4], u32) {
        let (enter, exit) = self.lanes(&boxes.min, &boxes.max, t_min, t_max);
        let mask = enter.simd_le(exit).to_bitmask() & valid;
        (enter.to_array(), mask)
    }

    /// The entry and exit distances of four boxes given by their planes.
    #[inline(always)]
    pub(crate) fn lanes(&self, min: &[[f32; 4]; 3], max: &[[f32; 4]; 3], t_min: f32, t_max: f32) -> (f32x4, f32x4) {
        let mut enter = f32x4::splat(t_min);
        let mut exit = f32x4::splat(t_max);
        for axis in 0..3 {
            let (near, far) = if self.neg[axis] { (&max[axis], &min[axis]) } else { (&min[axis], &max[axis]) };
            let t0 = (f32x4::from(*near) - self.org[axis]) * self.inv[axis];
            let t1 = (f32x4::from(*far) - self.org[axis]) * self.inv_far[axis];
            enter = max_keep(t0, enter);
            exit = min_keep(t1, exit);
        }
        (enter, exit)
    }
}

/// One ray against the `W` child boxes of a wide node: what the wide walk asks of a kernel. Every
/// kernel computes the same slab distances with the same operations (a subtraction and a product
/// per plane, nothing fused, NaN skipped as in `max_keep`), so all of them return the same entries
/// and masks bit for bit: the choice of kernel (`crate::cpu`) changes the speed, never a result
/// or a count. Implemented here for four boxes (`Simd4`, `Scalar`) and in `slab8` for eight.
pub trait SlabKernel<const W: usize>: Copy {
    /// The ray as this kernel wants it, prepared once per ray.
    type Ray;
    fn prepare(self, ray: &Ray) -> Self::Ray;
    /// Entry distances of the `W` boxes and the mask of those hit within `[t_min, t_max]`;
    /// `valid` masks out empty slots.
    fn test(self, ray: &Self::Ray, boxes: &Boxes<W>, valid: u32, t_min: f32, t_max: f32) -> ([f32; W], u32);
}

/// Four lanes of the `wide` crate: SSE on x86-64, NEON on aarch64, plain arrays elsewhere.
#[derive(Clone, Copy, Debug, Default)]
pub struct Simd4;

impl SlabKernel<4> for Simd4 {
    type Ray = RayX4;
    #[inline(always)]
    fn prepare(self, ray: &Ray) -> RayX4 {
        RayX4::new(ray)
    }
    #[inline(always)]
    fn test(self, ray: &RayX4, boxes: &Boxes4, valid: u32, t_min: f32, t_max: f32) -> ([f32; 4], u32) {
        ray.four_boxes(boxes, valid, t_min, t_max)
    }
}

/// One box at a time with `OneRay`'s scalar test: the reference the SIMD kernels are tested
/// against, and the path for a CPU without SIMD.
#[derive(Clone, Copy, Debug, Default)]
pub struct Scalar;

impl<const W: usize> SlabKernel<W> for Scalar {
    type Ray = OneRay;
    #[inline(always)]
    fn prepare(self, ray: &Ray) -> OneRay {
        OneRay::new(ray)
    }
    #[inline(always)]
    fn test(self, ray: &OneRay, boxes: &Boxes<W>, valid: u32, t_min: f32, t_max: f32) -> ([f32; W], u32) {
        let mut enter = [0.0; W];
        let mut mask = 0;
        for (k, e) in enter.iter_mut().enumerate() {
            let (lo, hi) = boxes.planes(k);
            let (t0, t1) = ray.one_box(&lo, &hi, t_min, t_max);
            *e = t0;
            mask |= ((t0 <= t1) as u32) << k;
        }
        (enter, mask & valid)
    }
}
