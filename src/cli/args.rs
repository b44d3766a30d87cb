//! Arguments shared by the subcommands. Every value list, help line, limit and default comes from
//! the core's option tables (`crate::options`), which the app's panels and scene files read too.

use crate::bvh::{BuildParams, Layout, Preset, SahCost, SceneBuild, SplitStrategy, TraceOptions, TraversalOrder};
use crate::geometry::{Aabb, TriangleTest};
use crate::options::{
    Choice, Number, MAX_LEAF_SIZE, PLOC_RADIUS, REINSERT_PASSES, SAH_BINS, SBVH_ALPHA, SBVH_GROWTH, TOP_MAX_LEAF_SIZE,
    TRAVERSAL_COST,
};
use crate::render::{Camera, UpAxis};
use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use clap::Args;
use glam::Vec3;

/// clap's parser for a choice: the names of its table, each with its help in `--help`.
pub fn choice<T: Choice + Clone>() -> impl TypedValueParser<Value = T> {
    PossibleValuesParser::new(T::TABLE.iter().map(|n| PossibleValue::new(n.name).help(n.help)))
        .map(|s| T::from_name(&s).expect("clap passes only the listed names"))
}

/// A whole number within a table's limits.
fn whole(n: &'static Number<u32>) -> impl TypedValueParser<Value = u32> {
    clap::value_parser!(u32).range(n.min as i64..=n.max as i64)
}

/// A number's help line with its limits and default, for `--help`.
fn number_help<T: std::fmt::Display + PartialOrd + Copy>(n: &Number<T>) -> String {
    format!("{} ({}) [default: {}]", n.help, n.range_text(), n.default)
}

/// How to build and traverse the BVH. Each option left out comes from `--preset` if given, else
/// from the scene file's `bvh` settings (as the app starts from them), else the default.
#[derive(Args, Debug, Clone, Default)]
pub struct BuildArgs {
    /// Start from a named set of options (the ones given here still win).
    #[arg(long, value_parser = choice::<Preset>())]
    pub preset: Option<Preset>,
    /// Split strategy [default: sah].
    #[arg(long, short, value_parser = choice::<SplitStrategy>())]
    pub strategy: Option<SplitStrategy>,
    #[arg(long, value_parser = whole(&MAX_LEAF_SIZE), help = number_help(&MAX_LEAF_SIZE))]
    pub max_leaf_size: Option<u32>,
    #[arg(long, value_parser = whole(&SAH_BINS), help = number_help(&SAH_BINS))]
    pub bins: Option<u32>,
    #[arg(long, value_parser = whole(&PLOC_RADIUS), help = number_help(&PLOC_RADIUS))]
    pub ploc_radius: Option<u32>,
    #[arg(long, value_parser = whole(&REINSERT_PASSES), help = number_help(&REINSERT_PASSES))]
    pub reinsert_passes: Option<u32>,
    #[arg(long, value_parser = parse_sbvh_alpha, help = number_help(&SBVH_ALPHA))]
    pub sbvh_alpha: Option<f32>,
    #[arg(long, value_parser = whole(&SBVH_GROWTH), help = number_help(&SBVH_GROWTH))]
    pub sbvh_growth: Option<u32>,
    #[arg(long, value_parser = parse_traversal_cost, help = number_help(&TRAVERSAL_COST))]
    pub traversal_cost: Option<f32>,
    /// Node layout for traversal [default: wide4; `compare` shows both unless one is given].
    #[arg(long, value_parser = choice::<Layout>())]
    pub layout: Option<Layout>,
    /// Child visited first at interior nodes of the binary layout (the wide one always takes the
    /// nearest first) [default: entry-distance].
    #[arg(long, value_parser = choice::<TraversalOrder>())]
    pub order: Option<TraversalOrder>,
    /// Ray–triangle test [default: watertight].
    #[arg(long = "triangle-test", value_parser = choice::<TriangleTest>())]
    pub test: Option<TriangleTest>,
    /// Build two levels: a top-level BVH over the scene's mesh placements and one BVH per mesh
    /// (the options above then apply to the meshes' BVHs). An OBJ is one placement of itself.
    #[arg(long)]
    pub two_level: bool,
    /// Split strategy of the top level [default: --strategy].
    #[arg(long, value_parser = choice::<SplitStrategy>(), requires = "two_level")]
    pub top_strategy: Option<SplitStrategy>,
    #[arg(long, default_value_t = TOP_MAX_LEAF_SIZE.default, value_parser = whole(&TOP_MAX_LEAF_SIZE), help = number_help(&TOP_MAX_LEAF_SIZE), requires = "two_level")]
    pub top_max_leaf_size: u32,
}

