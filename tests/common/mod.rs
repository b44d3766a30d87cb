//! Helpers shared by the integration tests: core's (`core/tests/common`), written once for every
//! package's tests; and what the top-level package's command-line and UI tests both write.
#![allow(dead_code)]

#[path = "../../core/tests/common/mod.rs"]
mod core_helpers;
#[allow(unused_imports)]
pub use core_helpers::*;

/// `n` stacked unit triangles (an OBJ's text) and a correct chain-shaped dump over them (its JSON,
/// depth n - 1): the deep tree the checker, the tracer and the Tree window must take without a
/// stack overflow. `doubled`: that triangle listed twice in its leaf (a finding the checker lists).
pub fn chain_texts(n: u32, doubled: Option<u32>) -> (String, String) {
    let mut obj = String::new();
    for k in 0..n {
        obj += &format!("v 0 0 {k}\nv 1 0 {k}\nv 0 1 {k}\n");
    }
    for k in 0..n {
        obj += &format!("f {} {} {}\n", 3 * k + 1, 3 * k + 2, 3 * k + 3);
    }
    let inner = n - 1;
    let mut nodes = Vec::new();
    for k in 0..inner {
        let next = if k + 1 < inner { k + 1 } else { inner + n - 1 };
        nodes.push(
            serde_json::json!({"min": [0, 0, k], "max": [1, 1, n - 1], "children": [inner + k, next], "axis": 2}),
        );
    }
    let mut prims: Vec<u32> = (0..n).collect();
    for k in 0..n {
        let (first, count) = if Some(k) == doubled { (n, 2) } else { (k, 1) };
        nodes.push(serde_json::json!({"min": [0, 0, k], "max": [1, 1, k], "first": first, "count": count}));
    }
    if let Some(k) = doubled {
        prims.extend([k, k]);
    }
    let dump = serde_json::json!({"format": "bvhscope-bvh", "version": 1, "primitives": prims, "nodes": nodes});
    (obj, dump.to_string())
}
