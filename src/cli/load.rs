//! Opening and building what a command is given: a mesh or a scene, loaded with its notes, built
//! on the GPU where asked and able, else on the CPU.

use crate::cli::error::CliError;
use crate::cli::{device, progress};
use crate::scene::{Scene, SceneBuildError};
use std::path::Path;

/// Load a mesh or a scene with a spinner when it takes over a second, and print what was skipped
/// and the first sentence of the scene's note.
pub(crate) fn load_mesh(path: &Path) -> Result<Scene, CliError> {
    load_noted(path, false)
}

/// `load_mesh`, with the scene's whole note (`stats`, the command that describes a scene; a
/// paragraph before every render's one line of output buried that line).
pub(crate) fn load_noted(path: &Path, whole_note: bool) -> Result<Scene, CliError> {
    let label = format!("loading {}", path.display());
    let loaded = progress::with_spinner(&label, || Scene::open(path))?;
    if loaded.report.degenerate_skipped > 0 {
        eprintln!(
            "note: {}: {} degenerate (zero-area) triangles skipped",
            path.display(),
            loaded.report.degenerate_skipped
        );
    }
    for w in &loaded.warnings {
        eprintln!("warning: {}: {w}", path.display());
    }
    if let Some(note) = loaded.desc.as_ref().and_then(|s| s.note.as_ref()) {
        match crate::explain::words::first_sentence(note) {
            Some(first) if !whole_note => {
                eprintln!("about this scene: {first} (the whole note: bvhscope stats {})", path.display())
            }
            _ => eprintln!("about this scene: {note}"),
        }
    }
    Ok(loaded)
}

/// Build what `build` asks for over a loaded file: on `gpu` when there is one and it builds this
/// (`gpu_path::builds_on_gpu`; the phases come back too), else on the CPU, where for two levels
/// an OBJ is one placement of itself. One level over a scene too large to flatten is refused
/// (`Scene::check_one_level`), before anything is allocated.
pub(crate) fn build_scene(
    gpu: Option<&bvhscope_gpu::Gpu>,
    scene: &Scene,
    build: &crate::bvh::SceneBuild,
) -> Result<(crate::bvh::SceneBvh, Option<device::GpuBuild>), CliError> {
    if build.top.is_none() {
        scene.check_one_level().map_err(|e| CliError::Usage(format!("{e} (--two-level)")))?;
    }
    if let Some(gpu) = gpu {
        if let Some(built) = device::gpu_build_scene(gpu, scene, build)? {
            return Ok((built.0, Some(built.1)));
        }
    }
    let label = if build.top.is_some() { "building the two-level BVH" } else { "building the BVH" };
    progress::with_spinner(label, || match scene.build(build, &crate::work::WorkControl::new()) {
        Ok(b) => Ok(b),
        Err(SceneBuildError::Scene(e)) => Err(e.into()),
        Err(SceneBuildError::Cancelled) => unreachable!("nobody else holds this control"),
    })
    .map(|bvh| (bvh, None))
}
