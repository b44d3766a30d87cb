//! Ray packets: up to four coherent rays (a 2×2 block of pixels) traced together through the
//! binary BVH, each box tested against all four rays with one SIMD slab test. Wald, Slusallek,
//! Benthin & Wagner, "Interactive Rendering with Coherent Ray Tracing" (EG 2001).
//!
//! Neighbouring primary rays enter nearly the same nodes, so a node is fetched and its box planes
//! loaded once per packet instead of once per ray. A lane leaves the packet's work as soon as a box
//! misses it (per-lane masks); leaves test their triangles only against the lanes that reached them,
//! with the same triangle test as single rays, so every lane gets the hit it would get alone (the
//! same distance; between triangles hit at exactly the same distance either may be reported).
//!
//! Packets are for the renderer's uncounted views only (`bvhscope render` of normals or depth):
//! heatmaps, and the app, which always counts for its hover read-out, trace single rays.
//! Incoherent rays would leave a packet half empty at once, so they are traced one by one.
//!
//! The 4-wide BVH already spends its SIMD lanes on four child boxes per ray. Packets over it (four
//! child boxes × four rays per node) were measured slower than its single rays (bunny, 1024²
//! primary frame: 10.3 against 12.7 MRays/s), so it traces packets ray by ray (the trait's default).

use super::node::{Bvh, TRAVERSAL_STACK_SIZE};
use super::simd::{max_keep, min_keep};
use super::stack::TraversalStack;
use super::{Hit, TraceOptions};
use crate::geometry::{Aabb, MollerTrumbore, Ray, TriangleHit, TriangleIntersector, TriangleTest, Watertight};
use wide::f32x4;

/// Rays per packet.
pub const PACKET: usize = 4;

/// Four rays in SIMD form (lane k = ray k). Inactive lanes have `t_max = -inf`, so every box
/// misses them.
struct Packet {
    org: [f32x4; 3],
    inv: [f32x4; 3],
    /// Per axis, all-ones lanes where the direction is negative (the far plane is `min`).
    neg: [f32x4; 3],
    t_min: f32x4,
}

impl Packet {
    fn new(rays: &[Ray; PACKET]) -> Self {
        let lanes = |f: &dyn Fn(&Ray) -> f32| f32x4::from([f(&rays[0]), f(&rays[1]), f(&rays[2]), f(&rays[3])]);
        let inv = [lanes(&|r| r.inv_dir().x), lanes(&|r| r.inv_dir().y), lanes(&|r| r.inv_dir().z)];
        // The scalar slab test picks planes by `is_sign_negative`; `< 0` agrees for every valid
        // ray (a -0 component gives -inf; an invalid ray has t_max = -inf and misses anyway).
        let sign = |v: f32x4| v.simd_lt(f32x4::ZERO);
        Self {
            org: [lanes(&|r| r.origin().x), lanes(&|r| r.origin().y), lanes(&|r| r.origin().z)],
            neg: [sign(inv[0]), sign(inv[1]), sign(inv[2])],
            inv,
            t_min: lanes(&|r| r.t_min),
        }
    }

    /// Lanes whose ray hits the box `[lo, hi]` (per axis, splatted) within [t_min, t_max], and the
    /// entry distances. The arithmetic is the scalar slab test's, lane by lane.
    #[inline(always)]
    fn hit(&self, lo: [f32; 3], hi: [f32; 3], t_max: f32x4) -> (u32, f32x4) {
        let mut enter = self.t_min;
        let mut exit = t_max;
        for axis in 0..3 {
            let ta = (f32x4::splat(lo[axis]) - self.org[axis]) * self.inv[axis];
            let tb = (f32x4::splat(hi[axis]) - self.org[axis]) * self.inv[axis];
            let near = self.neg[axis].bitselect(tb, ta);
            let far = self.neg[axis].bitselect(ta, tb);
            enter = max_keep(near, enter);
            exit = min_keep(far, exit);
        }
        (enter.simd_le(exit).to_bitmask(), enter)
    }

    #[inline(always)]
    fn hit_box(&self, b: &Aabb, t_max: f32x4) -> u32 {
        self.hit(b.min.to_array(), b.max.to_array(), t_max).0
    }
}

/// Per-lane state of the triangle tests: the hit so far and the ray's prepared test.
struct Lanes<T: TriangleIntersector> {
    t_max: [f32; PACKET],
    prepared: [Option<T::Prepared>; PACKET],
    best: [Option<(usize, TriangleHit)>; PACKET],
}

impl<T: TriangleIntersector> Lanes<T> {
    fn new(rays: &[Ray; PACKET], active: u8) -> Self {
        Self {
            t_max: std::array::from_fn(|k| if active & (1 << k) != 0 { rays[k].t_max } else { f32::NEG_INFINITY }),
            prepared: [None; PACKET],
            best: [None; PACKET],
        }
    }

