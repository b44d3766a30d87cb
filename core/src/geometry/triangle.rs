//! Ray–triangle intersection: the handout's `rayIntersectShape` step. It returns the distance and
//! barycentrics only; turning them into a surface point is `Mesh::fill_intersection`.
//!
//! Barycentric convention (every test): the hit point is `(1-u-v)·v0 + u·v1 + v·v2`.
//! The accepted interval is `t_min <= t < t_max`: the strict upper bound makes a closest-hit query
//! keep the first of two hits at the same distance and keeps an occlusion ray from hitting the
//! surface at its far end.

#[cfg(target_arch = "x86_64")]
use super::avx512::packet::WatertightRay16;
#[cfg(target_arch = "x86_64")]
use super::packet8::WatertightRay8;
pub use super::shear::{Hits4, WatertightRay};
#[cfg(target_arch = "x86_64")]
use super::{slab8::Avx2, triangle8::Hits8};
use crate::geometry::avx512::lanes::Avx512;
use crate::geometry::avx512::leaf::Hits16;
use crate::geometry::ray::Ray;
use glam::{DVec3, Vec3};
#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::{__m256, __m512};
use wide::f32x4;

/// Distance and barycentrics of a ray–triangle hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleHit {
    pub t: f32,
    pub u: f32,
    pub v: f32,
}

