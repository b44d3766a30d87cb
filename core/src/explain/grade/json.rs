//! `grade.json`: everything the report shows, for programs (the app, a course's own scripts):
//! how the class was graded (mesh, camera, rays, timing, the rubric in its file form), bvhscope's
//! reference trees, and every student's row in the order given. `FORMAT` and `VERSION` name the
//! layout; NOTES.md describes it for the app.

use super::{Graded, Setup, FORMAT, VERSION};
use serde_json::{json, Value};

/// The whole report as JSON.
pub fn document(setup: &Setup, graded: &Graded) -> Value {
    let c = &setup.camera;
    let scales: Vec<Value> = graded
        .references
        .scales()
        .into_iter()
        .map(|(layout, top)| json!({"layout": layout, "visits_max": top}))
        .collect();
    json!({
        "format": FORMAT,
        "version": VERSION,
        "mesh": setup.given_path.to_string_lossy(),
        "checked_against": setup.mesh_path.to_string_lossy(),
        "triangles": setup.mesh.triangle_count(),
        "file_triangles": setup.mesh.file_triangle_count(),
        "camera": c,
        "rays": { "primary": c.width as u64 * c.height as u64, "random": setup.rays },
        "trace": setup.trace,
        "timing": graded.references.timing,
        "heatmap_scales": scales,
        "heatmap_rays": setup.secondary.map(|s| s.spec),
        "max_seconds": setup.max_seconds,
        "rubric_file": setup.rubric.file.as_ref().map(|p| p.to_string_lossy()),
        "rubric": setup.rubric.to_json(),
        "rank_by": setup.rubric.rank_by.describe(),
        "references": graded.references.trees().collect::<Vec<_>>(),
        "seconds": graded.seconds,
        "students": graded.rows,
    })
}
