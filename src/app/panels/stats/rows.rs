//! The statistics panel's rows, each a figure of a strategy with what it means; the Compare
//! window shows some of them again, through the same row, so a figure and its difference read
//! the same in both (issue 59: the SAH difference was −5.43 in one, −5.44 in the other).

use crate::app::state::StrategyFigures;
use crate::bvh::fmt_ms;
use crate::render::RaySummary;

/// A row's value for a strategy (`None`: not measured yet).
pub enum Value {
    /// One number, shown with `digits` decimals and `unit` after it.
    Number { get: fn(&StrategyFigures) -> Option<f64>, digits: usize, unit: &'static str },
    /// Anything else ("12 / 7.3").
    Text(fn(&StrategyFigures) -> Option<String>),
}

/// A row: its name, what it means (tooltip), and its value for a strategy (`None`: not measured
/// yet). Per-ray rows are marked, because they depend on the camera as well as on the tree.
pub struct StatRow {
    pub name: &'static str,
    pub tip: &'static str,
    pub per_ray: bool,
    pub value: Value,
}

pub(super) fn rays(f: &StrategyFigures) -> Option<&RaySummary> {
    f.rays.as_ref().map(|r| &r.summary)
}

pub const ROWS: &[StatRow] = &[
    StatRow {
        name: "Build ms",
        tip: "Time to build the BVH: every level (for two levels, the meshes' BVHs and the top level), with the tree laid out for traversal",
        per_ray: false,
        value: Value::Text(|f| Some(fmt_ms(f.build_ms))),
    },
    StatRow {
        name: "Nodes",
        tip: "Interior nodes and leaves (for the 4-wide layout: wide nodes and leaf slots)",
        per_ray: false,
        value: Value::Number { get: |f| Some(f.stats.nodes as f64), digits: 0, unit: "" },
    },
    StatRow { name: "Leaves", tip: "Nodes that hold triangles", per_ray: false, value: Value::Number { get: |f| Some(f.stats.leaves as f64), digits: 0, unit: "" } },
    StatRow {
        name: "Depth max / mean",
        tip: "Levels from the root (depth 0) to the deepest leaf, and the mean over leaves, in levels of this layout",
        per_ray: false,
        value: Value::Text(|f| Some(format!("{} / {:.1}", f.stats.max_depth, f.stats.mean_leaf_depth))),
    },
    StatRow {
        name: "SAH cost",
        tip: "Surface area heuristic of the whole tree: Σ interior C_trav·A(node)/A(root) + Σ leaves C_isect·N·A(leaf)/A(root). The expected traversal steps plus triangle tests of a random ray through the root box (constants below)",
        per_ray: false,
        value: Value::Number { get: |f| Some(f.stats.sah_cost), digits: 2, unit: "" },
    },
    StatRow {
        name: "EPO",
        tip: "End-point overlap (Aila, Karras & Laine 2013, \"On Quality Metrics of Bounding Volume Hierarchies\"): Σ over nodes of C(n) × the area of other subtrees' triangles inside the node's box, over the total triangle area, with C(n) = C_trav for interior nodes and C_isect × triangles for leaves. A ray that starts or ends on a surface must visit every box around that point; EPO counts the ones that are not its leaf's ancestors, which the SAH does not see. Of the binary tree as built (the 4-wide layout is collapsed from it). Where summing every node would cost more than about the build, the terms it could not afford are estimated from points on the surface: value ± two standard errors",
        per_ray: false,
        value: Value::Text(|f| f.stats.epo.map(|e| crate::bvh::epo::figure(e, f.stats.epo_error))),
    },
    StatRow {
        name: "References / triangle",
        tip: "Leaf entries per triangle: 1, unless SBVH's spatial splits cut triangles so several leaves reference the parts of one (its growth bound limits this). In parentheses: the spatial splits",
        per_ray: false,
        value: Value::Text(|f| Some(format!("{:.3} ({})", f.stats.references_per_triangle(), f.stats.spatial_splits))),
    },
    StatRow {
        name: "Bytes / triangle",
        tip: "Memory of the nodes, the triangle index array and the triangles the tree keeps in leaf order (36 bytes each), per triangle; with the stored-edges triangle test on a wide layout, also the leaves it keeps in its own form (v0, two edges and the normal: 48 bytes a triangle more)",
        per_ray: false,
        value: Value::Number {
            get: |f| Some((f.stats.memory_bytes + f.stats.walk_bytes) as f64 / f.stats.triangles.max(1) as f64),
            digits: 1,
            unit: "",
        },
    },
    StatRow {
        name: "SIMD kernels",
        tip: "What the wide layout's walk runs on this CPU, chosen when the program starts: avx512 (eight boxes with mask registers, up to sixteen triangles of a leaf per pass), avx2 (eight boxes in one pass, or four in one four-lane pass in the 4-wide layout; up to eight triangles per pass), simd4 (four lanes: SSE2 or NEON), scalar. BVHSCOPE_SIMD=simd4 or scalar asks for a more portable one. Every choice finds the same hits with the same counts",
        per_ray: false,
        value: Value::Text(|f| Some(f.stats.simd.unwrap_or("— (binary)").to_string())),
    },
    StatRow {
        name: "Fallback splits",
        tip: "Nodes where the strategy found no useful split (midpoint with an empty side, SAH with coincident centroids) and an equal-count split was used",
        per_ray: false,
        value: Value::Number { get: |f| Some(f.stats.fallback_splits as f64), digits: 0, unit: "" },
    },
    StatRow {
        name: "Rays in root box",
        tip: "Share of the frame's primary rays that enter the root box; the others cost one box test and visit nothing. The per-ray rows below are means over these rays, unless they say all rays. An imported tree is measured on the mesh's box instead (its SAH cost too), as the tree beside it: a root box larger than the mesh's lets more rays in, and their work counts against it",
        per_ray: true,
        value: Value::Number { get: |f| rays(f).map(|r| 100.0 * r.root_fraction()), digits: 1, unit: " %" },
    },
    StatRow {
        name: "Nodes visited / ray",
        tip: "Nodes taken from the stack and processed (interior and leaf), per ray that enters the root box",
        per_ray: true,
        value: Value::Number { get: |f| rays(f).map(|r| r.root_mean_nodes_visited), digits: 2, unit: "" },
    },
    StatRow {
        name: "Box tests / ray",
        tip: "Ray–box slab tests per ray that enters the root box (the root's own test included; a wide node tests each valid child)",
        per_ray: true,
        value: Value::Number { get: |f| rays(f).map(|r| r.root_mean_box_tests), digits: 2, unit: "" },
    },
    StatRow {
        name: "Triangle tests / ray",
        tip: "Ray–triangle tests per ray that enters the root box",
        per_ray: true,
        value: Value::Number { get: |f| rays(f).map(|r| r.root_mean_triangle_tests), digits: 2, unit: "" },
    },
    StatRow {
        name: "Nodes / ray, all rays",
        tip: "Nodes visited per ray over all primary rays of the frame, those that miss the root box (0 nodes) included",
        per_ray: true,
        value: Value::Number { get: |f| rays(f).map(|r| r.mean_nodes_visited), digits: 2, unit: "" },
    },
    StatRow {
        name: "Tri tests / ray, all rays",
        tip: "Triangle tests per ray over all primary rays of the frame",
        per_ray: true,
        value: Value::Number { get: |f| rays(f).map(|r| r.mean_triangle_tests), digits: 2, unit: "" },
    },
    StatRow {
        name: "Most in one ray",
        tip: "The most nodes visited, and the most triangle tests, of any one ray of the frame",
        per_ray: true,
        value: Value::Text(|f| rays(f).map(|r| format!("{} / {}", r.max_nodes_visited, r.max_triangle_tests))),
    },
];

impl StatRow {
    /// The cell's text.
    pub fn text(&self, f: &StrategyFigures) -> Option<String> {
        match &self.value {
            Value::Number { get, digits, unit } => get(f).map(|v| format!("{v:.digits$}{unit}")),
            Value::Text(text) => text(f),
        }
    }

