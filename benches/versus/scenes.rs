//! The meshes of the benchmark: two shared scans and two generated scenes.

use bvhscope::mesh::{generate, Mesh, MeshGroup};
use bvhscope::random::Rng;
use glam::Vec3;

/// The tests' helpers, for the shared meshes (`shared`).
#[path = "../../core/tests/common/mod.rs"]
mod common;

/// Append `b` to `a` (positions, triangles, groups).
pub fn merge(a: &mut Mesh, b: &Mesh, transform: impl Fn(Vec3) -> Vec3) {
    let base = a.positions.len() as u32;
    let first = a.triangles.len() as u32;
    a.positions.extend(b.positions.iter().map(|&p| transform(p)));
    a.triangles.extend(b.triangles.iter().map(|t| t.map(|i| i + base)));
    a.normals.clear();
    a.uvs.clear();
    a.groups.push(MeshGroup { name: b.name.clone(), triangles: first..a.triangles.len() as u32 });
}

/// "Teapot in a stadium": a small dense mesh at the centre of a huge sparse one — the classic case
/// where spatial-median splits waste levels on empty space.
pub fn teapot_in_stadium() -> Mesh {
    let mut m = generate::stadium();
    let knot = generate::torus_knot(2, 3, 0.22, 1024, 32); // ~65k triangles, ~2 units across
    merge(&mut m, &knot, |p| p + Vec3::new(0.0, 1.5, 0.0));
    m.name = "teapot in a stadium".into();
    m
}

/// 40,000 long thin crossing triangles (`generate::needles`, seed 37 as `write_epo_meshes`
/// writes it): boxes that overlap everywhere, where walks differ most on incoherent rays.
pub fn needles() -> Mesh {
    let mut m = generate::needles(40_000, 37);
    m.name = "needles 40k".into();
    m
}

/// A generated mesh of 2.1 million triangles.
pub fn big_knot() -> Mesh {
    let mut m = generate::torus_knot(3, 5, 0.12, 8192, 128);
    m.name = "knot 2M".into();
    m
}

/// About 500k triangles of uneven sizes: 64 torus knots (8k triangles each) scattered with
/// different sizes, thicknesses and orientations through a box, some overlapping. Not one regular
/// surface like the 2M knot: the builders meet clusters, gaps and long thin triangles.
pub fn knot_field() -> Mesh {
    let mut m = Mesh { name: "knot field 500k".into(), ..Default::default() };
    let mut rng = Rng::new(0x2545_F491_4F6C_DD1D);
    let mut next = move || rng.unit();
    for k in 0..64u32 {
        let (p, q) = ([2, 3, 2, 3, 5][k as usize % 5], [3, 5, 5, 7, 2][k as usize % 5]);
        let knot = generate::torus_knot(p, q, 0.05 + 0.3 * next(), 256, 16);
        let scale = 0.2 + 2.0 * next() * next();
        let at = Vec3::new(next(), next(), next()) * 20.0;
        let rot = glam::Quat::from_euler(glam::EulerRot::XYZ, 6.3 * next(), 6.3 * next(), 6.3 * next());
        merge(&mut m, &knot, |v| rot * v * scale + at);
    }
    m
}

/// A mesh of `../shared/models` beside the checkout, as the tests find them: `None` with a
/// notice when the folder is absent (a failure under CI=true).
pub fn shared(name: &str) -> Option<Mesh> {
    common::shared_mesh(name)
}
