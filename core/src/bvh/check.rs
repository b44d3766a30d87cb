//! The checker of an imported BVH (`bvh::dump`): everything wrong with it, each finding naming
//! the node as `node N` and the triangle as `triangle N`, in four groups: structure (indices,
//! ranges, kinds, nodes reached twice, boxes), coverage (triangles in no leaf, nodes never
//! reached), bounds (a triangle outside its leaf's box or an ancestor's) and rays (the tree traced
//! by bvhscope's own traversal against the linear scan).

use super::dump::BvhDump;
use super::imported::Imported;
use super::{Accelerator, AnyBvh, BuildParams, Bvh, Hit, LinearScan, NoStats, TraceOptions};
use crate::geometry::{Aabb, Ray};
use crate::mesh::Mesh;
use glam::Vec3;
use rayon::prelude::*;
use serde::Serialize;

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
pub enum Group {
    Structure,
    Coverage,
    Bounds,
    Rays,
}

impl Group {
    pub const ALL: [Group; 4] = [Group::Structure, Group::Coverage, Group::Bounds, Group::Rays];
    pub fn label(self) -> &'static str {
        match self {
            Group::Structure => "structure",
            Group::Coverage => "coverage",
            Group::Bounds => "bounds",
            Group::Rays => "rays",
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Finding {
    pub group: Group,
    /// A defect (the tree is wrong) or a warning (worth a look, not wrong).
    pub defect: bool,
    pub text: String,
    pub node: Option<u32>,
    pub triangle: Option<u32>,
}

fn defect(group: Group, node: Option<u32>, triangle: Option<u32>, text: String) -> Finding {
    Finding { group, defect: true, text, node, triangle }
}

fn warning(group: Group, node: Option<u32>, triangle: Option<u32>, text: String) -> Finding {
    Finding { group, defect: false, text, node, triangle }
}

/// How far `t` sticks out of `b` (0 when inside).
fn excess(b: &Aabb, t: &[Vec3; 3]) -> f32 {
    let (lo, hi) = (Vec3::from(b.min), Vec3::from(b.max));
    t.iter().map(|p| (lo - *p).max(*p - hi).max_element().max(0.0)).fold(0.0, f32::max)
}

/// The structure, coverage and bounds of `dump` over `mesh`. Bounds allow `tolerance` (a
/// dump printed with six decimals rounds its boxes by half a millionth).
pub fn check_tree(dump: &BvhDump, mesh: &Mesh, tolerance: f32) -> Vec<Finding> {
    let mut out = Vec::new();
    // Primitives are numbers of the file's triangles (zero-area ones included, which the loader
    // drops); findings name triangles by those numbers.
    let by_file = mesh.triangles_by_file_number();
    let (nodes, prims, tris) = (&dump.nodes, &dump.primitives, by_file.len());
    if nodes.is_empty() {
        out.push(defect(Group::Structure, None, None, "the dump has no nodes (node 0 is the root)".into()));
        return out;
    }
    // Each node on its own.
    for (i, n) in nodes.iter().enumerate() {
        let id = Some(i as u32);
        let leafish = n.first.is_some() || n.count.is_some();
        match (&n.children, leafish) {
            (Some(_), true) => out.push(defect(
                Group::Structure,
                id,
                None,
                format!("node {i} is both a leaf (first/count) and interior (children)"),
            )),
            (None, false) => out.push(defect(
                Group::Structure,
                id,
                None,
                format!("node {i} is neither a leaf nor interior: no children, no first/count"),
            )),
            _ => {}
        }
        if let Some(kids) = &n.children {
            if kids.len() < 2 || kids.len() > 8 {
                out.push(defect(
                    Group::Structure,
                    id,
                    None,
                    format!("node {i} has {} children; 2 to 8 are supported", kids.len()),
                ));
            }
            for &k in kids {
                if k as usize >= nodes.len() {
                    out.push(defect(
                        Group::Structure,
                        id,
                        None,
                        format!("node {i}: child {k} is past the last node ({})", nodes.len() - 1),
                    ));
                }
            }
        }
        if n.children.is_none() && leafish {
            let (f, c) = (n.first.unwrap_or(0) as usize, n.count.unwrap_or(0) as usize);
            if n.first.is_none() || n.count.is_none() {
                out.push(defect(Group::Structure, id, None, format!("node {i}: a leaf needs both first and count")));
            } else if f + c > prims.len() {
                out.push(defect(
                    Group::Structure,
                    id,
                    None,
                    format!("node {i}: leaf range {f}..{} is past the end of primitives ({})", f + c, prims.len()),
                ));
            } else {
                for (k, &p) in prims[f..f + c].iter().enumerate() {
                    if p as usize >= tris {
                        out.push(defect(
                            Group::Structure,
                            id,
                            None,
                            format!("node {i}: primitives[{}] = {p}, but the mesh has {tris} triangles", f + k),
                        ));
                    }
                }
            }
        }
        let (lo, hi) = (Vec3::from(n.min), Vec3::from(n.max));
        if !(lo.is_finite() && hi.is_finite()) {
            out.push(defect(Group::Structure, id, None, format!("node {i}: its box has a NaN or infinite coordinate")));
        } else if let Some(a) = (0..3).find(|&a| lo[a] > hi[a]) {
            out.push(defect(
                Group::Structure,
                id,
                None,
                format!("node {i}: inverted box on {} (min {} > max {})", ["x", "y", "z"][a], lo[a], hi[a]),
            ));
        }
    }
    // The walk from the root: nodes reached twice, never reached; each reached node's parent.
    let mut parent = vec![u32::MAX; nodes.len()];
    let mut reached = vec![false; nodes.len()];
    let mut stack = vec![0usize];
    reached[0] = true;
    while let Some(i) = stack.pop() {
        for &k in nodes[i].children.iter().flatten() {
            let k = k as usize;
            if k >= nodes.len() {
                continue;
            }
            if reached[k] {
                let why = if k == 0 || is_ancestor(&parent, k, i) { "a cycle" } else { "two parents" };
                out.push(defect(
                    Group::Structure,
                    Some(k as u32),
                    None,
                    format!("node {k} is reached twice (from node {i}: {why})"),
                ));
                continue;
            }
            reached[k] = true;
            parent[k] = i as u32;
            stack.push(k);
        }
    }
    let unreached: Vec<usize> = (0..nodes.len()).filter(|&i| !reached[i]).collect();
    if !unreached.is_empty() {
        let list: Vec<String> = unreached.iter().take(8).map(|i| format!("node {i}")).collect();
        out.push(warning(
            Group::Coverage,
            Some(unreached[0] as u32),
            None,
            format!(
                "{} nodes are never reached from the root: {}{}",
                unreached.len(),
                list.join(", "),
                if unreached.len() > 8 { ", …" } else { "" }
            ),
        ));
    }
    // Coverage and bounds over the reached leaves. A triangle in one leaf must lie inside that
    // leaf's box and every ancestor's; one referenced by several leaves (an SBVH's spatial splits
    // cut it) may be split among them, so each of its points must lie inside one of them.
    let reached_leaves = || {
        (0..nodes.len()).filter(|&i| reached[i]).filter_map(|i| {
            let n = &nodes[i];
            let (Some(f), Some(c), None) = (n.first, n.count, &n.children) else { return None };
            let (f, c) = (f as usize, c as usize);
            (f + c <= prims.len()).then(|| (i, &prims[f..f + c]))
        })
    };
    let path_of = |i: usize| {
        let mut path = vec![i];
        while let Some(&q) = parent.get(*path.last().unwrap()).filter(|&&q| q != u32::MAX) {
            path.push(q as usize);
        }
        path
    };
    let mut references = vec![0u32; tris];
    for (_, leaf) in reached_leaves() {
        for &p in leaf {
            if let Some(r) = references.get_mut(p as usize) {
                *r += 1;
            }
        }
    }
    let mut covered = vec![false; tris];
    let mut shared: std::collections::BTreeMap<u32, Vec<usize>> = Default::default();
    for (i, leaf) in reached_leaves() {
        for &p in leaf {
            let Some(Some(m)) = by_file.get(p as usize) else { continue };
            covered[p as usize] = true;
            if references[p as usize] > 1 {
                shared.entry(p).or_default().push(i);
                continue;
            }
            let t = mesh.triangle(*m);
            // The highest node on the path from the root whose box does not hold the triangle.
            let path = path_of(i);
            if let Some(&worst) = path.iter().rev().find(|&&a| excess(&nodes[a].bounds(), &t) > tolerance) {
                let by = excess(&nodes[worst].bounds(), &t);
                let whose =
                    if worst == i { "its leaf's".to_string() } else { format!("leaf {i}'s ancestor node {worst}'s") };
                out.push(defect(
                    Group::Bounds,
                    Some(worst as u32),
                    Some(p),
                    format!("triangle {p} (in leaf node {i}) sticks out of {whose} box, node {worst}, by {by}"),
                ));
            }
        }
    }
    for (p, leaves) in shared {
        let Some(Some(m)) = by_file.get(p as usize) else { continue };
        let t = mesh.triangle(*m);
        // What a ray reaches of each leaf: the part of its box inside every ancestor's box.
        let reach: Vec<Aabb> = leaves
            .iter()
            .map(|&i| {
                path_of(i).iter().fold(Aabb::new(Vec3::NEG_INFINITY, Vec3::INFINITY), |b, &a| {
                    let n = nodes[a].bounds();
                    Aabb { min: b.min.max(n.min), max: b.max.min(n.max) }
                })
            })
            .collect();
        let inside = |q: Vec3| reach.iter().any(|b| excess(b, &[q; 3]) <= tolerance);
        let outside = triangle_samples(&t).find(|&q| !inside(q));
        if let Some(q) = outside {
            let list: Vec<String> = leaves.iter().take(6).map(|i| format!("node {i}")).collect();
            out.push(defect(
                Group::Bounds,
                Some(leaves[0] as u32),
                Some(p),
                format!(
                    "triangle {p} is split among {} leaves ({}{}), but its point ({}, {}, {}) lies in none of their boxes within their ancestors'",
                    leaves.len(),
                    list.join(", "),
                    if leaves.len() > 6 { ", …" } else { "" },
                    q.x,
                    q.y,
                    q.z
                ),
            ));
        }
    }
    for (t, _) in covered.iter().enumerate().filter(|(_, c)| !**c) {
        // A number the loader dropped is a zero-area triangle.
        let degenerate = by_file[t].is_none_or(|m| crate::geometry::triangle_double_area(&mesh.triangle(m)) <= 0.0);
        let text = format!(
            "triangle {t} is in no leaf{}",
            if degenerate { " (it is degenerate: no ray can hit it)" } else { "" }
        );
        out.push(if degenerate {
            warning(Group::Coverage, None, Some(t as u32), text)
        } else {
            defect(Group::Coverage, None, Some(t as u32), text)
        });
    }
    out
}

/// Points of a triangle a split among leaves must cover: its vertices, and a barycentric grid of
/// 16 steps a side (edges included).
fn triangle_samples(t: &[Vec3; 3]) -> impl Iterator<Item = Vec3> + '_ {
    const STEPS: u32 = 16;
    (0..=STEPS).flat_map(move |i| {
        (0..=STEPS - i).map(move |j| {
            let (u, v) = (i as f32 / STEPS as f32, j as f32 / STEPS as f32);
            match (i, j) {
                (0, 0) => t[0],
                (STEPS, _) => t[1],
                (_, STEPS) => t[2],
                _ => t[0] * (1.0 - u - v) + t[1] * u + t[2] * v,
            }
        })
    })
}

fn is_ancestor(parent: &[u32], a: usize, mut n: usize) -> bool {
    while n != a {
        match parent.get(n) {
            Some(&p) if p != u32::MAX => n = p as usize,
            _ => return false,
        }
    }
    true
}

/// Meshes up to this many triangles are checked against the linear scan itself.
pub const LINEAR_REFERENCE_MAX: usize = 4096;

/// A ray whose hit through the imported tree differs from the linear scan's.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct WrongRay {
    pub origin: [f32; 3],
    pub dir: [f32; 3],
    pub pixel: Option<(u32, u32)>,
    pub want: Option<(u32, f32)>,
    pub got: Option<(u32, f32)>,
}

