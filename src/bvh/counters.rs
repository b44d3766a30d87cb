//! Per-ray work counters, and the sink trait that lets the traversal count for free when nobody
//! is listening: `NoStats` has empty inlined methods, so the counting code compiles away in the
//! plain traversal (measured in `benches/`), while `RayCounters` feeds the heatmaps.

/// Where the traversal reports its work. Implementations must be cheap: these run per node.
pub trait TraversalStats {
    fn node_visited(&mut self);
    fn leaf_visited(&mut self);
    fn box_tests(&mut self, n: u32);
    fn triangle_tests(&mut self, n: u32);
}

/// The sink of the plain traversal: counts nothing, costs nothing.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoStats;

impl TraversalStats for NoStats {
    #[inline(always)]
    fn node_visited(&mut self) {}
    #[inline(always)]
    fn leaf_visited(&mut self) {}
    #[inline(always)]
    fn box_tests(&mut self, _: u32) {}
    #[inline(always)]
    fn triangle_tests(&mut self, _: u32) {}
}

/// The work one ray (or, summed, many rays) did. Plain integers: no atomics in the hot loop; a
/// renderer keeps one per pixel and sums afterwards.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct RayCounters {
    /// Nodes taken from the stack and processed, interior and leaf.
    pub nodes_visited: u32,
    /// Ray–box slab tests.
    pub box_tests: u32,
    pub leaves_visited: u32,
    /// Ray–triangle tests.
    pub triangle_tests: u32,
}

impl TraversalStats for RayCounters {
    #[inline(always)]
    fn node_visited(&mut self) {
        self.nodes_visited += 1;
    }
    #[inline(always)]
    fn leaf_visited(&mut self) {
        self.leaves_visited += 1;
    }
    #[inline(always)]
    fn box_tests(&mut self, n: u32) {
        self.box_tests += n;
    }
    #[inline(always)]
    fn triangle_tests(&mut self, n: u32) {
        self.triangle_tests += n;
    }
}

impl RayCounters {
    /// Combined cost of the ray under the SAH's own cost model: traversal steps plus triangle
    /// tests, weighted by the same constants the builder used.
    pub fn cost(&self, c: crate::bvh::SahCost) -> f32 {
        c.traversal * self.nodes_visited as f32 + c.intersection * self.triangle_tests as f32
    }
}
