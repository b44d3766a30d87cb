//! The traversal stack: a fixed array on the call stack, not initialised up front, that spills onto
//! the heap past its fixed part. Zeroing a few kilobytes per ray would cost more than traversing a
//! small BVH, and the builder bounds the tree depth (`builders::HEURISTIC_DEPTH_LIMIT`), so a built
//! tree never spills; an imported tree may be of any depth (a student's chain of 10,000 nodes is
//! correct, if slow), and its rays push onto the heap beyond the fixed part. The spill check is one
//! predicted branch where the bounds check used to be.

use std::mem::MaybeUninit;

/// A node to visit and the distance at which the ray enters its box.
pub type StackEntry = (u32, f32);

/// A stack of `N` entries of `E` on the call stack and any number more on the heap: by default a
/// node and its entry distance; packets keep a node and the first group of rays that may hit it.
pub struct TraversalStack<const N: usize, E: Copy = StackEntry> {
    items: [MaybeUninit<E>; N],
    /// Entries in all: those below `N` are in `items`, the rest in `spill` (in order).
    len: usize,
    spill: Vec<E>,
}

impl<const N: usize, E: Copy> TraversalStack<N, E> {
    #[inline(always)]
    pub fn new() -> Self {
        Self { items: [const { MaybeUninit::uninit() }; N], len: 0, spill: Vec::new() }
    }

    #[inline(always)]
    pub fn push(&mut self, e: E) {
        if self.len < N {
            self.items[self.len] = MaybeUninit::new(e);
        } else {
            self.push_spilled(e);
        }
        self.len += 1;
    }

    #[cold]
    #[inline(never)]
    fn push_spilled(&mut self, e: E) {
        self.spill.push(e);
    }

    /// Entry `i` (0 at the bottom), `i < len`.
    #[inline(always)]
    fn get(&self, i: usize) -> E {
        if i < N {
            // SAFETY: every slot below `min(len, N)` was written by `push`.
            unsafe { self.items[i].assume_init() }
        } else {
            self.spill[i - N]
        }
    }

    #[inline(always)]
    fn set(&mut self, i: usize, e: E) {
        if i < N {
            self.items[i] = MaybeUninit::new(e);
        } else {
            self.spill[i - N] = e;
        }
    }

    /// How many entries the stack holds.
    pub fn len(&self) -> usize {
        self.len
    }

    /// The top `m` entries (all when there are fewer), bottom first: what a trace's report of the
    /// stack needs, in time independent of the stack's depth.
    pub fn top(&self, m: usize) -> Vec<E> {
        (self.len.saturating_sub(m)..self.len).map(|i| self.get(i)).collect()
    }

    #[inline(always)]
    pub fn pop(&mut self) -> Option<E> {
        if self.len == 0 {
            return None;
        }
        self.len -= 1;
        if self.len < N {
            // SAFETY: every slot below `len` was written by `push` before `len` passed it.
            Some(unsafe { self.items[self.len].assume_init() })
        } else {
            self.spill.pop()
        }
    }
}

impl<const N: usize> TraversalStack<N> {
    /// Sort the top `k` entries so the nearest (smallest distance) is popped first.
    #[inline(always)]
    pub fn sort_top(&mut self, k: usize) {
        if self.len > N {
            return self.sort_top_spilled(k);
        }
        let base = self.len - k;
        for i in base + 1..self.len {
            // SAFETY: entries below `len` (here at most `N`) are initialised.
            let e = unsafe { self.items[i].assume_init() };
            let mut j = i;
            while j > base && unsafe { self.items[j - 1].assume_init() }.1 < e.1 {
                self.items[j] = self.items[j - 1];
                j -= 1;
            }
            self.items[j] = MaybeUninit::new(e);
        }
    }