/// Where the checker takes a ray's true hit from: the linear scan's hits. Past a few thousand
/// triangles they are found through bvhscope's own SAH tree instead, which returns the linear
/// scan's hit for every ray (tests/bvh_matches_linear.rs, tests/watertight_traversal.rs): a
/// million rays over a million triangles one by one would take days. Made once per mesh (the
/// app keeps it for every view of an imported tree).
pub enum Reference {
    Linear(LinearScan),
    Tree(Box<Bvh>),
}

impl Reference {
    pub fn of(mesh: &Mesh) -> Reference {
        if mesh.triangle_count() > LINEAR_REFERENCE_MAX {
            Reference::Tree(Box::new(Bvh::build(
                mesh,
                &BuildParams { layout: super::Layout::Binary, ..BuildParams::default() },
            )))
        } else {
            Reference::Linear(LinearScan::new(mesh))
        }
    }

    fn closest_hit(&self, ray: &Ray, opts: TraceOptions) -> Option<Hit> {
        match self {
            Reference::Linear(l) => l.closest_hit(&mut ray.clone(), opts, &mut NoStats),
            Reference::Tree(t) => t.closest_hit(&mut ray.clone(), opts, &mut NoStats),
        }
    }
}

/// Trace `rays` (with their pixels, if from a frame) through `bvh` and the `reference`; the ones
/// whose hits differ (a different distance; a different triangle only at a different distance).
pub fn wrong_rays(
    bvh: &impl Accelerator,
    mesh: &Mesh,
    reference: &Reference,
    rays: &[(Ray, Option<(u32, u32)>)],
    opts: TraceOptions,
) -> Vec<WrongRay> {
    let key = |h: Option<Hit>| h.map(|h| (mesh.file_number(h.prim), h.t));
    rays.par_iter()
        .filter_map(|(r, pixel)| {
            let want = reference.closest_hit(r, opts);
            let got = bvh.closest_hit(&mut r.clone(), opts, &mut NoStats);
            let same = match (want, got) {
                (None, None) => true,
                (Some(w), Some(g)) => w.t == g.t,
                _ => false,
            };
            (!same).then(|| WrongRay {
                origin: r.origin().to_array(),
                dir: r.dir().to_array(),
                pixel: *pixel,
                want: key(want),
                got: key(got),
            })
        })
        .collect()
}