/// A ray–triangle test with per-ray precomputation, used as a type parameter of the traversal so
/// the choice costs nothing per triangle.
pub trait TriangleIntersector: Copy + Send + Sync + 'static {
    /// Whether the 8-wide tree's leaves reach `intersect_group_coords` and its wider twins in this
    /// test's stored form (`stored_triangle`: v0, e1, e2 and the normal, twelve floats a triangle,
    /// coordinate by coordinate) rather than as their nine vertex coordinates.
    const STORED: bool = false;

    /// Data computed once per ray.
    type Prepared: Copy;
    fn prepare(ray: &Ray) -> Self::Prepared;
    fn intersect(p: &Self::Prepared, ray: &Ray, tri: &[Vec3; 3]) -> Option<TriangleHit>;

    /// Data computed once per group of four rays of a packet, for `intersect4`.
    type Prepared4: Copy;
    /// The setup of rays `base..base + 4` of `rays` (lanes past the end repeat the last ray).
    fn prepare4(rays: &[Ray], base: usize) -> Self::Prepared4;
    /// One triangle against the four rays, each within `[t_min, t_max)` of its lane: the mask
    /// of the lanes in `lanes` that hit, and their hits. Lane by lane the same result as
    /// `intersect` (packets must find exactly what single rays find).
    fn intersect4(p: &Self::Prepared4, t_min: f32x4, t_max: f32x4, lanes: u32, tri: &[Vec3; 3]) -> Hits4;

    /// `Prepared4` for a group of sixteen rays (AVX-512 packets, `avx512::packet`).
    #[cfg(target_arch = "x86_64")]
    type Prepared16: Copy;
    /// The setup of rays `base..base + 16` of `rays` (lanes past the end repeat the last ray).
    #[cfg(target_arch = "x86_64")]
    fn prepare16(k: Avx512, rays: &[Ray], base: usize) -> Self::Prepared16;
    /// `intersect4` for sixteen rays: lane by lane the same result as `intersect`.
    #[cfg(target_arch = "x86_64")]
    fn intersect16(
        k: Avx512,
        p: &Self::Prepared16,
        t_min: __m512,
        t_max: __m512,
        lanes: u32,
        tri: &[Vec3; 3],
    ) -> Hits16;

    /// `Prepared4` for a group of eight rays (AVX2 packets, `packet8`).
    #[cfg(target_arch = "x86_64")]
    type Prepared8: Copy;
    /// The setup of rays `base..base + 8` of `rays` (lanes past the end repeat the last ray).
    #[cfg(target_arch = "x86_64")]
    fn prepare8(k: Avx2, rays: &[Ray], base: usize) -> Self::Prepared8;
    /// `intersect4` for eight rays: lane by lane the same result as `intersect`.
    #[cfg(target_arch = "x86_64")]
    fn intersect8(k: Avx2, p: &Self::Prepared8, t_min: __m256, t_max: __m256, lanes: u32, tri: &[Vec3; 3]) -> Hits8;

    /// One ray against up to four triangles (`tris.len() <= 4`): lane k of the result is
    /// `intersect(p, ray, &tris[k])`, bit for bit. The watertight test does the four in one SIMD
    /// pass (`triangle4.rs`, the wide BVHs' leaves); this default runs `intersect` lane by lane.
    #[inline(always)]
    fn intersect_group(p: &Self::Prepared, ray: &Ray, tris: &[[Vec3; 3]]) -> Hits4 {
        let mut hits = Hits4 { mask: 0, t: [0.0; 4], u: [0.0; 4], v: [0.0; 4] };
        for (k, tri) in tris.iter().enumerate() {
            if let Some(h) = Self::intersect(p, ray, tri) {
                hits.mask |= 1 << k;
                (hits.t[k], hits.u[k], hits.v[k]) = (h.t, h.u, h.v);
            }
        }
        hits
    }

    /// `intersect_group` of triangles `4g..4g + 4` (those below `count`) of a leaf stored
    /// coordinate by coordinate (`coords`: the `count` values of v0.x, then of v0.y, …, v2.z; the
    /// wide layouts' leaves). The watertight test loads its lanes straight from there; this
    /// default gathers the triangles and runs `intersect_group`.
    #[inline(always)]
    fn intersect_group_coords(p: &Self::Prepared, ray: &Ray, coords: &[f32], count: usize, g: usize) -> Hits4 {
        let n = (count - 4 * g).min(4);
        let tri = |k: usize| super::leaf_triangle(coords, count, 4 * g + k);
        let tris = [tri(0), tri(1.min(n - 1)), tri(2.min(n - 1)), tri(3.min(n - 1))];
        Self::intersect_group(p, ray, &tris[..n])
    }

    /// `intersect_group_coords` of triangles `16g..16g + 16` (those below `count`) at once: lane k
    /// of the result is triangle `16g + k`'s `intersect`, bit for bit. The watertight test and the
    /// stored form do them in one AVX-512 pass (`avx512::leaf`, `avx512::stored_leaf`); this
    /// default runs two groups of eight (`intersect_group8_coords`: Möller–Trumbore's AVX2 pass;
    /// four groups of four measured 0.45× the AVX2 watertight walk on AVX-512, BENCHMARKS.md).
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn intersect_group16_coords(
        k: Avx512,
        p: &Self::Prepared,
        ray: &Ray,
        coords: &[f32],
        count: usize,
        g: usize,
    ) -> Hits16 {
        let mut hits = Hits16::NONE;
        for q in (2 * g..2 * g + 2).take_while(|&q| 8 * q < count) {
            let h = Self::intersect_group8_coords(k.avx2(), p, ray, coords, count, q);
            let at = 8 * (q - 2 * g);
            hits.mask |= h.mask << at;
            hits.t[at..at + 8].copy_from_slice(&h.t);
            hits.u[at..at + 8].copy_from_slice(&h.u);
            hits.v[at..at + 8].copy_from_slice(&h.v);
        }
        hits
    }

    /// `intersect_group_coords` of triangles `8g..8g + 8` (those below `count`) at once: lane k of
    /// the result is triangle `8g + k`'s `intersect`, bit for bit. The watertight test does them in
    /// one AVX2 pass (`triangle8`); this default runs two groups of four.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn intersect_group8_coords(
        _: Avx2,
        p: &Self::Prepared,
        ray: &Ray,
        coords: &[f32],
        count: usize,
        g: usize,
    ) -> Hits8 {
        let mut hits = Hits8::NONE;
        for q in (2 * g..2 * g + 2).take_while(|&q| 4 * q < count) {
            let h = Self::intersect_group_coords(p, ray, coords, count, q);
            let at = 4 * (q - 2 * g);
            hits.mask |= h.mask << at;
            hits.t[at..at + 4].copy_from_slice(&h.t);
            hits.u[at..at + 4].copy_from_slice(&h.u);
            hits.v[at..at + 4].copy_from_slice(&h.v);
        }
        hits
    }
}

