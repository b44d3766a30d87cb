//! The GPU path shared by the command line and the app: which device traces, the node format it
//! walks, the trees built on the GPU (lbvh and ploc, core's trees node for node, with their phases
//! timed) and a tree uploaded for tracing. The command line's flags (their names too) and messages
//! over it are in `cli::device`, the app's GPU jobs in `app::jobs::gpu` and its choice in `app::state::gpu`.

use crate::bvh::{AnyBvh, BuildParams, Bvh, RayCounters, SceneBuild, SceneBvh, Strategy, TraceOptions};
use crate::mesh::Mesh;
use crate::options::Named;
use crate::render::Camera;
use crate::scene::{Scene, SceneError};
use bvhscope_gpu::{
    BinaryFormat, CwbvhFormat, Gpu, GpuBuildTimings, GpuError, GpuFormat, GpuLbvh, GpuPloc, GpuTrace, Rays, Upload,
};
use std::sync::Arc;

/// Where rays are traced: the CPU (the renderer of `core`) or the GPU (`bvhscope-gpu`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Device {
    #[default]
    Cpu,
    Gpu,
}

/// The node format the GPU walks (its names and help: `GPU_NODE_NAMES`; how it is made and
/// uploaded: its row of `GPU_NODES`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum GpuNodes {
    #[default]
    Binary,
    Cwbvh,
}

/// The devices by name: `--device`, the saved settings and the app's buttons.
const DEVICES: [Named<Device>; 2] = [
    Named {
        value: Device::Cpu,
        name: "cpu",
        label: "CPU",
        help: "the renderer of the core, with the CPU's SIMD kernels",
    },
    Named {
        value: Device::Gpu,
        name: "gpu",
        label: "GPU",
        help: "wgpu compute shaders (Vulkan, Metal, DX12, lavapipe)",
    },
];
bvhscope_core::choice!(Device, DEVICES, 2);

/// The node formats by name: `--gpu-nodes`, the saved settings, the app's buttons, messages and
/// tables.
const GPU_NODE_NAMES: [Named<GpuNodes>; 2] = [
    Named {
        value: GpuNodes::Binary,
        name: "binary",
        label: "binary",
        help: "The binary tree as built: core's 32-byte nodes, byte for byte",
    },
    Named {
        value: GpuNodes::Cwbvh,
        name: "cwbvh",
        label: "CWBVH",
        help: "Compressed 8-wide nodes of 80 bytes (Ylitie, Karras & Laine 2017), made from the binary tree; \
               its counts are those of its own walk",
    },
];
bvhscope_core::choice!(GpuNodes, GPU_NODE_NAMES, 2);

/// How a node format is made from the binary tree and uploaded (its `GpuFormat`, in its own file
/// of `bvhscope-gpu`).
pub struct GpuNodesRow {
    pub nodes: GpuNodes,
    upload: Upload,
}

/// Every node format the GPU walks, one row each.
pub const GPU_NODES: [GpuNodesRow; 2] = [
    GpuNodesRow { nodes: GpuNodes::Binary, upload: BinaryFormat::upload },
    GpuNodesRow { nodes: GpuNodes::Cwbvh, upload: CwbvhFormat::upload },
];

impl GpuNodes {
    /// This format's row of `GPU_NODES`.
    pub fn row(self) -> &'static GpuNodesRow {
        GPU_NODES.iter().find(|r| r.nodes == self).expect("every node format has a row (a test checks)")
    }
}

/// Saved by its name.
impl serde::Serialize for GpuNodes {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

impl<'de> serde::Deserialize<'de> for GpuNodes {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let value = String::deserialize(d)?;
        GpuNodes::from_name(&value).ok_or_else(|| {
            let names = <GpuNodes as crate::options::Choice>::names();
            serde::de::Error::custom(format!("unknown GPU node format \"{value}\" (expected {names})"))
        })
    }
}

/// A build made on the GPU: which builder, and how long each phase took.
#[derive(Clone, Copy, Debug)]
pub struct GpuBuild {
    pub strategy: Strategy,
    pub timings: GpuBuildTimings,
}

