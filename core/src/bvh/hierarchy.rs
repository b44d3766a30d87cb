//! Where each node of a binary tree sits: its parent, depth and range of the leaf order, and the
//! leaf of each triangle. The nodes do not store these; the tree view, the inspector, the replay,
//! EPO and the checker's tests all need them.

use crate::bvh::node::Bvh;
use crate::bvh::wide::CollapsePlan;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU32, Ordering::Relaxed};

/// Where each node sits in the binary tree: what the tree view, the breadcrumb and the inspector
/// need and the nodes do not store. Computed once per tree, O(nodes).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Hierarchy {
    /// The parent of each node (`u32::MAX` for the root).
    pub parent: Vec<u32>,
    pub depth: Vec<u32>,
    /// The subtree's triangles, a contiguous range of the leaf order: `first..first + count`.
    pub first: Vec<u32>,
    pub count: Vec<u32>,
    /// The leaf holding each slot of the leaf order.
    pub leaf_of_slot: Vec<u32>,
    /// The slot of each mesh triangle in the leaf order (of a triangle in several leaves, an
    /// SBVH's cut triangle, its last slot: `other_slots` has the rest).
    pub slot_of_prim: Vec<u32>,
    /// The other slots of triangles in several leaves (empty unless spatial splits cut some).
    pub other_slots: std::collections::HashMap<u32, Vec<u32>>,
    /// How the 4- and 8-wide layouts group the nodes (`collapse_plan`), made when first asked.
    wide4: std::sync::OnceLock<CollapsePlan>,
    wide8: std::sync::OnceLock<CollapsePlan>,
}

/// Trees of at least this many nodes are read in parallel (a few tasks' worth).
const PARALLEL_MIN: usize = 1 << 14;

impl Hierarchy {
    /// The `W`-wide layout's collapse of this tree (`nodes`, the tree this hierarchy was made
    /// of), made on first use and kept: the inspector asks for it on every frame.
    pub fn collapse_plan<const W: usize>(&self, nodes: &[crate::bvh::node::BvhNode]) -> &CollapsePlan {
        const { assert!(W == 4 || W == 8, "the wide layouts are 4 and 8 wide") };
        let cell = if W == 8 { &self.wide8 } else { &self.wide4 };
        cell.get_or_init(|| CollapsePlan::of::<W>(nodes))
    }

    /// The hierarchy of `bvh`. A big tree whose every node but the root is the child of exactly
    /// one node before it (every tree the builders and the importer make) is read in parallel,
    /// its subtrees side by side; anything else, and a small tree, by `serial_of`. The two give
    /// the same (a test compares them).
    pub fn of(bvh: &Bvh) -> Hierarchy {
        // The parallel reading does more work than the serial one (its check, a second pass for
        // the slots: 140 against 60 ms on one thread for 4.4M nodes), so it pays only from about
        // four threads. The serial-fraction clock (`parallel::measure_serial`, one thread) takes
        // the path 16 threads would.
        let threads = rayon::current_num_threads().max(crate::parallel::measuring() as usize * 16);
        if bvh.nodes.len() >= PARALLEL_MIN && threads >= 4 && well_formed(bvh) {
            parallel_of(bvh)
        } else {
            Hierarchy::serial_of(bvh)
        }
    }

    /// `of` on one thread, for any node array (a child's parent is the last node naming it).
    pub fn serial_of(bvh: &Bvh) -> Hierarchy {
        let n = bvh.nodes.len();
        let mut h = Hierarchy {
            parent: vec![u32::MAX; n],
            depth: vec![0; n],
            first: vec![0; n],
            count: vec![0; n],
            leaf_of_slot: vec![0; bvh.prim_ids.len()],
            slot_of_prim: vec![u32::MAX; bvh.prim_ids.len()],
            other_slots: Default::default(),
            ..Default::default()
        };
        // Parents come before their children in the node array, so one pass down sets parents and
        // depths, and one pass back up sums the ranges.
        for (i, node) in bvh.nodes.iter().enumerate() {
            if node.is_leaf() {
                h.first[i] = node.index;
                h.count[i] = node.count as u32;
                for s in node.prims() {
                    h.leaf_of_slot[s] = i as u32;
                }
            } else {
                for c in [node.index, node.index + 1] {
                    h.parent[c as usize] = i as u32;
                    h.depth[c as usize] = h.depth[i] + 1;
                }
            }
        }
        for i in (0..n).rev() {
            let node = &bvh.nodes[i];
            if !node.is_leaf() {
                let (l, r) = (node.index as usize, node.index as usize + 1);
                h.first[i] = h.first[l].min(h.first[r]);
                h.count[i] = h.count[l] + h.count[r];
            }
        }
        for (slot, &prim) in bvh.prim_ids.iter().enumerate() {
            if let Some(s) = h.slot_of_prim.get_mut(prim as usize) {
                if *s != u32::MAX {
                    h.other_slots.entry(prim).or_default().push(*s);
                }
                *s = slot as u32;
            }
        }
        h
    }

