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
            if kids.len() < 2 || kids.len() > 4 {
                out.push(defect(
                    Group::Structure,
                    id,
                    None,
                    format!("node {i} has {} children; 2 to 4 are supported", kids.len()),
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
    // Coverage and bounds over the reached leaves.
    let mut covered = vec![false; tris];
    for i in (0..nodes.len()).filter(|&i| reached[i]) {
        let n = &nodes[i];
        let (Some(f), Some(c), None) = (n.first, n.count, &n.children) else { continue };
        let (f, c) = (f as usize, c as usize);
        if f + c > prims.len() {
            continue;
        }
        for &p in &prims[f..f + c] {
            let Some(Some(m)) = by_file.get(p as usize) else { continue };
            let t = mesh.triangle(*m);
            covered[p as usize] = true;
            // The highest node on the path from the root whose box does not hold the triangle.
            let mut path = vec![i];
            while let Some(&q) = parent.get(*path.last().unwrap()).filter(|&&q| q != u32::MAX) {
                path.push(q as usize);
            }
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

/// Trace `rays` (with their pixels, if from a frame) through `bvh` and the linear scan; the ones
/// whose hits differ (a different distance; a different triangle only at a different distance).
pub fn wrong_rays(
    bvh: &impl Accelerator,
    mesh: &Mesh,
    rays: &[(Ray, Option<(u32, u32)>)],
    opts: TraceOptions,
) -> Vec<WrongRay> {
    // The linear scan's hits. Past a few thousand triangles they are found through bvhscope's own
    // SAH tree instead, which returns the linear scan's hit for every ray (tests/correctness.rs,
    // tests/watertight_traversal.rs): a million rays over a million triangles one by one would
    // take days.
    let linear = LinearScan::new(mesh);
    let tree = (mesh.triangle_count() > LINEAR_REFERENCE_MAX)
        .then(|| Bvh::build(mesh, &BuildParams { layout: super::Layout::Binary, ..BuildParams::default() }));
    let key = |h: Option<Hit>| h.map(|h| (mesh.file_number(h.prim), h.t));
    rays.par_iter()
        .filter_map(|(r, pixel)| {
            let want = match &tree {
                Some(t) => t.closest_hit(&mut r.clone(), opts, &mut NoStats),
                None => linear.closest_hit(&mut r.clone(), opts, &mut NoStats),
            };
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
        return Checked { findings: out, tree: None, wrong_pixels: Vec::new() };
    }
    let (bvh, imported) = match super::imported::import(dump, mesh, path) {
        Ok(b) => b,
        Err(why) => {
            out.push(warning(Group::Rays, None, None, format!("rays not traced: {why}")));
            return Checked { findings: out, tree: None, wrong_pixels: Vec::new() };
        }
    };
    let all = check_rays(mesh, camera, rays);
    let wrong = wrong_rays(&bvh, mesh, &all, opts);
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
    Checked { findings: out, tree: Some((bvh, imported)), wrong_pixels }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::dump::DumpNode;
    use crate::mesh::generate;

    /// Four triangles in a row along x, each a unit square's half: triangle k spans x k..k+1.
    fn row() -> Mesh {
        let mut p = Vec::new();
        let mut t = Vec::new();
        for k in 0..4 {
            let i = p.len() as u32;
            let x = k as f32;
            p.extend([Vec3::new(x, 0.0, 0.0), Vec3::new(x + 1.0, 0.0, 0.0), Vec3::new(x, 1.0, 0.0)]);
            t.push([i, i + 1, i + 2]);
        }
        Mesh::from_triangles("row", p, t)
    }

    fn node(min: [f32; 3], max: [f32; 3]) -> DumpNode {
        DumpNode { min, max, children: None, first: None, count: None, axis: None }
    }

    /// A correct dump of `row()` with its nodes out of order: root 0 with children 3 and 1; leaf 3
    /// holds primitives[0..2] = T1, T0, leaf 1 holds [2..4] = T3, T2; node 2, an empty leaf, is
    /// never reached (a warning).
    fn good() -> BvhDump {
        let mut root = node([0.0, 0.0, 0.0], [4.0, 1.0, 0.0]);
        root.children = Some(vec![3, 1]);
        root.axis = Some(0);
        let mut left = node([0.0, 0.0, 0.0], [2.0, 1.0, 0.0]);
        (left.first, left.count) = (Some(0), Some(2));
        let mut right = node([2.0, 0.0, 0.0], [4.0, 1.0, 0.0]);
        (right.first, right.count) = (Some(2), Some(2));
        let spare = node([0.0, 0.0, 0.0], [0.0, 0.0, 0.0]);
        let mut spare = spare;
        (spare.first, spare.count) = (Some(0), Some(0));
        BvhDump {
            format: "bvhscope-bvh".into(),
            version: 1,
            mesh: None,
            primitives: vec![1, 0, 3, 2],
            nodes: vec![root, right, spare, left],
        }
    }

    fn camera(mesh: &Mesh) -> crate::render::Camera {
        crate::render::Camera::framing_up(&mesh.bounds(), 32, 24, crate::render::UpAxis::Y, 45.0)
    }

    /// The findings and the traced tree of `d` over `mesh`, with `n` random rays.
    fn run(d: &BvhDump, mesh: &Mesh, n: usize) -> (Vec<Finding>, Option<AnyBvh>) {
        let c = check(d, "test.json".as_ref(), mesh, &camera(mesh), n, TraceOptions::default());
        (c.findings, c.tree.map(|(b, _)| b))
    }

    #[test]
    fn a_correct_shuffled_dump_has_no_defect_and_traces_like_the_linear_scan() {
        let mesh = row();
        let (f, bvh) = run(&good(), &mesh, 2000);
        assert!(f.iter().all(|f| !f.defect), "{f:?}");
        assert_eq!(f.iter().filter(|f| f.node == Some(2)).count(), 1, "node 2 is never reached: a warning");
        let Some(AnyBvh::Binary(bvh)) = bvh else { panic!("a binary tree") };
        assert_eq!(bvh.nodes.len(), 3);
    }

    #[test]
    fn each_defect_names_its_node_or_triangle() {
        let mesh = row();
        let find = |d: &BvhDump| run(d, &mesh, 500).0;
        let has = |f: &[Finding], group: Group, node: Option<u32>, tri: Option<u32>, words: &str| {
            f.iter()
                .any(|x| x.defect && x.group == group && x.node == node && x.triangle == tri && x.text.contains(words))
        };
        // Structure: a child past the end.
        let mut d = good();
        d.nodes[0].children = Some(vec![3, 9]);
        assert!(has(&find(&d), Group::Structure, Some(0), None, "child 9 is past the last node"));
        // A leaf range past the end of the primitives.
        let mut d = good();
        d.nodes[1].count = Some(5);
        assert!(has(&find(&d), Group::Structure, Some(1), None, "past the end of primitives"));
        // A primitive that is no triangle of the mesh.
        let mut d = good();
        d.primitives[2] = 40;
        assert!(has(&find(&d), Group::Structure, Some(1), None, "primitives[2] = 40"));
        // Both leaf and interior; too many children.
        let mut d = good();
        d.nodes[3].children = Some(vec![1, 2]);
        assert!(has(&find(&d), Group::Structure, Some(3), None, "both a leaf"));
        let mut d = good();
        d.nodes[0].children = Some(vec![3, 1, 2, 2, 2]);
        assert!(has(&find(&d), Group::Structure, Some(0), None, "5 children"));
        // Reached twice: a cycle and two parents.
        let mut d = good();
        d.nodes[3].children = Some(vec![0, 1]);
        (d.nodes[3].first, d.nodes[3].count) = (None, None);
        assert!(find(&d).iter().any(|f| f.defect && f.text.contains("reached twice") && f.text.contains("a cycle")));
        let mut d = good();
        d.nodes[0].children = Some(vec![1, 1]);
        assert!(has(&find(&d), Group::Structure, Some(1), None, "two parents"));
        // An inverted box and a NaN box.
        let mut d = good();
        d.nodes[1].min[0] = 5.0;
        assert!(has(&find(&d), Group::Structure, Some(1), None, "inverted box on x"));
        let mut d = good();
        d.nodes[1].max[1] = f32::NAN;
        assert!(has(&find(&d), Group::Structure, Some(1), None, "NaN"));
        // Coverage: a triangle in no leaf.
        let mut d = good();
        d.primitives = vec![1, 0, 3, 3];
        assert!(has(&find(&d), Group::Coverage, None, Some(2), "triangle 2 is in no leaf"));
        // Bounds: the leaf's box too small, and an ancestor's.
        let mut d = good();
        d.nodes[1].max[0] = 3.5;
        let f = find(&d);
        assert!(has(&f, Group::Bounds, Some(1), Some(3), "by 0.5"), "{f:?}");
        assert!(has(&f, Group::Rays, None, Some(3), "hit differently"), "rays past x = 3.5 miss the leaf: {f:?}");
        let mut d = good();
        d.nodes[0].max[0] = 3.0;
        assert!(has(&find(&d), Group::Bounds, Some(0), Some(3), "ancestor node 0"));
    }

    /// bvhscope's own tree, written and read back (JSON and text), is the same tree: the same
    /// nodes, SAH cost and counts for every ray, and no finding.
    #[test]
    fn a_round_trip_gives_back_the_same_tree() {
        let mesh = generate::torus_knot(2, 3, 0.3, 64, 8);
        let bvh = Bvh::build(&mesh, &BuildParams { layout: crate::bvh::Layout::Binary, ..BuildParams::default() });
        let dump = BvhDump::of_bvh(&bvh, &mesh, None);
        let json: BvhDump = serde_json::from_str(&serde_json::to_string(&dump).unwrap()).unwrap();
        let dir = std::env::temp_dir().join(format!("bvhscope-dump-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let text_path = dir.join("tree.txt");
        std::fs::write(&text_path, dump.to_text()).unwrap();
        let text = BvhDump::read(&text_path).unwrap();
        for back in [json, text] {
            let (f, imported) = run(&back, &mesh, 2000);
            assert!(f.iter().all(|f| !f.defect), "{f:?}");
            let Some(AnyBvh::Binary(imported)) = imported else { panic!("a binary tree") };
            assert_eq!(imported.nodes.len(), bvh.nodes.len());
            let (a, b) = (crate::bvh::TreeStats::of(&bvh).sah_cost, crate::bvh::TreeStats::of(&imported).sah_cost);
            assert!((a - b).abs() <= 1e-9 * a, "{a} vs {b}");
            for (r, _) in check_rays(&mesh, &camera(&mesh), 200) {
                let (mut ca, mut cb) = (crate::bvh::RayCounters::default(), crate::bvh::RayCounters::default());
                let ha = bvh.closest_hit(&mut r.clone(), TraceOptions::default(), &mut ca);
                let hb = imported.closest_hit(&mut r.clone(), TraceOptions::default(), &mut cb);
                assert_eq!((ha, ca), (hb, cb));
            }
        }
    }

    /// A triangle in two leaves (as spatial splits make) is fine, and traced in both; a 4-wide
    /// tree is checked for structure, coverage and bounds, and traced.
    #[test]
    fn duplicated_references_and_four_wide_trees() {
        let mesh = row();
        let mut d = good();
        // Triangle 1 spans x 1..2: also put it in the right leaf, whose box then grows to hold it.
        d.primitives = vec![1, 0, 3, 2, 1];
        d.nodes[1].first = Some(2);
        d.nodes[1].count = Some(3);
        d.nodes[1].min[0] = 1.0;
        let (f, bvh) = run(&d, &mesh, 2000);
        assert!(f.iter().all(|f| !f.defect), "{f:?}");
        let Some(AnyBvh::Binary(bvh)) = bvh else { panic!("a binary tree") };
        assert_eq!(bvh.prim_ids.len(), 5, "triangle 1 twice");
        // Four leaves under one root: 4-wide.
        let leaf = |k: u32| {
            let mut n = node([k as f32, 0.0, 0.0], [k as f32 + 1.0, 1.0, 0.0]);
            (n.first, n.count) = (Some(k), Some(1));
            n
        };
        let mut root = node([0.0, 0.0, 0.0], [4.0, 1.0, 0.0]);
        root.children = Some(vec![1, 2, 3, 4]);
        let wide = BvhDump {
            format: "bvhscope-bvh".into(),
            version: 1,
            mesh: None,
            primitives: vec![0, 1, 2, 3],
            nodes: vec![root, leaf(0), leaf(1), leaf(2), leaf(3)],
        };
        let (f, bvh) = run(&wide, &mesh, 100);
        assert!(f.iter().all(|f| !f.defect), "{f:?}");
        let Some(AnyBvh::Wide(w)) = bvh else { panic!("a 4-wide tree") };
        assert_eq!((w.nodes.len(), w.nodes[0].valid), (1, 0b1111), "one wide node of four leaves");
        let mut broken = wide.clone();
        broken.nodes[3].max[0] = 2.5;
        let (f, _) = run(&broken, &mesh, 100);
        assert!(
            f.iter().any(|f| f.defect && f.group == Group::Bounds && f.node == Some(3) && f.triangle == Some(2)),
            "{f:?}"
        );
        // The box too small misses rays through the 4-wide traversal too, named by a pixel.
        assert!(f.iter().any(|f| f.defect && f.group == Group::Rays && f.text.contains("pixel")), "{f:?}");
    }

    /// bvhscope's 4-wide tree written as a dump checks clean: every node of 2 to 4 children, every
    /// triangle in a leaf inside its boxes.
    #[test]
    fn an_exported_four_wide_tree_checks_clean() {
        let mesh = generate::torus_knot(2, 3, 0.3, 64, 8);
        let w = crate::bvh::WideBvh::from_binary(Bvh::build(&mesh, &BuildParams::default()));
        let d = BvhDump::of_wide(&w, &mesh, None);
        assert!(d.nodes.iter().any(|n| n.children.as_ref().is_some_and(|k| k.len() > 2)));
        let f = check_tree(&d, &mesh, 1e-5);
        assert!(f.is_empty(), "{f:?}");
        let tiny = Mesh::from_triangles("one", vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]]);
        let w = crate::bvh::WideBvh::from_binary(Bvh::build(&tiny, &BuildParams::default()));
        let d = BvhDump::of_wide(&w, &tiny, None);
        assert_eq!(d.nodes.len(), 1, "one leaf");
        assert!(check_tree(&d, &tiny, 1e-5).is_empty());
    }

    /// A dump compressed with gzip reads as the JSON it holds.
    #[test]
    fn a_gzip_dump_reads_like_its_json() {
        use std::io::Write;
        let dir = std::env::temp_dir().join(format!("bvhscope-dump-gz-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let d = good();
        let path = dir.join("tree.json.gz");
        let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
        gz.write_all(serde_json::to_string(&d).unwrap().as_bytes()).unwrap();
        std::fs::write(&path, gz.finish().unwrap()).unwrap();
        assert_eq!(BvhDump::read(&path).unwrap(), d);
    }

    #[test]
    fn unreadable_dumps_say_why() {
        let dir = std::env::temp_dir().join(format!("bvhscope-dump-bad-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let w = |name: &str, text: &str| {
            let p = dir.join(name);
            std::fs::write(&p, text).unwrap();
            BvhDump::read(&p).unwrap_err().to_string()
        };
        assert!(w("future.json", r#"{"format": "bvhscope-bvh", "version": 2, "primitives": [], "nodes": []}"#)
            .contains("version 2"));
        assert!(w("broken.json", r#"{"format": "bvhscope-bvh", "version": 1, "nodes": [}"#).contains("broken JSON"));
        assert!(w("other.json", r#"{"format": "gltf"}"#).contains("\"gltf\""));
        assert!(w("bad.txt", "bvhscope-bvh 1\nnode 0 0 0 1 1 x leaf 0 1\n").contains("line 2"));
    }
}
