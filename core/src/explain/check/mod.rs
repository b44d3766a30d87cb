//! The checker of an imported BVH (`dump`): everything wrong with it, in four groups: structure
//! (indices, ranges, kinds, nodes reached twice, boxes), coverage (triangles in no leaf, nodes
//! never reached), bounds (a triangle outside its leaf's box or an ancestor's, found exactly) and
//! rays (the tree traced by bvhscope's own traversal against the linear scan). Each finding names
//! its root cause once (a node, a triangle) and lists what follows from it, so one wrong box is
//! one line, not a hundred.
//!
//! A checker that passes a wrong tree is worse than none, so the bounds are exact: a triangle is
//! checked against what a ray can reach of its leaf (the leaf's box inside every ancestor's), with
//! a tolerance of a few ulps of the triangle's own coordinates (`tolerance`), never of the scene's
//! size; a triangle cut among several leaves is clipped against their boxes (`cover`). And the
//! checker is bounded: references are counted before any is followed (`max_references`), rays
//! are traced in batches (`rays`), deep trees are walked without recursion.

#[cfg(test)]
mod adversarial_tests;
mod bounds;
#[cfg(test)]
mod check_tests;
mod cover;
mod rays;
mod structure;

pub use rays::{check_rays, wrong_rays, RaySet, Reference, WrongRay, WrongRays, LINEAR_REFERENCE_MAX, MAX_RAYS};

use crate::bvh::imported::Imported;
use crate::bvh::{AnyBvh, TraceOptions};
use crate::dump::{import, BvhDump};
use crate::mesh::Mesh;
use crate::work::{Cancelled, WorkControl};
use glam::Vec3;
use serde::Serialize;
use std::path::Path;

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

/// One thing found: its cause (`text`, naming the node or triangle), and the cases it covers
/// (`examples`: the triangles a wrong box leaves out, the nodes of one kind of defect…).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Finding {
    pub group: Group,
    /// A defect (the tree is wrong) or a warning (worth a look, not wrong).
    pub defect: bool,
    pub text: String,
    /// The node the finding is about (the first, for a finding of several).
    pub node: Option<u32>,
    /// The triangle it is about (the first, for a finding of several).
    pub triangle: Option<u32>,
    /// Every case, in order (empty for a finding that is one case).
    pub examples: Vec<String>,
    /// How far a box misses what it must hold, the largest of the finding's cases (bounds
    /// findings): what orders them, a wrong box before a rounding.
    pub excess: Option<f32>,
}

impl Finding {
    /// How serious it is, most serious first (`by_severity`), causes before what follows from
    /// them: a broken structure (nothing can be trusted), then triangles no leaf holds (no ray
    /// can hit them), then boxes that leave triangles out, the farthest first (a box missing by
    /// a tenth of the mesh before one rounded by an ulp), then the rays that hit wrongly (which
    /// follow from one of those where there is one: "1 of 2036 rays hit differently" says less
    /// than the leaf whose box is too small), then warnings.
    fn severity(&self) -> (u8, f32) {
        let class = match (self.defect, self.group) {
            (false, _) => 4,
            (true, Group::Structure) => 0,
            (true, Group::Coverage) => 1,
            (true, Group::Bounds) => 2,
            (true, Group::Rays) => 3,
        };
        // Larger excess first; NaN (a box that is not a box) first of all.
        let e = self.excess.map_or(0.0, |e| if e.is_nan() { f32::INFINITY } else { e });
        (class, -e)
    }
}

/// Order `findings` most serious first (`Finding::severity`), keeping the order among equals:
/// the first defect is the root cause a student fixes first (`grade`'s "first cause").
pub fn by_severity(findings: &mut [Finding]) {
    findings.sort_by(|a, b| {
        let (ka, kb) = (a.severity(), b.severity());
        ka.0.cmp(&kb.0).then(ka.1.total_cmp(&kb.1))
    });
}

/// Examples listed after a finding unless all are asked for (`check --all`).
pub const LISTED: usize = 4;