    /// `sort_top` where entries lie past the fixed part (an imported tree deeper than any built one).
    #[cold]
    #[inline(never)]
    fn sort_top_spilled(&mut self, k: usize) {
        let base = self.len - k;
        for i in base + 1..self.len {
            let e = self.get(i);
            let mut j = i;
            while j > base && self.get(j - 1).1 < e.1 {
                let below = self.get(j - 1);
                self.set(j, below);
                j -= 1;
            }
            self.set(j, e);
        }
    }

    /// Pop entries until one the ray enters no later than `limit` (the closest hit so far,
    /// widened as `geometry::slab` explains: a box starting a rounding error beyond the closest
    /// hit may still hold a hit that rounds nearer): the next node worth visiting. Entries beyond
    /// it are dropped, and `skipped` is told of each (a trace records them): nothing in them can
    /// be nearer.
    #[inline(always)]
    pub fn pop_nearer_or_skip(&mut self, limit: f32, mut skipped: impl FnMut(u32, f32)) -> Option<u32> {
        while let Some((node, t_enter)) = self.pop() {
            if t_enter <= limit {
                return Some(node);
            }
            skipped(node, t_enter);
        }
        None
    }
}

impl<const N: usize, E: Copy> Default for TraversalStack<N, E> {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pops_in_reverse_order() {
        let mut s = TraversalStack::<4>::new();
        assert_eq!(s.pop(), None);
        s.push((1, 1.0));
        s.push((2, 2.0));
        assert_eq!(s.pop(), Some((2, 2.0)));
        s.push((3, 3.0));
        assert_eq!(s.pop(), Some((3, 3.0)));
        assert_eq!(s.pop(), Some((1, 1.0)));
        assert_eq!(s.pop(), None);
    }

    #[test]
    fn pop_nearer_skips_entries_beyond_the_closest_hit() {
        let mut s = TraversalStack::<4>::new();
        for (i, t) in [(1, 1.0), (2, 5.0), (3, 2.0), (4, 9.0)] {
            s.push((i, t));
        }
        let mut skipped = Vec::new();
        assert_eq!(s.pop_nearer_or_skip(3.0, |n, t| skipped.push((n, t))), Some(3));
        assert_eq!(skipped, [(4, 9.0)]);
        assert_eq!(s.pop_nearer_or_skip(3.0, |n, t| skipped.push((n, t))), Some(1), "entry 2 (5.0) is beyond 3.0");
        assert_eq!(skipped, [(4, 9.0), (2, 5.0)]);
        assert_eq!(s.pop_nearer_or_skip(f32::INFINITY, |_, _| {}), None);
    }

    /// Past its fixed part the stack goes on on the heap, in order, and sorts across the seam.
    #[test]
    fn entries_past_the_fixed_part_spill_and_come_back_in_order() {
        let mut s = TraversalStack::<3>::new();
        for i in 0..10u32 {
            s.push((i, i as f32));
        }
        assert_eq!(s.len(), 10);
        assert_eq!(s.top(100).iter().map(|e| e.0).collect::<Vec<_>>(), (0..10).collect::<Vec<_>>());
        assert_eq!(s.top(2).iter().map(|e| e.0).collect::<Vec<_>>(), [8, 9]);
        // Sort the top eight (entries 2..10), across the seam between the array and the heap.
        s.sort_top(8);
        let order: Vec<u32> = std::iter::from_fn(|| s.pop()).map(|e| e.0).collect();
        assert_eq!(order, [2, 3, 4, 5, 6, 7, 8, 9, 1, 0]);
        assert_eq!(s.len(), 0);
    }

    #[test]
    fn sort_top_puts_the_nearest_on_top_and_leaves_the_rest() {
        let mut s = TraversalStack::<8>::new();
        s.push((9, 0.5)); // below the sorted part, must stay
        for (i, t) in [(1, 3.0), (2, 1.0), (3, 4.0), (4, 2.0)] {
            s.push((i, t));
        }
        s.sort_top(4);
        let order: Vec<u32> = std::iter::from_fn(|| s.pop()).map(|e| e.0).collect();
        assert_eq!(order, [2, 4, 1, 3, 9]);
    }
}