/// Watertight ray–triangle intersection. Woop, Benthin & Wald, "Watertight Ray/Triangle
/// Intersection", JCGT 2(1), 2013. The ray is sheared so it points along +z; the 2D edge functions
/// are then evaluated exactly consistently for a shared edge, and recomputed in double precision
/// when one of them is exactly zero (the paper's fallback), so rays through edges and vertices hit.
#[derive(Clone, Copy, Debug, Default)]
pub struct Watertight;

impl TriangleIntersector for Watertight {
    type Prepared = WatertightRay;

    #[inline(always)]
    fn prepare(ray: &Ray) -> WatertightRay {
        // kz: the axis of the direction's largest component; kx, ky the next two, swapped when
        // that component is negative, to keep the winding of the sheared triangle independent
        // of the direction's sign. Chosen without branches (random directions would mispredict
        // them on every ray) from a table of the six cases.
        const AXES: [[usize; 3]; 6] = [[1, 2, 0], [2, 1, 0], [2, 0, 1], [0, 2, 1], [0, 1, 2], [1, 0, 2]];
        const UNIT: [Vec3; 4] = [Vec3::X, Vec3::Y, Vec3::Z, Vec3::ZERO];
        let d = ray.dir();
        let a = d.abs();
        let x_largest = (a.x >= a.y) & (a.x >= a.z);
        let kz = if x_largest { 0 } else { 2 - (a.y >= a.z) as usize };
        let dd = d.extend(0.0).to_array();
        let [kx, ky, kz] = AXES[2 * kz + (dd[kz & 3] < 0.0) as usize].map(|k| k & 3);
        let (sx, sy, sz) = (dd[kx] / dd[kz], dd[ky] / dd[kz], 1.0 / dd[kz]);
        let rz_axis = UNIT[kz];
        WatertightRay { rx: UNIT[kx] - rz_axis * sx, ry: UNIT[ky] - rz_axis * sy, rz: rz_axis * sz }
    }

    #[inline(always)]
    fn intersect(p: &WatertightRay, ray: &Ray, tri: &[Vec3; 3]) -> Option<TriangleHit> {
        let o = ray.origin();
        let a = tri[0] - o;
        let b = tri[1] - o;
        let c = tri[2] - o;
        let (ax, ay) = (a.dot(p.rx), a.dot(p.ry));
        let (bx, by) = (b.dot(p.rx), b.dot(p.ry));
        let (cx, cy) = (c.dot(p.rx), c.dot(p.ry));
        let mut u = cx * by - cy * bx;
        let mut v = ax * cy - ay * cx;
        let mut w = bx * ay - by * ax;
        if u == 0.0 || v == 0.0 || w == 0.0 {
            let (ax, ay, bx, by, cx, cy) = (ax as f64, ay as f64, bx as f64, by as f64, cx as f64, cy as f64);
            u = (cx * by - cy * bx) as f32;
            v = (ax * cy - ay * cx) as f32;
            w = (bx * ay - by * ax) as f32;
        }
        // Inside when all three edge functions share a sign (both faces are hit).
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v + w;
        if det == 0.0 {
            return None;
        }
        let t_scaled = u * a.dot(p.rz) + v * b.dot(p.rz) + w * c.dot(p.rz);
        let inv_det = 1.0 / det;
        let t = t_scaled * inv_det;
        if !(t >= ray.t_min && t < ray.t_max) {
            return None;
        }
        // u, v, w weight v0, v1, v2: in our convention u ↔ v1 and v ↔ v2.
        Some(TriangleHit { t, u: v * inv_det, v: w * inv_det })
    }

    #[inline(always)]
    fn intersect_group(p: &WatertightRay, ray: &Ray, tris: &[[Vec3; 3]]) -> Hits4 {
        super::triangle4::watertight_group(p, ray, tris)
    }