/// Findings listed per group unless all are asked for: `check` prints so many, and the grader
/// keeps so many in a student's row (a dump for another mesh has thousands).
pub const FINDINGS_LISTED: usize = 12;

impl Finding {
    /// The finding as one line: its text, then up to `list` of its examples and how many there
    /// are in all when some are left out.
    pub fn line(&self, list: usize) -> String {
        if self.examples.is_empty() {
            return self.text.clone();
        }
        let shown: Vec<&str> = self.examples.iter().take(list).map(String::as_str).collect();
        let more = self.examples.len() > shown.len();
        let tail = if more { format!(", … ({} in all)", self.examples.len()) } else { String::new() };
        format!("{}: {}{tail}", self.text, shown.join(", "))
    }
}

pub(crate) fn defect(group: Group, node: Option<u32>, triangle: Option<u32>, text: String) -> Finding {
    Finding { group, defect: true, text, node, triangle, examples: Vec::new(), excess: None }
}

pub(crate) fn warning(group: Group, node: Option<u32>, triangle: Option<u32>, text: String) -> Finding {
    Finding { group, defect: false, text, node, triangle, examples: Vec::new(), excess: None }
}

/// "1 node is" / "3 nodes are": a count with its noun and verb agreeing.
pub(crate) fn count(n: usize, one: &str, many: &str) -> String {
    if n == 1 {
        format!("1 {one}")
    } else {
        format!("{n} {many}")
    }
}

/// Findings of one kind gathered as they are met, made into one finding at the end: "3 nodes
/// are …: node 1, node 4, node 9".
pub(crate) struct Tally {
    group: Group,
    defect: bool,
    one: &'static str,
    many: &'static str,
    node: Option<u32>,
    triangle: Option<u32>,
    examples: Vec<String>,
    excess: Option<f32>,
}

impl Tally {
    pub fn new(group: Group, defect: bool, one: &'static str, many: &'static str) -> Self {
        Tally { group, defect, one, many, node: None, triangle: None, examples: Vec::new(), excess: None }
    }

    pub fn add(&mut self, node: Option<u32>, triangle: Option<u32>, example: String) {
        if self.examples.is_empty() {
            (self.node, self.triangle) = (node, triangle);
        }
        self.examples.push(example);
    }

    /// `add`, for a case that misses by `excess` (the finding keeps the largest).
    pub fn add_by(&mut self, node: Option<u32>, triangle: Option<u32>, example: String, excess: f32) {
        self.add(node, triangle, example);
        self.excess = Some(self.excess.map_or(excess, |e| e.max(excess)));
    }

    pub fn finish(self, out: &mut Vec<Finding>) {
        if self.examples.is_empty() {
            return;
        }
        let text = count(self.examples.len(), self.one, self.many);
        out.push(Finding {
            group: self.group,
            defect: self.defect,
            text,
            node: self.node,
            triangle: self.triangle,
            examples: self.examples,
            excess: self.excess,
        });
    }
}

/// How far a dump's box may miss a triangle `t` and still hold it: four ulps of its largest
/// coordinate (a box written with nine significant digits, or computed in another order of
/// floating-point operations, is that close), never a fraction of the scene (a far triangle must
/// not excuse a wrong box near the origin).
pub fn tolerance(t: &[Vec3; 3]) -> f32 {
    let m = t.iter().map(|v| v.abs().max_element()).fold(0.0f32, f32::max);
    (4.0 * f32::EPSILON * m).max(f32::MIN_POSITIVE)
}

/// The most triangle references the leaves of a dump of `mesh` may hold: eight per triangle (a
/// tree needs one; spatial splits add some, bvhscope's SBVH at most three more), and a few
/// thousand for tiny meshes. Counted before any reference is followed, so a small dump cannot
/// ask for gigabytes.
pub fn max_references(mesh: &Mesh) -> u64 {
    8 * mesh.file_triangle_count() as u64 + 4096
}