/// `n` rays at the mesh from random points around it (fixed seed), and the `camera`'s primary
/// rays: what the checker traces.
pub fn check_rays(mesh: &Mesh, camera: &crate::render::Camera, n: usize) -> Vec<(Ray, Option<(u32, u32)>)> {
    let b = mesh.bounds();
    let (c, e) = (b.center(), b.extent().max(Vec3::splat(1e-6)));
    let gen = camera.ray_gen();
    let mut out: Vec<(Ray, Option<(u32, u32)>)> = (0..camera.height)
        .flat_map(|y| (0..camera.width).map(move |x| (x, y)))
        .map(|(x, y)| (gen.pixel_ray(x, y), Some((x, y))))
        .collect();
    let mut s = 0x9E37_79B9_7F4A_7C15u64;
    let mut r = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 40) as f32 / (1u64 << 24) as f32 - 0.5
    };
    for _ in 0..n {
        let o = c + Vec3::new(r(), r(), r()) * e * 3.0;
        let t = c + Vec3::new(r(), r(), r()) * e;
        out.push((Ray::new(o, t - o), None));
    }
    out
}

/// How far a dump's boxes may miss their triangles over `mesh` (a dump printed with six decimals
/// rounds its boxes by half a millionth of the mesh's size).
pub fn tolerance(mesh: &Mesh) -> f32 {
    1e-6 * mesh.bounds().extent().length().max(1.0)
}