    #[inline(always)]
    fn intersect_group_coords(p: &WatertightRay, ray: &Ray, coords: &[f32], count: usize, g: usize) -> Hits4 {
        super::triangle4::watertight_group_coords(p, ray, coords, count, g)
    }

    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn intersect_group16_coords(
        k: Avx512,
        p: &WatertightRay,
        ray: &Ray,
        coords: &[f32],
        count: usize,
        g: usize,
    ) -> Hits16 {
        // SAFETY: `k` proves the CPU has AVX-512F/VL.
        unsafe { super::avx512::watertight_leaf16(k, p, ray, coords, count, g) }
    }

    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn intersect_group8_coords(k: Avx2, p: &WatertightRay, ray: &Ray, coords: &[f32], count: usize, g: usize) -> Hits8 {
        // SAFETY: `k` proves the CPU has AVX2.
        unsafe { super::triangle8::watertight_leaf8(k, p, ray, coords, count, g) }
    }

    type Prepared4 = WatertightRay4;

    #[inline(always)]
    fn prepare4(rays: &[Ray], base: usize) -> WatertightRay4 {
        let last = rays.len() - 1;
        let mut rows = [[[0f32; 4]; 3]; 4]; // [origin, rx, ry, rz][axis][lane]
        for k in 0..4 {
            let r = &rays[(base + k).min(last)];
            let w = WatertightRay::with_branches(r.dir());
            for (row, v) in rows.iter_mut().zip([r.origin(), w.rx, w.ry, w.rz]) {
                for axis in 0..3 {
                    row[axis][k] = v[axis];
                }
            }
        }
        // Written out: `array::map` here was left out of line, a twentieth of a packet's time.
        let v = |row: &[[f32; 4]; 3]| [f32x4::from(row[0]), f32x4::from(row[1]), f32x4::from(row[2])];
        WatertightRay4 { org: v(&rows[0]), rx: v(&rows[1]), ry: v(&rows[2]), rz: v(&rows[3]) }
    }

    /// `intersect`'s arithmetic in the same order, one lane per ray (SSE and NEON round each
    /// operation as scalar code does, and nothing is fused), so each lane's result is the scalar
    /// one bit for bit; a lane with an exactly-zero edge function takes the same double-precision
    /// fallback, lane by lane.
    #[inline(always)]
    fn intersect4(p: &WatertightRay4, t_min: f32x4, t_max: f32x4, lanes: u32, tri: &[Vec3; 3]) -> Hits4 {
        let rel = |v: Vec3| [f32x4::splat(v.x) - p.org[0], f32x4::splat(v.y) - p.org[1], f32x4::splat(v.z) - p.org[2]];
        // glam's dot: (x·x' + y·y') + z·z'.
        let dot = |a: &[f32x4; 3], r: &[f32x4; 3]| a[0] * r[0] + a[1] * r[1] + a[2] * r[2];
        let (a, b, c) = (rel(tri[0]), rel(tri[1]), rel(tri[2]));
        let (ax, ay) = (dot(&a, &p.rx), dot(&a, &p.ry));
        let (bx, by) = (dot(&b, &p.rx), dot(&b, &p.ry));
        let (cx, cy) = (dot(&c, &p.rx), dot(&c, &p.ry));
        let z = [dot(&a, &p.rz), dot(&b, &p.rz), dot(&c, &p.rz)];
        super::triangle4::edge_test4([ax, ay, bx, by, cx, cy], z, t_min, t_max, lanes)
    }

    #[cfg(target_arch = "x86_64")]
    type Prepared8 = WatertightRay8;

    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn prepare8(k: Avx2, rays: &[Ray], base: usize) -> WatertightRay8 {
        // SAFETY: `k` proves the CPU has AVX2 and FMA.
        unsafe { WatertightRay8::new(k, rays, base) }
    }

    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn intersect8(k: Avx2, p: &WatertightRay8, t_min: __m256, t_max: __m256, lanes: u32, tri: &[Vec3; 3]) -> Hits8 {
        // SAFETY: `k` proves the CPU has AVX2 and FMA.
        unsafe { p.intersect(k, t_min, t_max, lanes, tri) }
    }

