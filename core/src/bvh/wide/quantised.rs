//! EXPERIMENT (issue 25): 8-wide nodes with child boxes quantised to 8 bits per plane relative to
//! the node's own box (Ylitie, Karras & Laine, "Efficient Incoherent Ray Traversal on GPUs Through
//! Compressed Wide BVHs", HPG 2017; Embree's compressed BVH8 nodes): 128 bytes instead of 256.
//! The walk is `traverse.rs`'s, the same leaves; only the node and its box decode differ, so the
//! two can be timed against each other.

use super::{ChildRef, WideBvh};
use crate::bvh::simd::prefetch;
use crate::bvh::stack::TraversalStack;
use crate::bvh::traverse::test_triangles_grouped;
use crate::bvh::{Hit, TraversalStats};
use crate::geometry::slab::widen;
use crate::geometry::{Ray, Watertight};

/// A quantised 8-wide node: plane p of a child decodes to `q · scale + origin` (one FMA, the same
/// rounding here and in the kernel); minima rounded down and maxima up, so a decoded box holds its
/// child's.
#[repr(C, align(64))]
#[derive(Clone, Copy, Debug)]
pub struct QNode8 {
    pub origin: [f32; 3],
    pub scale: [f32; 3],
    pub lo: [[u8; 8]; 3],
    pub hi: [[u8; 8]; 3],
    pub child: [u32; 8],
    pub count: [u8; 8],
    pub valid: u8,
}

const _: () = assert!(std::mem::size_of::<QNode8>() == 128);

fn decode(q: u8, scale: f32, origin: f32) -> f32 {
    (q as f32).mul_add(scale, origin)
}

/// The nodes of `bvh`, quantised.
pub fn quantise(bvh: &WideBvh<8>) -> Vec<QNode8> {
    bvh.nodes
        .iter()
        .map(|n| {
            let mut q = QNode8 {
                origin: [0.0; 3],
                scale: [1.0; 3],
                lo: [[255; 8]; 3],
                hi: [[0; 8]; 3],
                child: n.child,
                count: n.count,
                valid: n.valid,
            };
            for axis in 0..3 {
                let lo_all = n.slots().map(|s| n.boxes.min[axis][s]).fold(f32::INFINITY, f32::min);
                let hi_all = n.slots().map(|s| n.boxes.max[axis][s]).fold(f32::NEG_INFINITY, f32::max);
                if !(lo_all <= hi_all) {
                    continue;
                }
                // A power of two, so q · scale is exact, large enough that 255 reaches the top.
                let mut scale = f32::MIN_POSITIVE;
                let step = (hi_all - lo_all) / 255.0;
                if step > scale {
                    scale = 2f32.powi(step.log2().ceil() as i32);
                }
                while decode(255, scale, lo_all) < hi_all {
                    scale *= 2.0;
                }
                q.origin[axis] = lo_all;
                q.scale[axis] = scale;
                for s in n.slots() {
                    let (lo, hi) = (n.boxes.min[axis][s], n.boxes.max[axis][s]);
                    let mut a = ((lo - lo_all) / scale).floor().clamp(0.0, 255.0) as u8;
                    while a > 0 && decode(a, scale, lo_all) > lo {
                        a -= 1;
                    }
                    let mut b = ((hi - lo_all) / scale).ceil().clamp(0.0, 255.0) as u8;
                    while b < 255 && decode(b, scale, lo_all) < hi {
                        b += 1;
                    }
                    q.lo[axis][s] = a;
                    q.hi[axis][s] = b;
                }
            }
            q
        })
        .collect()
}