    /// Test triangles `first..first + count` of `tris` against the lanes in `mask`; true when
    /// some lane found a nearer hit.
    #[inline(always)]
    fn leaf(
        &mut self,
        rays: &mut [Ray; PACKET],
        mask: u32,
        tris: &[[glam::Vec3; 3]],
        first: usize,
        count: usize,
    ) -> bool {
        let mut found = false;
        for (i, tri) in tris[first..first + count].iter().enumerate() {
            let mut m = mask;
            while m != 0 {
                let k = m.trailing_zeros() as usize;
                m &= m - 1;
                let ray = &mut rays[k];
                if let Some(h) = T::intersect(self.prepared[k].get_or_insert_with(|| T::prepare(ray)), ray, tri) {
                    ray.t_max = h.t;
                    self.t_max[k] = h.t;
                    self.best[k] = Some((first + i, h));
                    found = true;
                }
            }
        }
        found
    }

    fn t_max(&self) -> f32x4 {
        f32x4::from(self.t_max)
    }

    fn hits(&self, prim_ids: &[u32]) -> [Option<Hit>; PACKET] {
        self.best.map(|b| b.map(|(i, h)| Hit { t: h.t, u: h.u, v: h.v, prim: prim_ids[i] }))
    }
}

impl Bvh {
    fn closest4<T: TriangleIntersector>(&self, rays: &mut [Ray; PACKET], active: u8) -> [Option<Hit>; PACKET] {
        let nodes = &self.nodes[..];
        let packet = Packet::new(rays);
        let mut lanes = Lanes::<T>::new(rays, active);
        if active == 0 {
            return [None; PACKET];
        }
        // Near child by the first active ray's direction on the split axis (the rays are coherent,
        // so it is near for nearly all of them; the order only affects speed, not the result).
        let lead = rays[active.trailing_zeros() as usize].inv_dir();
        let dir_neg = [lead.x.is_sign_negative(), lead.y.is_sign_negative(), lead.z.is_sign_negative()];
        let mut stack = TraversalStack::<TRAVERSAL_STACK_SIZE>::new();
        let mut t_max = lanes.t_max();
        let mut current = 0usize;
        loop {
            let node = &nodes[current];
            // Each node's box is tested when it is visited, against the rays' current t_max.
            let mask = packet.hit_box(&node.bounds, t_max);
            if mask != 0 {
                if !node.is_leaf() {
                    let left = node.index as usize;
                    let (near, far) = if dir_neg[node.axis as usize] { (left + 1, left) } else { (left, left + 1) };
                    stack.push((far as u32, 0.0));
                    current = near;
                    continue;
                }
                if lanes.leaf(rays, mask, &self.tris, node.index as usize, node.count as usize) {
                    t_max = lanes.t_max();
                }
            }
            match stack.pop() {
                Some((n, _)) => current = n as usize,
                None => break,
            }
        }
        lanes.hits(&self.prim_ids)
    }

    pub(crate) fn closest_hit4(
        &self,
        rays: &mut [Ray; PACKET],
        active: u8,
        opts: TraceOptions,
    ) -> [Option<Hit>; PACKET] {
        match opts.test {
            TriangleTest::Watertight => self.closest4::<Watertight>(rays, active),
            TriangleTest::MollerTrumbore => self.closest4::<MollerTrumbore>(rays, active),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::{Accelerator, AnyBvh, BuildParams, Layout, NoStats, SplitStrategy};
    use crate::mesh::generate::{builtin_scene, torus_knot};
    use crate::mesh::Mesh;
    use crate::render::Camera;
    use glam::Vec3;

    /// Packets of `rays` (in fours) against single rays: same hit or miss, same distance, and
    /// inactive lanes untouched.
    fn agree(bvh: &AnyBvh, rays: &[Ray], active: u8, what: &str) -> usize {
        let mut hits = 0;
        for (c, chunk) in rays.chunks_exact(PACKET).enumerate() {
            let mut four: [Ray; PACKET] = chunk.try_into().unwrap();
            let before = four;
            let opts = TraceOptions::default();
            let got = bvh.closest_hit4(&mut four, active, opts);
            for k in 0..PACKET {
                if active & (1 << k) == 0 {
                    assert_eq!(got[k], None, "{what}: inactive lane {k} of packet {c}");
                    assert_eq!(four[k], before[k], "{what}: inactive lane {k} of packet {c} left alone");
                    continue;
                }
                let mut single = before[k];
                let want = bvh.closest_hit(&mut single, opts, &mut NoStats);
                assert_eq!(got[k].map(|h| h.t), want.map(|h| h.t), "{what}: lane {k} of packet {c}");
                assert_eq!(four[k].t_max, single.t_max, "{what}: lane {k} of packet {c}: t_max");
                hits += got[k].is_some() as usize;
            }
        }
        hits
    }

    fn primary_blocks(mesh: &Mesh, size: u32) -> Vec<Ray> {
        let cam = Camera::framing_from(&mesh.bounds(), size, size, Vec3::new(0.45, 0.35, 1.0), 45.0);
        let g = cam.ray_gen();
        let mut rays = Vec::new();
        for by in (0..size).step_by(2) {
            for bx in (0..size).step_by(2) {
                rays.extend([(0, 0), (1, 0), (0, 1), (1, 1)].map(|(dx, dy)| g.pixel_ray(bx + dx, by + dy)));
            }
        }
        rays
    }

    /// Rays in every direction from points around the mesh: packets whose lanes diverge at once.
    fn scattered(mesh: &Mesh, count: usize) -> Vec<Ray> {
        let (c, r) = (mesh.bounds().center(), mesh.bounds().extent().length());
        let mut s = 0x2545_F491_4F6C_DD1Du64;
        let mut rnd = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 40) as f32 / (1u64 << 24) as f32 - 0.5
        };
        (0..count)
            .map(|_| {
                let o = c + Vec3::new(rnd(), rnd(), rnd()) * r;
                let d = Vec3::new(rnd(), rnd(), rnd()).normalize_or(Vec3::X);
                Ray::new(o, d)
            })
            .collect()
    }