    #[cfg(target_arch = "x86_64")]
    type Prepared16 = WatertightRay16;

    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn prepare16(k: Avx512, rays: &[Ray], base: usize) -> WatertightRay16 {
        // SAFETY: `k` proves the CPU has AVX-512F/VL.
        unsafe { WatertightRay16::new(k, rays, base) }
    }

    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn intersect16(
        k: Avx512,
        p: &WatertightRay16,
        t_min: __m512,
        t_max: __m512,
        lanes: u32,
        tri: &[Vec3; 3],
    ) -> Hits16 {
        // SAFETY: `k` proves the CPU has AVX-512F/VL.
        unsafe { p.intersect(k, t_min, t_max, lanes, tri) }
    }
}

/// Four rays' `WatertightRay` rows and origins, lane k for ray k.
#[derive(Clone, Copy, Debug)]
pub struct WatertightRay4 {
    org: [f32x4; 3],
    rx: [f32x4; 3],
    ry: [f32x4; 3],
    rz: [f32x4; 3],
}

/// The packet items of a test without a per-ray setup that packets do not vectorise
/// (`Prepared4`, `Prepared8`, `Prepared16` and their tests): its rays lane by lane.
macro_rules! lane_by_lane_packets {
    () => {
        /// The four rays themselves: the test is not vectorised for packets (the
        /// fastest preset's packets run the watertight test), so `intersect4` runs it lane by lane.
        type Prepared4 = [Ray; 4];

        fn prepare4(rays: &[Ray], base: usize) -> [Ray; 4] {
            std::array::from_fn(|k| rays[(base + k).min(rays.len() - 1)])
        }

        fn intersect4(rays: &[Ray; 4], t_min: f32x4, t_max: f32x4, lanes: u32, tri: &[Vec3; 3]) -> Hits4 {
            let (mask, t, u, v) = lane_by_lane::<Self, _>(rays, t_min.to_array(), t_max.to_array(), lanes, tri);
            Hits4 { mask, t, u, v }
        }

        #[cfg(target_arch = "x86_64")]
        type Prepared8 = [Ray; 8];

        #[cfg(target_arch = "x86_64")]
        fn prepare8(_: Avx2, rays: &[Ray], base: usize) -> [Ray; 8] {
            std::array::from_fn(|k| rays[(base + k).min(rays.len() - 1)])
        }

        /// Lane by lane, as `intersect4`.
        #[cfg(target_arch = "x86_64")]
        fn intersect8(_: Avx2, rays: &[Ray; 8], t_min: __m256, t_max: __m256, lanes: u32, tri: &[Vec3; 3]) -> Hits8 {
            // SAFETY: `__m256` and `[f32; 8]` have the same size, and every bit pattern is a float.
            let (t_min, t_max): ([f32; 8], [f32; 8]) = unsafe {
                (std::mem::transmute::<__m256, [f32; 8]>(t_min), std::mem::transmute::<__m256, [f32; 8]>(t_max))
            };
            let (mask, t, u, v) = lane_by_lane::<Self, _>(rays, t_min, t_max, lanes, tri);
            Hits8 { mask, t, u, v }
        }

        #[cfg(target_arch = "x86_64")]
        type Prepared16 = [Ray; 16];

        #[cfg(target_arch = "x86_64")]
        fn prepare16(_: Avx512, rays: &[Ray], base: usize) -> [Ray; 16] {
            std::array::from_fn(|k| rays[(base + k).min(rays.len() - 1)])
        }

        /// Lane by lane, as `intersect4`.
        #[cfg(target_arch = "x86_64")]
        fn intersect16(
            _: Avx512,
            rays: &[Ray; 16],
            t_min: __m512,
            t_max: __m512,
            lanes: u32,
            tri: &[Vec3; 3],
        ) -> Hits16 {
            // SAFETY: `__m512` and `[f32; 16]` have the same size, and every bit pattern is a float.
            let (t_min, t_max): ([f32; 16], [f32; 16]) = unsafe {
                (std::mem::transmute::<__m512, [f32; 16]>(t_min), std::mem::transmute::<__m512, [f32; 16]>(t_max))
            };
            let (mask, t, u, v) = lane_by_lane::<Self, _>(rays, t_min, t_max, lanes, tri);
            Hits16 { mask, t, u, v }
        }
    };
}
pub(super) use lane_by_lane_packets;