/// What is checked: a dump read from `dump_path`, over the mesh read from `mesh_path`.
pub struct Subject<'a> {
    pub dump: &'a BvhDump,
    pub dump_path: &'a Path,
    pub mesh: &'a Mesh,
    pub mesh_path: &'a Path,
}

/// The structure, coverage and bounds of `dump` over `mesh` (no rays).
pub fn check_tree(dump: &BvhDump, mesh: &Mesh) -> Vec<Finding> {
    let mut out = Vec::new();
    let Some(walk) = structure::check(dump, mesh, &mut out) else { return out };
    bounds::check(dump, mesh, &walk, &mut out);
    bounds::root_box(dump, mesh, &walk, &mut out);
    out
}

/// When the dump names another mesh than the one given, or most of its primitives number
/// triangles this mesh does not have: one line saying so, before the defects that follow from it.
/// A few numbers past the end are a student's off-by-one, not another mesh: those are the
/// structure's defects, naming their nodes.
pub fn wrong_mesh(s: &Subject) -> Option<Finding> {
    let given = s.mesh_path.file_name().map(|n| n.to_string_lossy().into_owned())?;
    let named = s.dump.mesh.as_deref().map(|m| m.rsplit(['/', '\\']).next().unwrap_or(m).to_string());
    let tris = s.mesh.file_triangle_count();
    let past_count = s.dump.primitives.iter().filter(|&&p| p as usize >= tris).count();
    let most_past = past_count > 0 && 2 * past_count > s.dump.primitives.len();
    let highest = s.dump.primitives.iter().copied().max().filter(|_| most_past);
    let other_name = named.as_ref().filter(|n| !n.eq_ignore_ascii_case(&given));
    if other_name.is_none() && highest.is_none() {
        return None;
    }
    let mut text = match other_name {
        Some(n) => format!("the dump was written for {n}, but is checked against {given} ({tris} triangles)"),
        None => format!("the dump is checked against {given} ({tris} triangles)"),
    };
    if let Some(h) = highest {
        text += &format!(
            ", and {past_count} of its {} primitives number triangles past them (up to {h})",
            s.dump.primitives.len()
        );
    }
    text += ": is this the mesh it was built over?";
    Some(warning(Group::Structure, None, None, text))
}

/// Why a dump cannot be traced as it is, or `Ok` with the tree every view traces.
pub fn traceable(findings: &[Finding], dump: &BvhDump, mesh: &Mesh, path: &Path) -> Result<(AnyBvh, Imported), String> {
    if findings.iter().any(|f| f.group == Group::Structure && f.defect) {
        return Err("its structure has defects".into());
    }
    import(dump, mesh, path)
}

/// What `check` found.
pub struct Checked {
    pub findings: Vec<Finding>,
    /// The tree as traced, when its structure is sound.
    pub tree: Option<(AnyBvh, Imported)>,
    /// The camera's pixels whose hit through the tree differs from the linear scan's (the app's
    /// red mask).
    pub wrong_pixels: Vec<(u32, u32)>,
    /// What the rays were checked against, when they were traced.
    pub reference: Option<Reference>,
    /// Rays traced.
    pub rays: u64,
    /// Of them, the rays whose hit through the tree differs from the reference's.
    pub wrong_rays: u64,
}

/// Findings of every group for `s`: the tree's, then, when its structure is sound, the rays'
/// (the camera's primary rays and `rays` random ones, `control` told of each batch), checked
/// against a `Reference` built here and kept in the answer (the app's wrong pixels use it again).
pub fn check(
    s: &Subject,
    camera: &crate::render::Camera,
    rays: u64,
    opts: TraceOptions,
    control: &WorkControl,
) -> Result<Checked, Cancelled> {
    let (out, tree) = match check_structure(s) {
        Ok(traced) => traced,
        Err(findings) => return Ok(Checked::untraced(findings)),
    };
    // Built only once the tree can be traced: past 4,096 triangles it is a whole SAH build.
    let reference = Reference::of(s.mesh);
    let mut checked = check_rays_of(s, out, tree, &reference, camera, rays, opts, control)?;
    checked.reference = Some(reference);
    Ok(checked)
}