    /// Every slot of a triangle in the leaf order (more than one where spatial splits cut it).
    pub fn slots_of_prim(&self, prim: u32) -> impl Iterator<Item = u32> + '_ {
        let last = self.slot_of_prim.get(prim as usize).copied().filter(|&s| s != u32::MAX);
        last.into_iter().chain(self.other_slots.get(&prim).into_iter().flatten().copied())
    }

    /// The leaf that holds the part of triangle `prim` at `point` (a pixel's hit): its leaf, or of
    /// a triangle cut among several leaves the one whose box is nearest the point (holds it, but
    /// for rounding).
    pub fn leaf_of_hit(&self, bvh: &Bvh, prim: u32, point: glam::Vec3) -> Option<u32> {
        let away = |leaf: u32| {
            let b = bvh.nodes[leaf as usize].bounds();
            (glam::Vec3::from(b.min) - point).max(point - glam::Vec3::from(b.max)).max(glam::Vec3::ZERO).length()
        };
        let leaves = self.slots_of_prim(prim).filter_map(|s| self.leaf_of_slot.get(s as usize).copied());
        leaves.min_by(|&a, &b| away(a).total_cmp(&away(b)))
    }

    /// The node's ancestors from the root down, the node last: the breadcrumb.
    pub fn path(&self, node: u32) -> Vec<u32> {
        let mut out = vec![node];
        let mut n = node;
        while let Some(&p) = self.parent.get(n as usize).filter(|&&p| p != u32::MAX) {
            out.push(p);
            n = p;
        }
        out.reverse();
        out
    }

    /// The leaf that holds a mesh triangle (a pixel's hit: its leaf).
    pub fn leaf_of_prim(&self, prim: u32) -> Option<u32> {
        let slot = *self.slot_of_prim.get(prim as usize)?;
        self.leaf_of_slot.get(slot as usize).copied()
    }

    /// Whether leaf-order slot `slot` lies in `node`'s subtree.
    pub fn holds(&self, node: usize, slot: u32) -> bool {
        slot.wrapping_sub(self.first[node]) < self.count[node]
    }
}

/// Whether every node but the root is the child of exactly one node before it, and every leaf's
/// slots lie in the leaf order: then the walk from the root reaches each node once, and each
/// node's parent, depth and range are the one `serial_of` finds.
fn well_formed(bvh: &Bvh) -> bool {
    crate::parallel::region(|| well_formed_in_parallel(bvh))
}

fn well_formed_in_parallel(bvh: &Bvh) -> bool {
    let (nodes, n) = (&bvh.nodes, bvh.nodes.len());
    // Each node named as a child at most once (a bit each), and n − 1 namings in all: then every
    // node but the root (never named: children come after their parents) is named exactly once.
    let named = Bits::new(n);
    let namings = (0..n).into_par_iter().try_fold(
        || 0usize,
        |k, i| {
            let node = &nodes[i];
            if node.is_leaf() {
                return (node.prims().end <= bvh.prim_ids.len()).then_some(k);
            }
            let c = node.index as usize;
            let fresh = c > i && c + 1 < n && !named.set(c) && !named.set(c + 1);
            fresh.then_some(k + 2)
        },
    );
    namings.try_reduce(|| 0, |a, b| Some(a + b)) == Some(n - 1)
}

/// A bit per item, set from many tasks at once.
struct Bits(Vec<std::sync::atomic::AtomicU64>);

impl Bits {
    fn new(n: usize) -> Bits {
        Bits((0..n.div_ceil(64)).into_par_iter().map(|_| Default::default()).collect())
    }