#[cfg(target_arch = "x86_64")]
impl WideBvh<8> {
    /// The closest hit walking `nodes` (this tree's, quantised). AVX2 only.
    ///
    /// # Safety
    /// The CPU must have AVX2 and FMA.
    #[target_feature(enable = "avx2,fma,popcnt,bmi1,bmi2,lzcnt")]
    pub unsafe fn trace_quantised<S: TraversalStats>(&self, nodes: &[QNode8], ray: &mut Ray, stats: &mut S) -> Option<Hit> {
        use std::arch::x86_64::*;
        if self.prim_ids.is_empty() || self.root_bounds.intersect(ray).is_none() {
            return None;
        }
        let (o, i) = (ray.origin(), ray.inv_dir());
        let f = i * (1.0 + crate::geometry::slab::SLACK);
        let s = |x: f32| _mm256_set1_ps(x);
        let org = [s(o.x), s(o.y), s(o.z)];
        let inv = [s(i.x), s(i.y), s(i.z)];
        let inv_far = [s(f.x), s(f.y), s(f.z)];
        let neg = [i.x.is_sign_negative(), i.y.is_sign_negative(), i.z.is_sign_negative()];
        let (mut prepared, mut best) = (None, None);
        let mut limit = widen(ray.t_max);
        let t_min = ray.t_min;
        let mut stack = TraversalStack::<{ super::traverse::STACK8 }>::new();
        let mut cur = ChildRef::ROOT;
        let of = |node: &QNode8, index: u32, slot: usize| {
            if node.count[slot] > 0 {
                ChildRef::from_raw(1 << 31 | index << 3 | slot as u32)
            } else {
                ChildRef::from_raw(node.child[slot])
            }
        };
        let prefetch_child = |node: &QNode8, slot: usize| {
            let i = node.child[slot] as usize;
            if node.count[slot] > 0 {
                if let Some(t) = self.tris.get(i) {
                    prefetch(t);
                }
            } else if let Some(n) = nodes.get(i) {
                prefetch(n);
            }
        };
        'traversal: loop {
            while !cur.is_leaf() {
                let index = cur.node();
                let node = &nodes[index as usize];
                stats.node_visited();
                stats.box_tests(node.valid.count_ones());
                let mut enter = _mm256_set1_ps(t_min);
                let mut exit = _mm256_set1_ps(limit);
                for axis in 0..3 {
                    let (near, far) = if neg[axis] { (&node.hi[axis], &node.lo[axis]) } else { (&node.lo[axis], &node.hi[axis]) };
                    let scale = _mm256_broadcast_ss(&node.scale[axis]);
                    let origin = _mm256_broadcast_ss(&node.origin[axis]);
                    let dq = |q: &[u8; 8]| {
                        let v = _mm256_cvtepi32_ps(_mm256_cvtepu8_epi32(_mm_loadl_epi64(q.as_ptr().cast())));
                        _mm256_fmadd_ps(v, scale, origin)
                    };
                    let t0 = _mm256_mul_ps(_mm256_sub_ps(dq(near), org[axis]), inv[axis]);
                    let t1 = _mm256_mul_ps(_mm256_sub_ps(dq(far), org[axis]), inv_far[axis]);
                    enter = _mm256_max_ps(t0, enter);
                    exit = _mm256_min_ps(t1, exit);
                }
                let mask = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(enter, exit)) as u32 & node.valid as u32;
                let mut e = [0.0f32; 8];
                _mm256_storeu_ps(e.as_mut_ptr(), enter);
                if mask == 0 {
                    match stack.pop_nearer_or_skip(limit, |_, _| {}) {
                        Some(r) => {
                            cur = ChildRef::from_raw(r);
                            continue 'traversal;
                        }
                        None => break 'traversal,
                    }
                }
                let s0 = mask.trailing_zeros() as usize;
                let rest = mask & (mask - 1);
                if rest == 0 {
                    cur = of(node, index, s0);
                    continue;
                }
                let s1 = rest.trailing_zeros() as usize;
                if rest & (rest - 1) == 0 {
                    let (r0, r1) = (of(node, index, s0), of(node, index, s1));
                    if e[s0] <= e[s1] {
                        prefetch_child(node, s1);
                        stack.push((r1.raw(), e[s1]));
                        cur = r0;
                    } else {
                        prefetch_child(node, s0);
                        stack.push((r0.raw(), e[s0]));
                        cur = r1;
                    }
                    continue;
                }
                let mut m = mask;
                let mut k = 0;
                while m != 0 {
                    let slot = m.trailing_zeros() as usize;
                    m &= m - 1;
                    prefetch_child(node, slot);
                    stack.push((of(node, index, slot).raw(), e[slot]));
                    k += 1;
                }
                stack.sort_top(k);
                cur = match stack.pop() {
                    Some((r, _)) => ChildRef::from_raw(r),
                    None => break 'traversal,
                };
            }
            let (index, slot) = cur.leaf::<8>();
            let node = &nodes[index];
            stats.leaf_visited();
            let (first, count) = (node.child[slot] as usize, node.count[slot] as usize);
            let coords = &super::leaves::floats(&self.tris)[9 * first..];
            let ids = |i: usize| self.prim_ids[i];
            test_triangles_grouped::<Watertight, false, S>(coords, count, first, ray, stats, &mut prepared, &mut best, ids);
            limit = widen(ray.t_max);
            match stack.pop_nearer_or_skip(limit, |_, _| {}) {
                Some(r) => cur = ChildRef::from_raw(r),
                None => break 'traversal,
            }
        }
        best.map(|(i, h)| Hit { t: h.t, u: h.u, v: h.v, prim: self.prim_ids[i] })
    }
}