/// `check` against a `reference` the caller built once for the mesh (the grader checks a whole
/// class against one); the answer's `reference` is `None`.
pub fn check_with(
    s: &Subject,
    reference: &Reference,
    camera: &crate::render::Camera,
    rays: u64,
    opts: TraceOptions,
    control: &WorkControl,
) -> Result<Checked, Cancelled> {
    match check_structure(s) {
        Ok((out, tree)) => check_rays_of(s, out, tree, reference, camera, rays, opts, control),
        Err(findings) => Ok(Checked::untraced(findings)),
    }
}

impl Checked {
    fn untraced(findings: TreeFindings) -> Checked {
        Checked {
            findings: findings.ordered(),
            tree: None,
            wrong_pixels: Vec::new(),
            reference: None,
            rays: 0,
            wrong_rays: 0,
        }
    }
}

/// A dump's findings before they are ordered: the wrong-mesh line, if any, kept apart so it stays
/// first (every defect after it follows from it), and the rest.
struct TreeFindings {
    wrong_mesh: Option<Finding>,
    rest: Vec<Finding>,
}

impl TreeFindings {
    /// The wrong-mesh line, then the rest most serious first (`by_severity`).
    fn ordered(mut self) -> Vec<Finding> {
        by_severity(&mut self.rest);
        self.wrong_mesh.into_iter().chain(self.rest).collect()
    }
}

/// A tree as traced, and what tells it from a built one (its file, the dump's node ids).
type Traced = (AnyBvh, Imported);

/// The tree's findings, and the tree to trace; `Err` with the findings when it cannot be traced.
fn check_structure(s: &Subject) -> Result<(TreeFindings, Traced), TreeFindings> {
    let mut out = TreeFindings { wrong_mesh: wrong_mesh(s), rest: check_tree(s.dump, s.mesh) };
    if out.rest.iter().any(|f| f.group == Group::Structure && f.defect) {
        return Err(out);
    }
    match import(s.dump, s.mesh, s.dump_path) {
        Ok(tree) => Ok((out, tree)),
        Err(why) => {
            // Not a warning: a tree bvhscope cannot trace is a tree nobody can see is right.
            out.rest.push(defect(Group::Rays, None, None, format!("the tree cannot be traced: {why}")));
            Err(out)
        }
    }
}

/// The rays' findings of a traceable tree, after the tree's (`out`).
#[allow(clippy::too_many_arguments)]
fn check_rays_of(
    s: &Subject,
    mut out: TreeFindings,
    (bvh, imported): (AnyBvh, Imported),
    reference: &Reference,
    camera: &crate::render::Camera,
    rays: u64,
    opts: TraceOptions,
    control: &WorkControl,
) -> Result<Checked, Cancelled> {
    let (cap, big) = crate::dump::oversized_leaves(s.dump);
    if let Some(&first) = big.first() {
        let text = format!(
            "{} more than {cap} triangles, the most a leaf of the layout it is traced in holds: each is traced as a subtree of leaves with its box (the same hits; its counts include the added boxes)",
            count(big.len(), "leaf holds", "leaves hold")
        );
        let mut f = warning(Group::Rays, Some(first), None, text);
        f.examples = big
            .iter()
            .map(|&i| format!("node {i} ({} triangles)", s.dump.nodes[i as usize].count.unwrap_or(0)))
            .collect();
        out.rest.push(f);
    }
    let set = RaySet::checking(s.mesh, camera, rays);
    let wrong = wrong_rays(&bvh, s.mesh, reference, &set, opts, control)?;
    if let Some(f) = wrong.finding(set.len()) {
        out.rest.push(f);
    }
    Ok(Checked {
        findings: out.ordered(),
        tree: Some((bvh, imported)),
        wrong_pixels: wrong.pixels,
        reference: None,
        rays: set.len(),
        wrong_rays: wrong.count,
    })
}