    /// Set bit `i`; whether it was set before.
    fn set(&self, i: usize) -> bool {
        let bit = 1u64 << (i % 64);
        self.0[i / 64].fetch_or(bit, Relaxed) & bit != 0
    }

    fn get(&self, i: usize) -> bool {
        self.0[i / 64].load(Relaxed) & (1u64 << (i % 64)) != 0
    }
}

/// `serial_of` for a well-formed tree, in parallel: depth first from the root, the subtrees below
/// the first `JOIN_LEVELS` levels each a task that walks its nodes depth first (near the order
/// the builders lay them out in; a level at a time hopped about the array and cost four times
/// as much) and sums their ranges on the way back. Every node is reached once, so each is written by one task and the result
/// does not depend on the thread count.
fn parallel_of(bvh: &Bvh) -> Hierarchy {
    use crate::parallel::{region, Disjoint};
    let (n, slots) = (bvh.nodes.len(), bvh.prim_ids.len());
    // Zeroed (untouched pages until written); every node's entries are written below.
    let (mut parent, mut depth, mut first, mut count) = (vec![0u32; n], vec![0u32; n], vec![0u32; n], vec![0u32; n]);
    // Several leaves might name a slot (an imported tree's): the last has it, as in `serial_of`.
    let leaf_of_slot: Vec<AtomicU32> = region(|| (0..slots).into_par_iter().map(|_| AtomicU32::new(0)).collect());
    {
        let out = Out {
            bvh,
            parent: Disjoint::new(&mut parent),
            depth: Disjoint::new(&mut depth),
            first: Disjoint::new(&mut first),
            count: Disjoint::new(&mut count),
            leaf_of_slot: &leaf_of_slot,
        };
        region(|| out.visit(0, 0, u32::MAX));
    }
    let leaf_of_slot = region(|| leaf_of_slot.into_par_iter().map(AtomicU32::into_inner).collect());
    // Each triangle's slot: written at once where it has one (most), else its slots are
    // gathered in order and the last kept, the others listed, as `serial_of` meets them.
    let (once, twice) = (Bits::new(slots), Bits::new(slots));
    region(|| {
        bvh.prim_ids.par_iter().for_each(|&prim| {
            if (prim as usize) < slots && once.set(prim as usize) {
                twice.set(prim as usize);
            }
        })
    });
    // (Slot + 1, so that the zeroed vector reads "none" below.)
    let mut slot_of_prim = vec![0u32; slots];
    let shared: Vec<(u32, u32)> = {
        let out = Disjoint::new(&mut slot_of_prim);
        region(|| {
            bvh.prim_ids
                .par_iter()
                .enumerate()
                .filter_map(|(slot, &prim)| {
                    if (prim as usize) >= slots {
                        None
                    } else if twice.get(prim as usize) {
                        Some((prim, slot as u32))
                    } else {
                        // SAFETY: a triangle with one slot is written by that slot's task alone.
                        unsafe { out.set(prim as usize, slot as u32 + 1) };
                        None
                    }
                })
                .collect()
        })
    };
    let mut other_slots: std::collections::HashMap<u32, Vec<u32>> = Default::default();
    for (prim, slot) in shared {
        let s = &mut slot_of_prim[prim as usize];
        if *s != 0 {
            other_slots.entry(prim).or_default().push(*s - 1);
        }
        *s = slot + 1;
    }
    region(|| slot_of_prim.par_iter_mut().for_each(|s| *s = s.wrapping_sub(1)));
    Hierarchy { parent, depth, first, count, leaf_of_slot, slot_of_prim, other_slots, ..Default::default() }
}

/// Levels of the tree split among tasks (up to 2^this subtrees).
const JOIN_LEVELS: u32 = 12;

/// Where `parallel_of`'s tasks write: each node's entries by the one task that reaches it.
struct Out<'a> {
    bvh: &'a Bvh,
    parent: crate::parallel::Disjoint<'a, u32>,
    depth: crate::parallel::Disjoint<'a, u32>,
    first: crate::parallel::Disjoint<'a, u32>,
    count: crate::parallel::Disjoint<'a, u32>,
    leaf_of_slot: &'a [AtomicU32],
}

