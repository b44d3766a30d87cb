//! The build replay's state behind the Replay window: the replay of the current single BVH's
//! binary tree (`explain::replay`, prepared with the tree view's `Explained`), the step shown and
//! whether it plays. While the window is open the viewport shows the tree after `k` splits.

use super::node::Explained;
use crate::bvh::morton::MortonOrder;
use crate::explain::inspect::{CurvePoint, Marker};
use crate::explain::replay::{PartialBvh, Replay};
use std::sync::Arc;
use std::time::Instant;

#[derive(Default)]
pub struct ReplayView {
    pub window: bool,
    pub replay: Option<Arc<Replay>>,
    /// The splits made so far (0: the root alone).
    pub k: usize,
    /// The tree after `k` splits, what the viewport traces.
    pub partial: Option<Arc<PartialBvh>>,
    pub playing: bool,
    pub last_tick: Option<Instant>,
    /// The newest split: its node, the plane the tree's strategy cut it at, and for the binned
    /// SAH the cost at its bins' planes per axis (not computed for nodes over
    /// `MAX_PLANE_TRIANGLES`, whose sweep would hold up the window).
    pub newest: Option<(u32, Option<Marker>, [Vec<CurvePoint>; 3])>,
    /// An LBVH tree's Morton order (its leaf order), drawn as the curve its splits cut.
    pub morton: Option<Arc<MortonOrder>>,
}

/// The largest newest split whose plane the replay computes as it steps.
pub const MAX_PLANE_TRIANGLES: u32 = 300_000;

impl ReplayView {
    /// The replay of `e`'s tree, made if missing (O(nodes)), with the partial tree at `k`.
    pub fn fit(&mut self, e: &Explained) {
        let fresh = self.replay.as_ref().is_some_and(|r| Arc::ptr_eq(&r.tree, &e.tree));
        if !fresh {
            let r = Arc::new(Replay::of(e.tree.clone()));
            self.k = self.k.min(r.splits());
            self.morton = MortonOrder::of(&r.tree).map(Arc::new);
            self.replay = Some(r);
            self.partial = None;
        }
        if self.partial.as_ref().is_none_or(|p| p.splits != self.k) {
            self.partial = self.replay.as_ref().map(|r| Arc::new(r.partial(self.k)));
            let r = self.replay.as_ref().expect("made above");
            self.newest = self.k.checked_sub(1).map(|i| r.order[i]).map(|n| {
                // An imported tree has no strategy of bvhscope's to find its plane with.
                if e.hierarchy.count[n as usize] <= MAX_PLANE_TRIANGLES && e.bvh.import().is_none() {
                    let (m, bins) = crate::explain::inspect::own_split(&e.tree, &e.hierarchy, n);
                    (n, m, bins)
                } else {
                    (n, None, Default::default())
                }
            });
        }
    }

    /// Go to step `k` (clamped to the replay's splits).
    pub fn set(&mut self, k: usize) {
        let n = self.replay.as_ref().map_or(0, |r| r.splits());
        self.k = k.min(n);
        if self.k == n {
            self.playing = false;
        }
    }

    /// The next step of playing: about an eighth more splits each time, so a play runs through
    /// the first splits one by one and through the last thousands in a few seconds.
    pub fn next_play_step(&self) -> usize {
        self.k + (self.k / 8).max(1)
    }
}