impl GpuBuild {
    /// The phases as `stats` prints them (PLOC's emission is its clustering, its boxes the host's
    /// layout of the leaves).
    pub fn text(&self) -> String {
        let t = &self.timings;
        let ms = |d: std::time::Duration| format!("{:.2}", d.as_secs_f64() * 1e3);
        let (emission, boxes) = match self.strategy {
            Strategy::Ploc => (format!("clustering {} ({} rounds)", ms(t.emission), t.rounds), "layout on the host"),
            _ => (format!("emission {}", ms(t.emission)), "boxes"),
        };
        format!(
            "{} ms (upload {}, codes {}, sort {}, {emission}, {boxes} {}, download {})",
            ms(t.total()),
            ms(t.upload),
            ms(t.codes),
            ms(t.sort),
            ms(t.boxes),
            ms(t.download)
        )
    }

    pub fn json(&self) -> serde_json::Value {
        let t = &self.timings;
        let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3;
        serde_json::json!({
            "strategy": self.strategy.name(), "total_ms": ms(t.total()), "upload_ms": ms(t.upload),
            "codes_ms": ms(t.codes), "sort_ms": ms(t.sort), "emission_ms": ms(t.emission), "boxes_ms": ms(t.boxes),
            "download_ms": ms(t.download), "ploc_rounds": t.rounds,
        })
    }
}

/// How a builder on the GPU builds: core's tree, node for node, with its phases timed.
type BuildOnGpu = fn(&Gpu, &Mesh, &BuildParams) -> Result<(Bvh, GpuBuildTimings), GpuError>;

/// A builder on the GPU: the strategy it builds and how.
pub struct GpuBuilderRow {
    pub strategy: Strategy,
    build: BuildOnGpu,
}

/// Every strategy the GPU builds, one row each; the rest are built on the CPU. The help texts
/// name them from here (`gpu_built`).
pub const GPU_BUILDERS: [GpuBuilderRow; 2] = [
    GpuBuilderRow { strategy: Strategy::Lbvh, build: |gpu, mesh, p| GpuLbvh::new(gpu)?.build(gpu, mesh, p) },
    GpuBuilderRow { strategy: Strategy::Ploc, build: |gpu, mesh, p| GpuPloc::new(gpu)?.build(gpu, mesh, p) },
];

/// The strategies the GPU builds, in words: "lbvh and ploc".
pub fn gpu_built() -> String {
    let names: Vec<&str> = GPU_BUILDERS.iter().map(|r| r.strategy.name()).collect();
    match names.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{} and {last}", rest.join(", ")),
        _ => names.concat(),
    }
}

/// Whether the GPU builds `build`: a strategy of `GPU_BUILDERS`, over one level. Everything else
/// is built on the CPU; the command line and the app both ask here.
pub fn builds_on_gpu(build: &SceneBuild) -> bool {
    build.top.is_none() && GPU_BUILDERS.iter().any(|r| r.strategy == build.bvh.strategy)
}

