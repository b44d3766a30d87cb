//! The checker's coverage and bounds groups: every triangle in a leaf, and every triangle inside
//! what a ray can reach of its leaf: the leaf's box inside every ancestor's box (a ray enters a
//! node only through its parent). Found exactly:
//!
//! - a triangle in one leaf is inside that region when its three vertices are (the region is a
//!   box, the triangle the convex hull of its vertices); when it is not, the highest node on its
//!   path whose box leaves it out is the root cause, found by a binary search (the region only
//!   shrinks going down), and the finding is that node's: "node 3's box does not contain its child
//!   node 6 (by 0.5 on +x): 144 triangles below node 6 stick out of it";
//! - a triangle cut among several leaves (spatial splits) must be covered by the union of their
//!   regions: the triangle is clipped against them (`cover`), nothing sampled.
//!
//! One walk from the root without recursion, carrying the path: time linear in the nodes and the
//! references, plus a logarithm of the depth per triangle that sticks out.

use super::structure::Walk;
use super::{count, cover, defect, tolerance, warning, Finding, Group, Tally};
use crate::dump::BvhDump;
use crate::geometry::Aabb;
use crate::mesh::Mesh;
use glam::Vec3;
use std::collections::BTreeMap;

const AXES: [&str; 3] = ["x", "y", "z"];

/// How far `t` sticks out of `b`, and where: (distance, axis, beyond the max side). Distance 0
/// when inside.
fn excess(b: &Aabb, t: &[Vec3]) -> (f32, usize, bool) {
    let (lo, hi) = (Vec3::from(b.min), Vec3::from(b.max));
    let mut worst = (0.0f32, 0usize, false);
    for p in t {
        for a in 0..3 {
            let (below, above) = (lo[a] - p[a], p[a] - hi[a]);
            // NaN boxes (a structure defect) stick out by infinity.
            let (below, above) = (
                if below.is_nan() { f32::INFINITY } else { below },
                if above.is_nan() { f32::INFINITY } else { above },
            );
            if below > worst.0 {
                worst = (below, a, false);
            }
            if above > worst.0 {
                worst = (above, a, true);
            }
        }
    }
    worst
}

fn by(e: (f32, usize, bool)) -> String {
    format!("by {} on {}{}", e.0, if e.2 { "+" } else { "-" }, AXES[e.1])
}

/// Whether `t` lies in `b` grown by `tol`.
fn holds(b: &Aabb, t: &[Vec3; 3], tol: f32) -> bool {
    excess(b, t).0 <= tol
}

/// Triangles sticking out for one root cause, keyed by (node `worst`, its child on their way
/// down, `None` when `worst` is their own leaf).
#[derive(Default)]
struct Cause {
    examples: Vec<String>,
    first: Option<u32>,
    /// The farthest any of them sticks out.
    excess: f32,
}

pub(super) fn check(dump: &BvhDump, mesh: &Mesh, walk: &Walk, out: &mut Vec<Finding>) {
    let by_file = mesh.triangles_by_file_number();
    let (leaves_of, twice) = leaves_per_triangle(dump, walk, by_file.len());
    let regions = walk_regions(dump, mesh, &by_file, walk, &leaves_of);
    report_causes(dump, regions.causes, out);
    report_cut(mesh, &by_file, &regions.shared, &regions.reach, out);
    report_missing(mesh, &by_file, &regions.covered, out);
    regions.degenerate_in.finish(out);
    twice.finish(out);
}

/// Leaf `i`'s triangles (file numbers), when it is a leaf whose range lies in the dump.
fn leaf_prims(dump: &BvhDump, i: usize) -> Option<&[u32]> {
    let n = &dump.nodes[i];
    let (Some(f), Some(c), None) = (n.first, n.count, &n.children) else { return None };
    dump.primitives.get(f as usize..f as usize + c as usize)
}