    /// Axis-aligned rays, some with zero direction components and origins on box planes: the slab
    /// test's NaN and infinity cases, lane by lane.
    fn axis_aligned(mesh: &Mesh) -> Vec<Ray> {
        let b = mesh.bounds();
        let mut rays = Vec::new();
        for i in 0..64 {
            let f = i as f32 / 63.0;
            let p = b.min + (b.max - b.min) * f;
            rays.push(Ray::new(Vec3::new(p.x, p.y, b.max.z + 1.0), Vec3::NEG_Z));
            rays.push(Ray::new(Vec3::new(b.min.x - 1.0, p.y, p.z), Vec3::X));
            rays.push(Ray::new(Vec3::new(b.min.x, b.min.y - 1.0, p.z), Vec3::Y));
            rays.push(Ray::new(Vec3::new(p.x, b.max.y, b.min.z - 1.0), Vec3::Z));
        }
        rays
    }

    #[test]
    fn packets_find_what_single_rays_find() {
        for mesh in [builtin_scene(), torus_knot(2, 3, 0.3, 256, 16)] {
            for layout in Layout::ALL {
                for strategy in SplitStrategy::ALL {
                    let bvh = AnyBvh::build(&mesh, &BuildParams { layout, ..BuildParams::with_strategy(strategy) });
                    let what = format!("{} {strategy:?} {layout:?}", mesh.name);
                    let hits = agree(&bvh, &primary_blocks(&mesh, 64), 0b1111, &what);
                    assert!(hits > 200 && hits < 64 * 64, "{what}: the frame both hits and misses ({hits})");
                    assert!(agree(&bvh, &scattered(&mesh, 2048), 0b1111, &what) > 0);
                    assert!(agree(&bvh, &axis_aligned(&mesh), 0b1111, &what) > 0);
                    for active in [0b0001, 0b1000, 0b0110, 0b1011, 0] {
                        agree(&bvh, &primary_blocks(&mesh, 32), active, &what);
                    }
                }
            }
        }
    }

    #[test]
    fn packets_keep_the_rays_intervals() {
        let mesh = builtin_scene();
        let bvh = AnyBvh::build(&mesh, &BuildParams::default());
        // Segments that stop short of the surface, or start beyond it, must miss as single rays do.
        let rays: Vec<Ray> = primary_blocks(&mesh, 32)
            .into_iter()
            .enumerate()
            .map(|(i, r)| match i % 3 {
                0 => Ray::segment(r.origin(), r.dir(), 0.0, 1e-3),
                1 => Ray::segment(r.origin(), r.dir(), 1e6, f32::INFINITY),
                _ => r,
            })
            .collect();
        let hits = agree(&bvh, &rays, 0b1111, "segments");
        assert!(hits > 0);
    }

    #[test]
    fn an_empty_bvh_misses_every_lane() {
        let empty = Mesh::from_triangles("empty", vec![], vec![]);
        for layout in Layout::ALL {
            let bvh = AnyBvh::build(&empty, &BuildParams { layout, ..BuildParams::default() });
            let mut rays = [Ray::new(Vec3::ZERO, Vec3::X); PACKET];
            assert_eq!(bvh.closest_hit4(&mut rays, 0b1111, TraceOptions::default()), [None; PACKET]);
        }
    }
}