/// The tree of `dump` as bvhscope traces it (`imported::import`), when its structure is sound and
/// it can be traced; otherwise why not.
pub fn traceable(
    findings: &[Finding],
    dump: &BvhDump,
    mesh: &Mesh,
    path: &std::path::Path,
) -> Result<(AnyBvh, Imported), String> {
    if findings.iter().any(|f| f.group == Group::Structure && f.defect) {
        return Err("its structure has defects".into());
    }
    super::imported::import(dump, mesh, path)
}

/// What `check` found.
pub struct Checked {
    pub findings: Vec<Finding>,
    /// The tree as traced, when its structure is sound and it can be traced.
    pub tree: Option<(AnyBvh, Imported)>,
    /// The camera's pixels whose hit through the tree differs from the linear scan's (the app's
    /// red mask).
    pub wrong_pixels: Vec<(u32, u32)>,
    /// What the rays were checked against, when they were traced.
    pub reference: Option<Reference>,
}

/// Findings of every group for `dump` (read from `path`) over `mesh`: the tree's, then, when its
/// structure is sound, the rays'. Returns the findings and the imported tree (when it could be made).
pub fn check(
    dump: &BvhDump,
    path: &std::path::Path,
    mesh: &Mesh,
    camera: &crate::render::Camera,
    rays: usize,
    opts: TraceOptions,
) -> Checked {
    let mut out = check_tree(dump, mesh, tolerance(mesh));
    if out.iter().any(|f| f.group == Group::Structure && f.defect) {
        return Checked { findings: out, tree: None, wrong_pixels: Vec::new(), reference: None };
    }
    let (bvh, imported) = match super::imported::import(dump, mesh, path) {
        Ok(b) => b,
        Err(why) => {
            out.push(warning(Group::Rays, None, None, format!("rays not traced: {why}")));
            return Checked { findings: out, tree: None, wrong_pixels: Vec::new(), reference: None };
        }
    };
    let all = check_rays(mesh, camera, rays);
    let reference = Reference::of(mesh);
    let wrong = wrong_rays(&bvh, mesh, &reference, &all, opts);
    // A pixel's ray for the example when there is one (easier to find in the image).
    if let Some(w) = wrong.iter().find(|w| w.pixel.is_some()).or(wrong.first()) {
        let v = |a: [f32; 3]| format!("{},{},{}", a[0], a[1], a[2]);
        let at = match w.pixel {
            Some((x, y)) => format!("pixel {x},{y} (trace MESH --bvh FILE --pixel {x},{y} shows its walk)"),
            None => format!(
                "the ray {}:{} (trace MESH --bvh FILE --ray {}:{} shows its walk)",
                v(w.origin),
                v(w.dir),
                v(w.origin),
                v(w.dir)
            ),
        };
        let show = |h: Option<(u32, f32)>| h.map_or("nothing".to_string(), |(p, t)| format!("triangle {p} at t = {t}"));
        out.push(defect(Group::Rays, None, w.got.or(w.want).map(|h| h.0), format!(
            "{} of {} rays hit differently from the linear scan; e.g. {at}: the linear scan hits {}, the imported tree {}",
            wrong.len(), all.len(), show(w.want), show(w.got)
        )));
    }
    let wrong_pixels = wrong.iter().filter_map(|w| w.pixel).collect();
    Checked { findings: out, tree: Some((bvh, imported)), wrong_pixels, reference: Some(reference) }
}

#[cfg(test)]
#[path = "check_tests.rs"]
mod tests;
