//! `bvhscope export-bvh MESH -o FILE`: a built-in strategy's tree in the bvhscope-bvh format
//! (the format `check` reads).

use super::args::{BuildArgs, DeviceArgs};
use crate::bvh::{AnyBvh, BuildParams, Layout};
use crate::cli::error::CliError;
use crate::cli::load::load_mesh;
use crate::dump::BvhDump;
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct ExportBvhArgs {
    #[arg(help = crate::cli::args::MESH_HELP)]
    pub mesh: PathBuf,
    #[command(flatten)]
    pub build: BuildArgs,
    /// With --device gpu the strategies the GPU builds (`gpu_path::GPU_BUILDERS`) are built there
    /// (the same tree as the CPU's, node for node); the others on the CPU either way.
    #[command(flatten)]
    pub device: DeviceArgs,
    /// The file to write: .json (JSON), .json.gz (gzip-compressed JSON) or .txt (the text form).
    #[arg(long, short)]
    pub output: PathBuf,
}

/// Write the tree as built (binary unless --layout asks for a wide one) in the bvhscope-bvh format.
pub fn run(a: &ExportBvhArgs) -> Result<(), CliError> {
    // Before anything is built: a name that says no dump format, an output that is the mesh.
    BvhDump::written_as(&a.output).map_err(CliError::Usage)?;
    crate::files::refuse_inputs(&a.output, &[(&a.mesh, "the mesh")])?;
    if a.device.gpu_nodes.is_some() {
        return Err(CliError::Usage("--gpu-nodes is the format the GPU traces; export-bvh writes no GPU nodes".into()));
    }
    let gpu = super::device::open(&a.device)?;
    let scene = load_mesh(&a.mesh)?;
    let mesh = scene.flat_mesh().map_err(|e| CliError::Usage(format!("{}: {e}", a.mesh.display())))?;
    // The binary tree unless --layout wide4 or wide8 asks for a wide one.
    let layout = a.build.layout.unwrap_or(Layout::Binary);
    let params = BuildParams { layout, ..a.build.params(scene.build.as_ref()) };
    let name = crate::files::file_name(&a.mesh);
    let built = match &gpu {
        Some(g) => super::device::gpu_build(g, &mesh, &params)?.map(|(bvh, _)| bvh),
        None => None,
    };
    if gpu.is_some() && built.is_none() {
        let on_gpu = crate::gpu_path::gpu_built();
        eprintln!("note: the GPU builds {on_gpu}; {} is built on the CPU", params.strategy.name());
    }
    let bvh = built.unwrap_or_else(|| AnyBvh::build(&mesh, &params));
    let dump = BvhDump::of_any(&bvh, &mesh, Some(name));
    dump.write(&a.output).map_err(|e| CliError::Usage(e.to_string()))?;
    eprintln!("wrote {} ({} nodes, {} primitives)", a.output.display(), dump.nodes.len(), dump.primitives.len());
    Ok(())
}
