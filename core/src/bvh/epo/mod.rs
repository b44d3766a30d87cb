//! End-point overlap (EPO; Aila, Karras & Laine, "On Quality Metrics of Bounding Volume
//! Hierarchies", HPG 2013): how much of the scene's surface lies inside boxes of nodes that do not
//! hold it. A ray that starts or ends on a triangle (every secondary ray does) must visit every
//! node whose box contains that point; the nodes not above the triangle's leaf are pure overhead,
//! which the SAH, counting only box areas, does not see.
//!
//! EPO = Σ over nodes n of C(n) · Σ over triangles t outside n's subtree of A(t ∩ box(n)),
//! divided by the total surface area, with C(n) weighting nodes as the SAH does: C_trav for an
//! interior node, C_isect·(its triangles) for a leaf. A(t ∩ box) is the area of the triangle
//! clipped to the box (Sutherland & Hodgman's polygon clipping, 1974). Triangles are the slots of
//! the leaf order: a triangle an SBVH cut into several leaves counts once per leaf.
//!
//! The cost. One node's sum is found exactly by walking the tree from the root (`exact`): the tree
//! is a spatial index of its own triangles, subtrees that miss the box or lie inside it cost one
//! test, and only triangles crossing the box's boundary are clipped. Over all nodes that is
//! cheap only where boxes overlap little; where they overlap much (long thin crossing triangles)
//! the pairs of a node and a triangle meeting its box grow as nodes × triangles (the 40,000
//! needles of BENCHMARKS.md: 6·10⁹ units of work, 100 s). And even on a scan it costs several
//! builds, since each node clips the triangles along its box's faces. So `measure` has a budget
//! of work proportional to the build's, `BUDGET_PER_TRIANGLE_LEVEL` · n log₂ n units for n
//! triangles (`budget`; at least `SMALL_BUDGET` for a small mesh), and spends it where it buys
//! most:
//!
//! 1. a pilot walks a thousand nodes spread over the tree with a small cap; where by its prices
//!    most of the other walks fit the budget at some cap, they are made at that cap (in blocks,
//!    stopping where the pilot was wrong by much), then again for those left while there is room.
//!    A node whose walk finished has its exact term. On a small mesh all do.
//! 2. The terms of the other nodes are estimated together from points on the surface with what
//!    is left (`sample`): unbiased, with a standard error from independent replicates, by walks
//!    down the tree from points or by pairs of a node and a point, whichever the pilot finds
//!    better. `Epo` says how many terms are exact and the error of the rest (± two standard
//!    errors are about a 95% interval).
//!
//! Work is counted, not timed, so the figure is the same on every machine and thread count.

mod clip;
mod exact;
mod measure;
mod sample;

pub use clip::{clipped_area, triangle_area};

#[cfg(test)]
mod epo_tests;

pub use measure::{
    budget, figure, measure, measure_within, node_term, node_terms, of, Epo, BUDGET_PER_TRIANGLE_LEVEL, SMALL,
    SMALL_BUDGET,
};