impl BuildArgs {
    /// The parameters before the options given on the command line: the preset's, the scene's,
    /// or the defaults.
    fn base(&self, scene: Option<&BuildParams>) -> BuildParams {
        match (self.preset, scene) {
            (Some(p), _) => p.build(),
            (None, Some(s)) => *s,
            (None, None) => BuildParams::default(),
        }
    }

    /// The build parameters: the options given, else the preset's, the scene's (`scene`, from a
    /// scene file), the defaults.
    pub fn params(&self, scene: Option<&BuildParams>) -> BuildParams {
        let base = self.base(scene);
        self.params_with(scene, self.strategy.unwrap_or(base.strategy), self.layout.unwrap_or(base.layout))
    }

    /// `params` with the strategy and layout given (`compare` goes through them all).
    pub fn params_with(&self, scene: Option<&BuildParams>, strategy: SplitStrategy, layout: Layout) -> BuildParams {
        let base = self.base(scene);
        BuildParams {
            strategy,
            layout,
            max_leaf_size: self.max_leaf_size.unwrap_or(base.max_leaf_size),
            sah_bins: self.bins.unwrap_or(base.sah_bins),
            ploc_radius: self.ploc_radius.unwrap_or(base.ploc_radius),
            reinsert_passes: self.reinsert_passes.unwrap_or(base.reinsert_passes),
            sbvh_alpha: self.sbvh_alpha.unwrap_or(base.sbvh_alpha),
            sbvh_growth: self.sbvh_growth.unwrap_or(base.sbvh_growth),
            cost: SahCost { traversal: self.traversal_cost.unwrap_or(base.cost.traversal), ..base.cost },
        }
    }

    /// The layouts `compare` shows: the one given or the preset's, else both.
    pub fn compare_layouts(&self) -> Vec<Layout> {
        match (self.layout, self.preset) {
            (Some(l), _) => vec![l],
            (None, Some(p)) => vec![p.build().layout],
            (None, None) => Layout::ALL.to_vec(),
        }
    }

    /// What to build: one BVH with `params`, or (with `--two-level`) two levels whose bottom
    /// uses `params`.
    pub fn scene_build(&self, params: BuildParams) -> SceneBuild {
        let top = self.two_level.then(|| BuildParams {
            strategy: self.top_strategy.unwrap_or(params.strategy),
            max_leaf_size: self.top_max_leaf_size,
            layout: Layout::Binary,
            ..params
        });
        SceneBuild { bvh: params, top }
    }

    pub fn trace(&self) -> TraceOptions {
        let base = self.preset.map_or(TraceOptions::default(), Preset::trace);
        TraceOptions { order: self.order.unwrap_or(base.order), test: self.test.unwrap_or(base.test) }
    }
}

/// The options that rebuild `build` and trace with `opts`, every one given (so neither a preset
/// nor a scene file's settings change them): what the app writes when it names the command line
/// that reproduces what it shows. `BuildArgs` parses them back to the same values.
pub fn build_flags(build: &SceneBuild, opts: TraceOptions) -> Vec<String> {
    let p = &build.bvh;
    let mut out = vec![
        format!("--strategy {}", p.strategy.named().name),
        format!("--max-leaf-size {}", p.max_leaf_size),
        format!("--bins {}", p.sah_bins),
        format!("--ploc-radius {}", p.ploc_radius),
        format!("--reinsert-passes {}", p.reinsert_passes),
        format!("--sbvh-alpha {}", p.sbvh_alpha),
        format!("--sbvh-growth {}", p.sbvh_growth),
        format!("--traversal-cost {}", p.cost.traversal),
        format!("--layout {}", p.layout.named().name),
        format!("--order {}", opts.order.named().name),
        format!("--triangle-test {}", opts.test.named().name),
    ];
    if let Some(top) = &build.top {
        out.push("--two-level".into());
        out.push(format!("--top-strategy {}", top.strategy.named().name));
        out.push(format!("--top-max-leaf-size {}", top.max_leaf_size));
    }
    out
}

/// A path as one shell word: as it is when it needs no quoting, else in single quotes.
pub fn shell_word(s: &str) -> String {
    if !s.is_empty() && s.chars().all(|c| c.is_ascii_alphanumeric() || "/._-+,:=@%".contains(c)) {
        s.to_string()
    } else {
        format!("'{}'", s.replace('\'', r"'\''"))
    }
}

/// Where rays are traced: the CPU (the renderer of `core`) or the GPU (`bvhscope-gpu`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Device {
    #[default]
    Cpu,
    Gpu,
}

/// The node format the GPU walks.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum GpuNodes {
    /// The binary tree as built: core's 32-byte nodes, byte for byte.
    #[default]
    Binary,
    /// Compressed 8-wide nodes of 80 bytes (Ylitie, Karras & Laine 2017), made from the binary tree.
    Cwbvh,
}