    /// The row named `name` (the Compare window's rows are these).
    pub fn named(name: &str) -> &'static StatRow {
        ROWS.iter().find(|r| r.name == name).expect("a row of the statistics")
    }
}

/// B − A of a row, as both the statistics and the Compare window print it: of the unrounded
/// figures, rounded once to the row's decimals (whole numbers for counts), so the difference is
/// never that of two roundings. A text row whose cells are one number each ("Build ms") gives
/// the difference of those; others none.
pub fn difference(row: &StatRow, a: &StrategyFigures, b: &StrategyFigures) -> Option<String> {
    match &row.value {
        Value::Number { get, digits, .. } => {
            let (x, y) = (get(a)?, get(b)?);
            Some(format_difference(y - x, *digits))
        }
        Value::Text(text) => {
            let num = |f| text(f).and_then(|t| t.parse::<f64>().ok());
            Some(format!("{:+.2}", num(b)? - num(a)?))
        }
    }
}

/// A difference with `digits` decimals and its sign ("+0", "-5.44").
pub fn format_difference(d: f64, digits: usize) -> String {
    format!("{d:+.digits$}")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The difference is rounded once: 10.004 → 4.568 is −5.436, "-5.44", where the two cells'
    /// own roundings (10.00, 4.57) would say −5.43.
    #[test]
    fn a_difference_is_of_the_figures_not_of_their_roundings() {
        let row = StatRow::named("SAH cost");
        let figures = |sah: f64| StrategyFigures {
            label: String::new(),
            stats: crate::bvh::TreeStats { sah_cost: sah, ..Default::default() },
            build_ms: 1.0,
            rays: None,
            frame_ms: None,
            speedup: None,
        };
        let (a, b) = (figures(10.004), figures(4.568));
        assert_eq!((row.text(&a).unwrap(), row.text(&b).unwrap()), ("10.00".into(), "4.57".into()));
        assert_eq!(difference(row, &a, &b).as_deref(), Some("-5.44"));
        assert_eq!(difference(StatRow::named("Nodes"), &a, &b).as_deref(), Some("+0"));
    }
}