/// Möller–Trumbore ray–triangle intersection. Möller & Trumbore, "Fast, Minimum Storage
/// Ray/Triangle Intersection", JGT 2(1), 1997. A ray (nearly) parallel to the plane is rejected
/// with a tolerance relative to the edge and direction lengths, so the test is scale-independent.
#[derive(Clone, Copy, Debug, Default)]
pub struct MollerTrumbore;

/// A group of `N` rays one lane at a time, for the tests without a per-ray setup that packets do
/// not vectorise: for the lanes in `lanes`, ray k within `[t_min[k], t_max[k])` against `tri`;
/// the mask of the hits and their `t`, `u`, `v`.
#[allow(clippy::type_complexity)]
pub(super) fn lane_by_lane<T: TriangleIntersector<Prepared = ()>, const N: usize>(
    rays: &[Ray; N],
    t_min: [f32; N],
    t_max: [f32; N],
    lanes: u32,
    tri: &[Vec3; 3],
) -> (u32, [f32; N], [f32; N], [f32; N]) {
    let (mut mask, mut t, mut u, mut v) = (0, [0.0; N], [0.0; N], [0.0; N]);
    let mut m = lanes;
    while m != 0 {
        let k = m.trailing_zeros() as usize;
        m &= m - 1;
        let mut ray = rays[k];
        (ray.t_min, ray.t_max) = (t_min[k], t_max[k]);
        if let Some(h) = T::intersect(&(), &ray, tri) {
            mask |= 1 << k;
            (t[k], u[k], v[k]) = (h.t, h.u, h.v);
        }
    }
    (mask, t, u, v)
}

impl TriangleIntersector for MollerTrumbore {
    type Prepared = ();

    #[inline]
    fn prepare(_ray: &Ray) {}

    #[inline(always)]
    fn intersect(_: &(), ray: &Ray, tri: &[Vec3; 3]) -> Option<TriangleHit> {
        let d = ray.dir();
        let e1 = tri[1] - tri[0];
        let e2 = tri[2] - tri[0];
        let pv = d.cross(e2);
        let det = e1.dot(pv);
        // |det| = |d|·|e1 × e2|·|cos|; reject below 1e-7 of its largest possible value.
        let scale = d.length() * e1.length() * e2.length();
        if !(det.abs() > 1e-7 * scale) {
            return None;
        }
        let inv_det = 1.0 / det;
        let s = ray.origin() - tri[0];
        let u = s.dot(pv) * inv_det;
        if !(0.0..=1.0).contains(&u) {
            return None;
        }
        let q = s.cross(e1);
        let v = d.dot(q) * inv_det;
        if v < 0.0 || u + v > 1.0 || v.is_nan() {
            return None;
        }
        let t = e2.dot(q) * inv_det;
        if !(t >= ray.t_min && t < ray.t_max) {
            return None;
        }
        Some(TriangleHit { t, u, v })
    }

    /// A leaf's triangles in one AVX2 pass of eight, as the watertight test's (`triangle8`), so
    /// the two tests can be raced on one tree with the same loads.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn intersect_group8_coords(k: Avx2, _: &(), ray: &Ray, coords: &[f32], count: usize, g: usize) -> Hits8 {
        // SAFETY: `k` proves the CPU has AVX2.
        unsafe { super::triangle8::moller_trumbore_leaf8(k, ray, coords, count, g) }
    }

    lane_by_lane_packets!();
}

/// Twice the triangle's area, in double precision (used to detect degenerate triangles).
pub fn double_area(tri: &[Vec3; 3]) -> f64 {
    let a = tri[0].as_dvec3();
    let b: DVec3 = tri[1].as_dvec3() - a;
    let c: DVec3 = tri[2].as_dvec3() - a;
    b.cross(c).length()
}

#[cfg(test)]
#[path = "triangle_tests.rs"]
mod tests;