/// The first pass: how many distinct reached leaves hold each triangle, and the triangles a leaf
/// holds twice.
fn leaves_per_triangle(dump: &BvhDump, walk: &Walk, tris: usize) -> (Vec<u32>, Tally) {
    let mut leaves_of = vec![0u32; tris];
    let mut last = vec![u32::MAX; tris];
    let mut twice = Tally::new(
        Group::Coverage,
        false,
        "triangle is referenced twice in one leaf (tested twice by every ray that reaches it)",
        "triangles are referenced twice in one leaf (tested twice by every ray that reaches it)",
    );
    for i in (0..dump.nodes.len()).filter(|&i| walk.reached[i]) {
        for &p in leaf_prims(dump, i).into_iter().flatten() {
            let Some(l) = last.get_mut(p as usize) else { continue };
            if *l == i as u32 {
                twice.add(Some(i as u32), Some(p), format!("triangle {p} (leaf node {i})"));
            } else {
                *l = i as u32;
                leaves_of[p as usize] += 1;
            }
        }
    }
    (leaves_of, twice)
}

/// What the walk from the root finds: each node's reachable region, the boxes that leave a
/// triangle of one leaf out (by the highest node at fault and its child on the path), the
/// triangles cut among several leaves (with their leaves), which triangles are in a leaf, and
/// the degenerate ones that are.
struct Regions {
    reach: Vec<Aabb>,
    causes: BTreeMap<(u32, Option<u32>), Cause>,
    shared: BTreeMap<u32, Vec<usize>>,
    covered: Vec<bool>,
    degenerate_in: Tally,
}

/// The second pass: the walk from the root with the path and each node's reachable region.
fn walk_regions(dump: &BvhDump, mesh: &Mesh, by_file: &[Option<u32>], walk: &Walk, leaves_of: &[u32]) -> Regions {
    let nodes = &dump.nodes;
    let mut r = Regions {
        reach: vec![Aabb::EMPTY; nodes.len()],
        causes: BTreeMap::new(),
        shared: BTreeMap::new(),
        covered: vec![false; by_file.len()],
        degenerate_in: Tally::new(
            Group::Coverage,
            false,
            "degenerate (zero-area) triangle is in a leaf: harmless, no ray can hit it",
            "degenerate (zero-area) triangles are in leaves: harmless, no ray can hit them",
        ),
    };
    let mut last = vec![u32::MAX; by_file.len()];
    let mut path: Vec<usize> = Vec::new();
    let mut stack = vec![(0usize, 0usize)];
    while let Some((i, depth)) = stack.pop() {
        path.truncate(depth);
        path.push(i);
        let b = nodes[i].bounds();
        r.reach[i] = if depth == 0 { b } else { r.reach[path[depth - 1]].intersection(b) };
        for &k in nodes[i].children.iter().flatten().rev() {
            let k = k as usize;
            if k < nodes.len() && k != 0 && walk.parent[k] == i as u32 {
                stack.push((k, depth + 1));
            }
        }
        let Some(leaf) = leaf_prims(dump, i) else { continue };
        for &p in leaf {
            let Some(l) = last.get_mut(p as usize) else { continue };
            if std::mem::replace(l, i as u32) == i as u32 {
                continue; // the second reference in this leaf: already looked at
            }
            r.covered[p as usize] = true;
            let Some(m) = by_file[p as usize] else {
                r.degenerate_in.add(Some(i as u32), Some(p), format!("triangle {p} (leaf node {i})"));
                continue;
            };
            let t = mesh.triangle(m);
            if leaves_of[p as usize] > 1 {
                r.shared.entry(p).or_default().push(i);
                continue;
            }
            let tol = tolerance(&t);
            if holds(&r.reach[i], &t, tol) {
                continue;
            }
            // The highest node on the path whose region leaves the triangle out: each side of
            // the region only moves inwards going down, so each side's first failure is found
            // by a binary search, and the earliest of the six is the one.
            let (lo, hi) = (t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2]));
            let mut k = depth;
            for a in 0..3 {
                let low = path.partition_point(|&q| !(r.reach[q].min[a] - lo[a] > tol));
                let high = path.partition_point(|&q| !(hi[a] - r.reach[q].max[a] > tol));
                k = k.min(low).min(high);
            }
            // NaN in a box (a structure defect) breaks the order the search relies on.
            let k = k.min(depth);
            let worst = path[k];
            let e = excess(&nodes[worst].bounds(), &t);
            let child = (k < depth).then(|| path[k + 1] as u32);
            let cause = r.causes.entry((worst as u32, child)).or_default();
            cause.first.get_or_insert(p);
            // (NaN, a box that is no box, counts as farthest.)
            cause.excess = if e.0.is_nan() { f32::INFINITY } else { cause.excess.max(e.0) };
            cause.examples.push(match child {
                Some(_) => format!("triangle {p} {} (leaf node {i})", by(e)),
                None => format!("triangle {p} {}", by(e)),
            });
        }
    }
    r
}

