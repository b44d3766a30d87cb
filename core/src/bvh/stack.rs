//! The traversal stack: a fixed array on the call stack, not initialised up front. Zeroing a few
//! kilobytes per ray would cost more than traversing a small BVH; the builder bounds the tree depth
//! (`build::HEURISTIC_DEPTH_LIMIT`), which bounds how many entries a traversal can push.

use std::mem::MaybeUninit;

/// A node to visit and the distance at which the ray enters its box.
pub type StackEntry = (u32, f32);

/// A stack of up to `N` entries of `E`: by default a node and its entry distance; packets keep a
/// node and the first group of rays that may hit it.
pub struct TraversalStack<const N: usize, E: Copy = StackEntry> {
    items: [MaybeUninit<E>; N],
    len: usize,
}

impl<const N: usize, E: Copy> TraversalStack<N, E> {
    #[inline(always)]
    pub fn new() -> Self {
        Self { items: [const { MaybeUninit::uninit() }; N], len: 0 }
    }

    /// Push an entry. Indexing stays bounds-checked: overflowing is impossible by the depth bound,
    /// and if that bound were ever broken this stops with a message instead of corrupting memory.
    #[inline(always)]
    pub fn push(&mut self, e: E) {
        self.items[self.len] = MaybeUninit::new(e);
        self.len += 1;
    }

    /// The entries, bottom first (for a trace's report of the stack).
    pub fn entries(&self) -> &[E] {
        // SAFETY: every slot below `len` was written by `push`, and `MaybeUninit<E>` has `E`'s
        // layout.
        unsafe { std::slice::from_raw_parts(self.items.as_ptr().cast::<E>(), self.len) }
    }

    #[inline(always)]
    pub fn pop(&mut self) -> Option<E> {
        if self.len == 0 {
            return None;
        }
        self.len -= 1;
        // SAFETY: every slot below `len` was written by `push` before `len` passed it.
        Some(unsafe { self.items[self.len].assume_init() })
    }
}

impl<const N: usize> TraversalStack<N> {
    /// Sort the top `k` entries so the nearest (smallest distance) is popped first.
    #[inline(always)]
    pub fn sort_top(&mut self, k: usize) {
        let base = self.len - k;
        for i in base + 1..self.len {
            // SAFETY: entries below `len` are initialised.
            let e = unsafe { self.items[i].assume_init() };
            let mut j = i;
            while j > base && unsafe { self.items[j - 1].assume_init() }.1 < e.1 {
                self.items[j] = self.items[j - 1];
                j -= 1;
            }
            self.items[j] = MaybeUninit::new(e);
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