impl Out<'_> {
    /// Node `i` at depth `d` under `up`, and its subtree: returns its range (first, count).
    fn visit(&self, i: u32, d: u32, up: u32) -> (u32, u32) {
        let node = &self.bvh.nodes[i as usize];
        if d >= JOIN_LEVELS || node.is_leaf() {
            return self.walk(i, d, up);
        }
        // SAFETY (here and in `walk`): `well_formed` proved that every node is the child of
        // exactly one node, which comes before it, so the tree from the root reaches each node
        // once: node i's entries are written only by the task that reaches it, and read back
        // only by that task.
        unsafe {
            self.parent.set(i as usize, up);
            self.depth.set(i as usize, d);
        }
        let ((f1, c1), (f2, c2)) =
            rayon::join(|| self.visit(node.index, d + 1, i), || self.visit(node.index + 1, d + 1, i));
        let range = (f1.min(f2), c1 + c2);
        unsafe {
            self.first.set(i as usize, range.0);
            self.count.set(i as usize, range.1);
        }
        range
    }

    /// `visit` on this thread: the subtree in preorder (parents and depths), then in reverse
    /// (ranges: children before parents).
    fn walk(&self, root: u32, d: u32, up: u32) -> (u32, u32) {
        let nodes = &self.bvh.nodes;
        let (mut order, mut stack) = (Vec::new(), vec![(root, d, up)]);
        while let Some((i, d, up)) = stack.pop() {
            let node = &nodes[i as usize];
            unsafe {
                self.parent.set(i as usize, up);
                self.depth.set(i as usize, d);
            }
            if node.is_leaf() {
                unsafe {
                    self.first.set(i as usize, node.index);
                    self.count.set(i as usize, node.count as u32);
                }
                for s in node.prims() {
                    self.leaf_of_slot[s].fetch_max(i, Relaxed);
                }
            } else {
                order.push(i);
                stack.extend([(node.index + 1, d + 1, i), (node.index, d + 1, i)]);
            }
        }
        for &i in order.iter().rev() {
            let c = nodes[i as usize].index as usize;
            unsafe {
                let (f, k) = (self.first.get(c).min(self.first.get(c + 1)), self.count.get(c) + self.count.get(c + 1));
                self.first.set(i as usize, f);
                self.count.set(i as usize, k);
            }
        }
        unsafe { (self.first.get(root as usize), self.count.get(root as usize)) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::params::Strategy;
    use crate::bvh::params::{BuildParams, Layout};
    use crate::mesh::generate::{grid_of, torus_knot};

    /// The parallel reading of a big tree is `serial_of`'s, on 1 and 4 threads, with cut
    /// triangles (an SBVH) and without; a tree that is not well formed is read serially.
    #[test]
    fn a_big_tree_read_in_parallel_is_read_as_on_one_thread() {
        let mesh = grid_of(&torus_knot(2, 3, 0.3, 200, 40), 3);
        for strategy in [Strategy::SahBinned, Strategy::Sbvh] {
            let params = BuildParams {
                strategy,
                layout: Layout::Binary,
                max_leaf_size: 1,
                sbvh_growth: 100,
                ..Default::default()
            };
            let bvh = Bvh::build(&mesh, &params);
            assert!(bvh.nodes.len() >= PARALLEL_MIN && well_formed(&bvh), "{strategy:?}");
            let serial = Hierarchy::serial_of(&bvh);
            if strategy == Strategy::Sbvh {
                assert!(!serial.other_slots.is_empty(), "the SBVH cut some triangles");
            }
            for threads in [1, 4] {
                let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
                assert!(pool.install(|| parallel_of(&bvh)) == serial, "{strategy:?} on {threads} threads");
                // (`of` reads serially on one thread, in parallel on four.)
                assert!(pool.install(|| Hierarchy::of(&bvh)) == serial, "{strategy:?}: `of` on {threads} threads");
            }
            // A node named twice, or a child before its parent: not well formed.
            let mut bad = bvh.clone();
            let i = (0..bad.nodes.len()).rev().find(|&i| !bad.nodes[i].is_leaf()).unwrap();
            bad.nodes[i].index = 1;
            assert!(!well_formed(&bad));
            assert!(Hierarchy::of(&bad) == Hierarchy::serial_of(&bad));
        }
    }
}