/// Leaves whose own box is wrong: one finding, a leaf each; a wrong box above the leaves: one
/// finding per box, the triangles it leaves out listed.
fn report_causes(dump: &BvhDump, causes: BTreeMap<(u32, Option<u32>), Cause>, out: &mut Vec<Finding>) {
    let nodes = &dump.nodes;
    let mut leaves = Tally::new(
        Group::Bounds,
        true,
        "leaf's box does not hold all its triangles",
        "leaves' boxes do not hold all their triangles",
    );
    let mut leaf_causes = Vec::new();
    for ((worst, child), cause) in causes {
        let n = cause.examples.len();
        let Some(c) = child else {
            leaf_causes.push((worst, cause));
            continue;
        };
        let child_box = nodes[c as usize].bounds();
        let e = excess(&nodes[worst as usize].bounds(), &[child_box.min.into(), child_box.max.into()]);
        let text = if e.0 > 0.0 && !child_box.is_empty() {
            format!(
                "node {worst}'s box does not contain its child node {c} ({}): {} below node {c} stick{} out of node {worst}'s box",
                by(e),
                count(n, "triangle", "triangles"),
                if n == 1 { "s" } else { "" }
            )
        } else {
            format!("node {worst}'s box leaves out {} below its child node {c}", count(n, "triangle", "triangles"))
        };
        let mut f = defect(Group::Bounds, Some(worst), cause.first, text);
        f.examples = cause.examples;
        f.excess = Some(cause.excess);
        out.push(f);
    }
    // The leaf whose box misses by most first: it is the finding's node, the first cause.
    leaf_causes.sort_by(|a, b| b.1.excess.total_cmp(&a.1.excess));
    for (worst, cause) in leaf_causes {
        let n = cause.examples.len();
        let more = if n > 1 { format!(", and {} more", n - 1) } else { String::new() };
        leaves.add_by(
            Some(worst),
            cause.first,
            format!("leaf node {worst} ({}{more})", cause.examples[0]),
            cause.excess,
        );
    }
    leaves.finish(out);
}

/// Triangles cut among several leaves: each must be covered by the union of its leaves' regions.
fn report_cut(
    mesh: &Mesh,
    by_file: &[Option<u32>],
    shared: &BTreeMap<u32, Vec<usize>>,
    reach: &[Aabb],
    out: &mut Vec<Finding>,
) {
    let mut cut = Tally::new(
        Group::Bounds,
        true,
        "triangle cut among several leaves has a part in none of their boxes (within their ancestors')",
        "triangles cut among several leaves have parts in none of their boxes (within their ancestors')",
    );
    let mut complex = Tally::new(
        Group::Bounds,
        false,
        "triangle is cut among too many leaves to clip exactly (its rays are still checked)",
        "triangles are cut among too many leaves to clip exactly (their rays are still checked)",
    );
    for (&p, leaves) in shared {
        let Some(Some(m)) = by_file.get(p as usize) else { continue };
        let t = mesh.triangle(*m);
        let regions: Vec<Aabb> = leaves.iter().map(|&i| reach[i]).collect();
        let list = |k: usize| {
            let names: Vec<String> = leaves.iter().take(k).map(|i| format!("node {i}")).collect();
            format!("{}{}", names.join(", "), if leaves.len() > k { ", …" } else { "" })
        };
        match cover::uncovered(&t, &regions, tolerance(&t)) {
            cover::Coverage::Covered => {}
            cover::Coverage::Uncovered(q) => cut.add_by(
                Some(leaves[0] as u32),
                Some(p),
                format!("triangle {p} around ({}, {}, {}) (leaves {})", q.x, q.y, q.z, list(4)),
                // How far the part left out lies from the nearest of the boxes.
                regions.iter().map(|r| excess(r, &[q]).0).fold(f32::INFINITY, f32::min),
            ),
            cover::Coverage::TooComplex => {
                complex.add(Some(leaves[0] as u32), Some(p), format!("triangle {p} ({} leaves)", leaves.len()))
            }
        }
    }
    cut.finish(out);
    complex.finish(out);
}

