//! Scenes: several meshes, each placed by a transform, with a camera and the BVH settings to start
//! with. Two formats are read: bvhscope's own scene file (`scene_file.rs`) and the Moer-lite
//! renderer's `scene.json` (`moer_lite.rs`). An opened file is a `Scene` (`open.rs`); a scene of
//! placements is flattened into one mesh (`flatten.rs`) only for a one-level BVH.

mod desc;
mod flatten;
mod moer_lite;
mod open;
mod scene_file;
/// Also the grader's rubric reader's (`explain::grade::rubric`): one check for every JSON a person writes.
pub use flatten::{flatten, load_instances, SceneInstances};
pub use open::{load_any, Geometry, Scene, SceneBuildError, SceneSource, MAX_FLAT_TRIANGLES};
pub use scene_file::{parse_scene_file, write_scene_file};

pub(crate) use desc::resolve;
pub use desc::{describe, trs, SceneDesc, SceneError, SceneMesh, MAX_PLACEMENTS, MAX_SCENE_BYTES};