/// Why a build on the GPU gave no tree: the scene's triangles could not be gathered, or the GPU
/// failed.
#[derive(Debug, thiserror::Error)]
pub enum GpuBuildError {
    #[error(transparent)]
    Scene(#[from] SceneError),
    #[error(transparent)]
    Gpu(#[from] GpuError),
}

/// `build` over `scene`'s triangles on `gpu` when the GPU builds it (`builds_on_gpu`), finished
/// as a build on the CPU is; `None`: the CPU builds this one.
pub fn build_scene_on_gpu(
    gpu: &Gpu,
    scene: &Scene,
    build: &SceneBuild,
) -> Result<Option<(SceneBvh, GpuBuild)>, GpuBuildError> {
    if !builds_on_gpu(build) {
        return Ok(None);
    }
    let mesh = scene.flat_mesh()?;
    let built = build_on_gpu(gpu, &mesh, &build.bvh)?;
    Ok(built.map(|(bvh, phases)| (SceneBvh::Single { bvh, mesh, imported: None }, phases)))
}

/// `params.strategy` over `mesh` on `gpu` by its row of `GPU_BUILDERS`, finished as a build on
/// the CPU is (`AnyBvh::finish`); `None` for the strategies only the CPU builds.
pub fn build_on_gpu(gpu: &Gpu, mesh: &Mesh, params: &BuildParams) -> Result<Option<(AnyBvh, GpuBuild)>, GpuError> {
    let strategy = params.strategy;
    let Some(row) = GPU_BUILDERS.iter().find(|r| r.strategy == strategy) else { return Ok(None) };
    let (bvh, timings) = (row.build)(gpu, mesh, params)?;
    Ok(Some((AnyBvh::finish(bvh), GpuBuild { strategy, timings })))
}

/// A tree on the GPU in the node format asked for, with its CPU form: the CPU walks of the same
/// tree finish the rays a GPU walk leaves unfinished at its step budget (`GpuTree::trace_rays`). What a
/// format does is its `GpuFormat`; this holds one and finishes its walks.
pub struct GpuTree {
    nodes: GpuNodes,
    format: Box<dyn GpuFormat>,
}

impl GpuTree {
    /// Upload the binary tree of `bvh` (one level: as built, or an imported dump's) as `nodes`,
    /// by the upload of the format's row of `GPU_NODES`.
    pub fn new(gpu: &Gpu, bvh: &SceneBvh, nodes: GpuNodes) -> Result<(GpuTree, Arc<Mesh>), GpuError> {
        let SceneBvh::Single { mesh, .. } = bvh else {
            return Err(GpuError::Input("the GPU traces one BVH, not two levels".into()));
        };
        let tree = bvh.binary_tree().ok_or_else(|| {
            GpuError::Input("this imported wide tree has no binary form the GPU could walk; trace it on the CPU".into())
        })?;
        let format = (nodes.row().upload)(gpu, tree)?;
        Ok((GpuTree { nodes, format }, mesh.clone()))
    }

    /// How many nodes of its own the format made from the binary tree (`None`: the binary tree's
    /// own nodes are walked).
    pub fn own_nodes(&self) -> Option<usize> {
        self.format.own_nodes()
    }

    pub fn nodes(&self) -> GpuNodes {
        self.nodes
    }

    /// Trace `rays` (closest hits), counting when `counted`, in `trace`'s order (binary nodes;
    /// CWBVH orders its children by octant). A ray whose GPU walk reaches the step budget
    /// (`bvhscope_gpu::STEP_BUDGET`) is finished by the same walk on the CPU, never taken for a
    /// miss: every hit and count is the CPU's, and `cpu_finished` says how many rays that was.
    pub fn trace_rays(&self, gpu: &Gpu, rays: Rays, trace: TraceOptions, counted: bool) -> Result<GpuTrace, GpuError> {
        let opts = bvhscope_gpu::GpuTraceOptions { order: trace.order, counted, exact: true, test: trace.test };
        let mut out = self.format.trace(gpu, rays, opts)?;
        if !out.unfinished.is_empty() {
            out.finish(|i| self.cpu_walk(&mut rays.ray(i), trace));
        }
        Ok(out)
    }

    /// One ray's walk on the CPU, with its counts: core's walk of the binary tree, or the CWBVH's
    /// own CPU walk.
    pub fn cpu_walk(
        &self,
        ray: &mut crate::geometry::Ray,
        trace: TraceOptions,
    ) -> (Option<crate::bvh::Hit>, RayCounters) {
        self.format.cpu_walk(ray, trace)
    }

    /// The per-pixel counts of the same walk on the CPU (row by row): core's renderer for binary
    /// nodes (`cpu` is the binary tree's `SceneBvh`), the CWBVH's own CPU walk for CWBVH nodes.
    pub fn cpu_counts(&self, cpu: &SceneBvh, camera: &Camera, trace: TraceOptions) -> Vec<RayCounters> {
        self.format.cpu_counts(cpu, camera, trace)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every node format has one row, and its value reads back as it. The list is an exhaustive
    /// match, so a new variant does not compile until it is named here (and then needs its row).
    #[test]
    fn every_gpu_node_format_has_one_row_and_reads_back() {
        let listed = |n: GpuNodes| match n {
            GpuNodes::Binary | GpuNodes::Cwbvh => n,
        };
        for nodes in [GpuNodes::Binary, GpuNodes::Cwbvh].map(listed) {
            assert_eq!(GPU_NODES.iter().filter(|r| r.nodes == nodes).count(), 1, "{nodes:?}");
            let saved = serde_json::to_string(&nodes).unwrap();
            assert_eq!(serde_json::from_str::<GpuNodes>(&saved).unwrap(), nodes);
        }
        assert_eq!(serde_json::to_string(&GpuNodes::Cwbvh).unwrap(), "\"cwbvh\"");
        assert!(serde_json::from_str::<GpuNodes>("\"wide\"").is_err());
    }
}