/// Triangles in no leaf: a defect, or a warning for a degenerate one no ray can hit.
fn report_missing(mesh: &Mesh, by_file: &[Option<u32>], covered: &[bool], out: &mut Vec<Finding>) {
    let mut missing = Tally::new(Group::Coverage, true, "triangle is in no leaf", "triangles are in no leaf");
    let mut degenerate_out = Tally::new(
        Group::Coverage,
        false,
        "degenerate (zero-area) triangle is in no leaf: harmless, no ray can hit it",
        "degenerate (zero-area) triangles are in no leaf: harmless, no ray can hit them",
    );
    for t in (0..by_file.len()).filter(|&t| !covered[t]) {
        let degenerate = by_file[t].is_none_or(|m| crate::geometry::triangle_double_area(&mesh.triangle(m)) <= 0.0);
        let tally = if degenerate { &mut degenerate_out } else { &mut missing };
        tally.add(None, Some(t as u32), format!("triangle {t}"));
    }
    missing.finish(out);
    degenerate_out.finish(out);
}

/// A root box larger than the mesh's box: no defect (every ray still finds its hit), but a
/// comparison measures every tree against the mesh's box (`TreeStats::against`,
/// `Frame::ray_summary_in`), so the student is told by how much theirs is larger and why: the
/// leaf whose box reaches farthest out, and the degenerate triangle it keeps, if any (no ray can
/// hit one, so nothing else checks where its box is).
pub(super) fn root_box(dump: &BvhDump, mesh: &Mesh, walk: &Walk, out: &mut Vec<Finding>) {
    let mb = mesh.bounds();
    let Some(root) = dump.nodes.first().map(|n| n.bounds()) else { return };
    if mb.is_empty() || root.is_empty() {
        return;
    }
    let m = mb.min.abs().max(mb.max.abs()).max_element();
    let tol = (4.0 * f32::EPSILON * m).max(f32::MIN_POSITIVE);
    let e = excess(&mb, &[root.min.into(), root.max.into()]);
    if !(e.0 > tol) {
        return;
    }
    let by_file = mesh.triangles_by_file_number();
    let (nodes, prims) = (&dump.nodes, &dump.primitives);
    // The reached leaf whose box sticks out farthest, and a degenerate triangle it holds.
    let mut far: Option<(f32, usize)> = None;
    for (i, n) in nodes.iter().enumerate() {
        if !walk.reached[i] || n.children.is_some() {
            continue;
        }
        let b = n.bounds();
        let x = excess(&mb, &[b.min.into(), b.max.into()]).0;
        if x > tol && far.is_none_or(|(f, _)| x > f) {
            far = Some((x, i));
        }
    }
    let leaf_prims = |i: usize| {
        let n = &nodes[i];
        let (f, c) = (n.first.unwrap_or(0) as usize, n.count.unwrap_or(0) as usize);
        prims.get(f..f + c).unwrap_or_default()
    };
    let degenerate = far.and_then(|(_, i)| {
        leaf_prims(i).iter().copied().find(|&p| by_file.get(p as usize).is_some_and(|m| m.is_none()))
    });
    let ratio = root.area() as f64 / (mb.area() as f64).max(f64::MIN_POSITIVE);
    let why = match (far, degenerate) {
        (Some((_, i)), Some(p)) => format!(
            "leaf node {i} reaches farthest out; it holds triangle {p}, a degenerate (zero-area) triangle no ray can hit, which a BVH may leave out"
        ),
        (Some((_, i)), None) => format!("leaf node {i}'s box reaches farthest out, past every triangle it holds"),
        (None, _) => "its boxes are larger than the triangles they hold".into(),
    };
    let text = format!(
        "the root box is larger than the mesh's box ({}, {ratio:.2}× its area): {why}; the SAH cost and the rays per ray of comparisons are measured against the mesh's box, so the larger box costs what it costs",
        by(e)
    );
    let mut f = warning(Group::Bounds, far.map(|(_, i)| i as u32).or(Some(0)), degenerate, text);
    f.excess = Some(e.0);
    out.push(f);
}
