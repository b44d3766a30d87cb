//! The node inspector's sentences, written once: the Node window and `bvhscope inspect` print
//! them both.

use super::Inspection;
use crate::bvh::builders::driver::SplitKind;
use crate::bvh::wide::WideGroup;
use crate::bvh::{Builder, Strategy};

/// What the SBVH does at the node, in a line (the app's Node window shows the same line).
pub fn sbvh_text(ins: &Inspection) -> Option<String> {
    let e = ins.sbvh?;
    let what = match e.split.map(|s| s.kind) {
        None => "makes a leaf".to_string(),
        Some(k) => format!(
            "splits by {}",
            match k {
                SplitKind::Object => "an object split",
                SplitKind::Spatial => "a spatial split (cutting triangles)",
                SplitKind::EqualCount => "equal count (fallback)",
            }
        ),
    };
    let priced = if let Some(d) = e.over_budget {
        format!("the cheaper spatial split would add {d} references, over the budget")
    } else if e.spatial_priced {
        "spatial planes priced".to_string()
    } else if e.budget == 0 {
        "no spatial planes: no reference budget left".to_string()
    } else {
        "no spatial planes: overlap not above α".to_string()
    };
    Some(format!(
        "SBVH here: {what}; object split's overlap {:.2e} of the root's area; {priced}; {} extra references left",
        e.overlap_ratio, e.budget
    ))
}

/// Which wide node of a wide layout binary node `node` is collapsed into.
pub fn wide_group_text(node: u32, g: &WideGroup) -> String {
    let list = |v: &[u32]| v.iter().map(|n| n.to_string()).collect::<Vec<_>>().join(", ");
    let role = if g.collapsed.contains(&node) { "is collapsed into" } else { "is a leaf slot of" };
    format!(
        "In the {}-wide layout, node {node} {role} the wide node over binary node {}, which swallows binary nodes {} and has children {}.",
        g.width,
        g.top,
        list(&g.collapsed),
        list(&g.children)
    )
}

/// "12", or for a node added to binarise a 4-wide dump, what it is.
pub fn dump_text(d: Option<u32>) -> String {
    d.map_or("none: added to binarise a node of more than two children".into(), |d| d.to_string())
}

/// Why `strategy` marks no plane at a node.
pub fn no_split_text(strategy: Strategy) -> &'static str {
    match strategy.builder() {
        Builder::TopDown { references: true, .. } => "makes a leaf here",
        Builder::Morton | Builder::Clustering => "no plane priced here: it builds from the Morton order",
        Builder::TopDown { .. } => "no split (the builder falls back to equal count)",
    }
}