/// `--device` and the GPU's node format: the one declaration `render`, `stats`, `compare` and
/// `trace` take (the GPU path's rules are in `cli::device`).
#[derive(Args, Debug, Clone, Default)]
pub struct DeviceArgs {
    /// Trace the rays on the CPU or on the GPU (wgpu compute shaders: Vulkan, Metal, DX12; Mesa's
    /// lavapipe too). On the GPU the per-pixel counts are the CPU's for the binary layout, the
    /// strategies lbvh and ploc are built there too, and only the watertight test and one level
    /// run; with no GPU adapter the command fails (it never falls back to the CPU).
    #[arg(long, value_enum, default_value = "cpu")]
    pub device: Device,
    /// With --device gpu: the node format walked, the binary tree as built or its compressed
    /// 8-wide form (CWBVH) [default: binary].
    #[arg(long, value_enum, value_name = "FORMAT")]
    pub gpu_nodes: Option<GpuNodes>,
}

impl GpuNodes {
    /// How messages and tables name the format.
    pub fn name(self) -> &'static str {
        match self {
            GpuNodes::Binary => "binary",
            GpuNodes::Cwbvh => "CWBVH",
        }
    }
}

impl DeviceArgs {
    pub fn gpu(&self) -> bool {
        self.device == Device::Gpu
    }

    pub fn nodes(&self) -> GpuNodes {
        self.gpu_nodes.unwrap_or_default()
    }
}

/// How much of a BVH dump is read (`--bvh`): a dump decompressed past the limit is refused while
/// it is read (a gzip bomb, a device).
#[derive(Args, Debug, Clone, Default)]
pub struct DumpLimit {
    /// Largest BVH dump read, in MB after decompression [default: what a dump of the mesh can
    /// need: 64 MB and 6.5 kB per triangle].
    #[arg(long, value_name = "MB", value_parser = clap::value_parser!(u64).range(1..=1_000_000))]
    pub max_dump_mb: Option<u64>,
}

impl DumpLimit {
    /// The limit in bytes for a dump of `mesh`.
    pub fn bytes(&self, mesh: &crate::mesh::Mesh) -> u64 {
        self.max_dump_mb.map_or_else(|| crate::dump::max_bytes(mesh.file_triangle_count()), |mb| mb << 20)
    }
}

/// The camera and image size of a render.
#[derive(Args, Debug, Clone)]
pub struct ViewArgs {
    /// Image size, WIDTHxHEIGHT [default: the scene's, else 1280x720].
    #[arg(long, value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// Camera as EYE:TARGET[:UP], each X,Y,Z (e.g. 0,1,5:0,0,0); UP defaults to the --up axis.
    /// Default: frames the mesh from the front.
    #[arg(long, value_parser = parse_camera, allow_hyphen_values = true)]
    pub camera: Option<(Vec3, Vec3, Option<Vec3>)>,
    /// Vertical field of view in degrees (0.01 to 179.9).
    #[arg(long, default_value_t = 45.0, value_parser = parse_fov)]
    pub fov: f32,
    /// Which axis of the mesh points up: the default camera frames it from the front with this
    /// axis up (and `--camera` takes it as the up vector unless it gives one).
    #[arg(long, value_parser = choice::<UpAxis>(), default_value = "y")]
    pub up: UpAxis,
}

impl ViewArgs {
    /// The camera: `--camera` if given, else the scene's, else one framing the mesh; the size is
    /// `--size`, else the scene's, else 1280x720.
    pub fn camera(&self, bounds: &Aabb, scene: Option<&Camera>) -> Result<Camera, super::CliError> {
        let (w, h) = self.size.or(scene.map(|c| (c.width, c.height))).unwrap_or((1280, 720));
        let cam = match (self.camera, scene) {
            (Some((position, look_at, up)), _) => {
                let up = up.unwrap_or(self.up.vector());
                Camera { position, look_at, up, vfov_deg: self.fov, width: w, height: h }
            }
            (None, Some(c)) => Camera { width: w, height: h, ..*c },
            (None, None) => Camera::framing_up(bounds, w, h, self.up, self.fov),
        };
        cam.validate().map_err(|e| super::CliError::Usage(format!("--camera: {e}")))?;
        Ok(cam)
    }
}

/// A vertical field of view within the camera's limits.
pub fn parse_fov(s: &str) -> Result<f32, String> {
    let (lo, hi) = (Camera::MIN_VFOV_DEG, Camera::MAX_VFOV_DEG);
    match s.trim().parse::<f32>() {
        Ok(v) if (lo..=hi).contains(&v) => Ok(v),
        _ => Err(format!("'{s}' is not an angle from {lo} to {hi} degrees")),
    }
}

/// A traversal cost within its limits.
pub fn parse_traversal_cost(s: &str) -> Result<f32, String> {
    real(s, &TRAVERSAL_COST)
}

fn parse_sbvh_alpha(s: &str) -> Result<f32, String> {
    real(s, &SBVH_ALPHA)
}

/// A number within a table's limits.
fn real(s: &str, n: &Number<f32>) -> Result<f32, String> {
    match s.trim().parse::<f32>() {
        Ok(v) if n.contains(v) => Ok(v),
        _ => Err(format!("'{s}' is not a number {}", n.range_text())),
    }
}

/// `1280x720` → (1280, 720).
pub fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(|| format!("'{s}' is not WIDTHxHEIGHT"))?;
    let parse = |v: &str| v.trim().parse::<u32>().map_err(|_| format!("'{s}' is not WIDTHxHEIGHT"));
    let (w, h) = (parse(w)?, parse(h)?);
    if w == 0 || h == 0 || w > 16384 || h > 16384 || w as u64 * h as u64 > crate::render::Camera::MAX_PIXELS {
        return Err(format!("'{s}': width and height must be 1..=16384, and the image at most 40 megapixels"));
    }
    Ok((w, h))
}

pub fn parse_vec3(s: &str) -> Result<Vec3, String> {
    let v: Vec<f32> = s
        .split(',')
        .map(|c| c.trim().parse::<f32>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("'{s}' is not X,Y,Z"))?;
    match v[..] {
        [x, y, z] if x.is_finite() && y.is_finite() && z.is_finite() => Ok(Vec3::new(x, y, z)),
        _ => Err(format!("'{s}' is not X,Y,Z (three finite numbers)")),
    }
}

/// `0,1,5:0,0,0[:0,1,0]` → (eye, target, up if given).
pub fn parse_camera(s: &str) -> Result<(Vec3, Vec3, Option<Vec3>), String> {
    let parts: Vec<&str> = s.split(':').collect();
    match parts[..] {
        [eye, target] => Ok((parse_vec3(eye)?, parse_vec3(target)?, None)),
        [eye, target, up] => Ok((parse_vec3(eye)?, parse_vec3(target)?, Some(parse_vec3(up)?))),
        _ => Err(format!("'{s}' is not EYE:TARGET[:UP]")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_and_cameras_parse() {
        assert_eq!(parse_size("1280x720"), Ok((1280, 720)));
        assert!(parse_size("0x10").is_err() && parse_size("12").is_err() && parse_size("axb").is_err());
        let (e, t, u) = parse_camera("0,1,5:0,0,0").unwrap();
        assert_eq!((e, t, u), (Vec3::new(0.0, 1.0, 5.0), Vec3::ZERO, None));
        assert_eq!(parse_camera("1,2,3:4,5,6:0,0,1").unwrap().2, Some(Vec3::Z));
        assert!(parse_camera("1,2:0,0,0").is_err() && parse_camera("nan,0,0:0,0,0").is_err());
        assert_eq!(parse_traversal_cost("2.5"), Ok(2.5));
        assert!(parse_traversal_cost("nan").is_err() && parse_traversal_cost("inf").is_err());
        assert!(parse_traversal_cost("-1").is_err() && parse_traversal_cost("0").is_err());
    }

    #[test]
    fn options_given_win_over_the_preset_which_wins_over_the_scene() {
        use clap::Parser;
        #[derive(Parser)]
        struct T {
            #[command(flatten)]
            b: BuildArgs,
        }
        let scene = BuildParams { strategy: SplitStrategy::EqualCount, max_leaf_size: 2, ..BuildParams::default() };
        let parse = |args: &[&str]| T::parse_from([&["t"], args].concat()).b;
        let plain = parse(&[]);
        assert_eq!(plain.params(None), BuildParams::default());
        assert_eq!(plain.params(Some(&scene)), scene, "a scene file's settings, as the app starts from them");
        assert_eq!(plain.trace(), TraceOptions::default());
        let handout = parse(&["--preset", "handout"]);
        assert_eq!(handout.params(Some(&scene)), Preset::Handout.build());
        assert_eq!(handout.trace(), Preset::Handout.trace());
        assert_eq!(handout.compare_layouts(), vec![Layout::Binary]);
        let mine = parse(&["--preset", "handout", "--max-leaf-size", "8", "--triangle-test", "watertight"]);
        let p = mine.params(None);
        assert_eq!((p.strategy, p.layout, p.max_leaf_size), (SplitStrategy::Midpoint, Layout::Binary, 8));
        assert_eq!(mine.trace(), TraceOptions { test: TriangleTest::Watertight, ..Preset::Handout.trace() });
        assert_eq!(parse(&["-s", "sah-sweep"]).params(Some(&scene)).strategy, SplitStrategy::SahSweep);
        assert_eq!(parse(&[]).compare_layouts(), Layout::ALL.to_vec());
    }
}
