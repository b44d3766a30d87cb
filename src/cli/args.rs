//! Arguments shared by the subcommands. Every value list, help line, limit and default comes from
//! the core's option tables (`crate::options`), which the app's panels and scene files read too.

use crate::bvh::{BuildParams, Layout, Param, ParamValue, Preset, SceneBuild, Strategy, TraceOptions, TraversalOrder};
use crate::geometry::{Aabb, TriangleTest};
use crate::gpu_path::{Device, GpuNodes};
use crate::options::{Choice, Number, BUILD_PARAMS, TOP_MAX_LEAF_SIZE};
use crate::render::{Camera, UpAxis};
use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use clap::{Arg, ArgMatches, Args, Command, FromArgMatches};
use glam::Vec3;

/// clap's parser for a choice: the names of its table, each with its help in `--help`.
pub fn choice<T: Choice + Clone>() -> impl TypedValueParser<Value = T> {
    PossibleValuesParser::new(T::TABLE.iter().map(|n| PossibleValue::new(n.name).help(n.help)))
        .map(|s| T::from_name(&s).expect("clap passes only the listed names"))
}

/// A whole number within a number's limits.
fn whole(n: &'static Number<u32>) -> impl TypedValueParser<Value = u32> {
    clap::value_parser!(u32).range(n.limits.min as i64..=n.limits.max as i64)
}

/// The build parameters given on the command line: one option per row of the core's table
/// (`--max-leaf-size`, `--bins`, …), its name, help, limits and default read from there.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ParamArgs(pub Vec<(Param, ParamValue)>);

impl Args for ParamArgs {
    fn augment_args(cmd: Command) -> Command {
        BUILD_PARAMS.iter().fold(cmd, |cmd, o| {
            let arg = Arg::new(o.name).long(o.name).value_name(o.name.to_uppercase().replace('-', "_"));
            cmd.arg(arg.help(o.help_line()).value_parser(move |s: &str| o.parse(s)))
        })
    }
    fn augment_args_for_update(cmd: Command) -> Command {
        Self::augment_args(cmd)
    }
}

impl FromArgMatches for ParamArgs {
    fn from_arg_matches(m: &ArgMatches) -> Result<Self, clap::Error> {
        let given = BUILD_PARAMS.iter().filter_map(|o| Some((o.param, *m.get_one::<ParamValue>(o.name)?)));
        Ok(ParamArgs(given.collect()))
    }
    fn update_from_arg_matches(&mut self, m: &ArgMatches) -> Result<(), clap::Error> {
        *self = Self::from_arg_matches(m)?;
        Ok(())
    }
}

/// How to build and traverse the BVH. Each option left out comes from `--preset` if given, else
/// from the scene file's `bvh` settings (as the app starts from them), else the default.
#[derive(Args, Debug, Clone, Default)]
pub struct BuildArgs {
    /// Start from a named set of options (the ones given here still win).
    #[arg(long, value_parser = choice::<Preset>())]
    pub preset: Option<Preset>,
    /// Split strategy [default: sah].
    #[arg(long, short, value_parser = choice::<Strategy>())]
    pub strategy: Option<Strategy>,
    #[command(flatten)]
    pub numbers: ParamArgs,
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
    #[arg(long, value_parser = choice::<Strategy>(), requires = "two_level")]
    pub top_strategy: Option<Strategy>,
    #[arg(long, default_value_t = TOP_MAX_LEAF_SIZE.limits.default, value_parser = whole(&TOP_MAX_LEAF_SIZE), help = format!("{} ({})", TOP_MAX_LEAF_SIZE.help, TOP_MAX_LEAF_SIZE.limits.range_text()), requires = "two_level")]
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
    pub fn params_with(&self, scene: Option<&BuildParams>, strategy: Strategy, layout: Layout) -> BuildParams {
        let mut p = BuildParams { strategy, layout, ..self.base(scene) };
        for &(param, v) in &self.numbers.0 {
            param.set(&mut p, v);
        }
        p
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

    pub fn trace_options(&self) -> TraceOptions {
        let base = self.preset.map_or(TraceOptions::default(), Preset::trace_options);
        TraceOptions { order: self.order.unwrap_or(base.order), test: self.test.unwrap_or(base.test) }
    }
}

/// `--device` and the GPU's node format: the one declaration `render`, `stats`, `compare` and
/// `trace` take (the GPU path's rules are in `cli::device`).
#[derive(Args, Debug, Clone, Default)]
pub struct DeviceArgs {
    /// Trace the rays on the CPU or on the GPU (its help: `device_help`).
    #[arg(long, value_parser = choice::<Device>(), default_value = "cpu", help = device_help())]
    pub device: Device,
    /// With --device gpu: the node format walked, the binary tree as built or its compressed
    /// 8-wide form (CWBVH) [default: binary].
    #[arg(long, value_parser = choice::<GpuNodes>(), value_name = "FORMAT")]
    pub gpu_nodes: Option<GpuNodes>,
}

/// `--device`'s help, naming the strategies the GPU builds from its table.
fn device_help() -> String {
    format!(
        "Trace the rays on the CPU or on the GPU (wgpu compute shaders: Vulkan, Metal, DX12; Mesa's lavapipe \
         too). On the GPU the per-pixel counts are the CPU's for the binary layout, the strategies {} are built \
         there too, and only the watertight test and one level run; with no GPU adapter the command fails (it \
         never falls back to the CPU).",
        crate::gpu_path::gpu_built()
    )
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

    /// The dump at `path` (`--bvh`) read and made into bvhscope's tree over the scene's mesh, as
    /// every command traces it (its structure must be sound: `check` says what is wrong otherwise).
    pub fn import(
        &self,
        scene: &crate::scene::Scene,
        path: &std::path::Path,
    ) -> Result<crate::bvh::SceneBvh, crate::cli::error::CliError> {
        use crate::cli::error::CliError;
        let mesh = scene.flat_mesh().map_err(|e| CliError::Usage(e.to_string()))?;
        let dump = crate::dump::BvhDump::read(path, self.bytes(&mesh)).map_err(|e| CliError::Usage(e.to_string()))?;
        let structure = crate::explain::check::check_tree(&dump, &mesh);
        let (bvh, imported) = crate::explain::check::traceable(&structure, &dump, &mesh, path)
            .map_err(|why| CliError::Usage(format!("{}: {why}; bvhscope check lists what is wrong", path.display())))?;
        Ok(crate::bvh::SceneBvh::imported(bvh, mesh, imported))
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
    pub fn camera(&self, bounds: &Aabb, scene: Option<&Camera>) -> Result<Camera, crate::cli::error::CliError> {
        let (w, h) = self.size.or(scene.map(|c| (c.width, c.height))).unwrap_or((1280, 720));
        let cam = match (self.camera, scene) {
            (Some((position, look_at, up)), _) => {
                let up = up.unwrap_or(self.up.vector());
                Camera { position, look_at, up, vfov_deg: self.fov, width: w, height: h }
            }
            (None, Some(c)) => Camera { width: w, height: h, ..*c },
            (None, None) => Camera::framing_up(bounds, w, h, self.up, self.fov),
        };
        cam.validate().map_err(|e| crate::cli::error::CliError::Usage(format!("--camera: {e}")))?;
        Ok(cam)
    }
}

/// The help of every command's mesh argument, written once: each format `mesh::load` reads
/// (`MeshFormat::EXTENSIONS`, a test holds them together) and the scene files.
pub const MESH_HELP: &str =
    "The mesh (.obj, .ply, .off, .stl; .gltf or .glb, opened as a scene) or a scene file (.json: bvhscope's or Moer-lite's)";

/// A vertical field of view within the camera's limits.
pub fn parse_fov(s: &str) -> Result<f32, String> {
    let (lo, hi) = (Camera::MIN_VFOV_DEG, Camera::MAX_VFOV_DEG);
    match s.trim().parse::<f32>() {
        Ok(v) if (lo..=hi).contains(&v) => Ok(v),
        _ => Err(format!("'{s}' is not an angle from {lo} to {hi} degrees")),
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

    /// Every command's mesh argument says the same, and names every format the readers take.
    #[test]
    fn the_mesh_argument_has_one_help_naming_every_format() {
        use clap::CommandFactory;
        let cli = crate::cli::Cli::command();
        let mut seen = 0;
        for sub in cli.get_subcommands() {
            if let Some(arg) = sub.get_arguments().find(|a| a.get_id() == "mesh") {
                assert_eq!(arg.get_help().map(|h| h.to_string()).as_deref(), Some(MESH_HELP), "{}", sub.get_name());
                seen += 1;
            }
        }
        assert!(seen >= 9, "{seen} commands take a mesh");
        for ext in crate::mesh::MeshFormat::EXTENSIONS {
            assert!(MESH_HELP.contains(&format!(".{ext}")), "{ext}");
        }
    }

    #[test]
    fn sizes_and_cameras_parse() {
        assert_eq!(parse_size("1280x720"), Ok((1280, 720)));
        assert!(parse_size("0x10").is_err() && parse_size("12").is_err() && parse_size("axb").is_err());
        let (e, t, u) = parse_camera("0,1,5:0,0,0").unwrap();
        assert_eq!((e, t, u), (Vec3::new(0.0, 1.0, 5.0), Vec3::ZERO, None));
        assert_eq!(parse_camera("1,2,3:4,5,6:0,0,1").unwrap().2, Some(Vec3::Z));
        assert!(parse_camera("1,2:0,0,0").is_err() && parse_camera("nan,0,0:0,0,0").is_err());
        let cost = |s: &str| Param::TraversalCost.option().parse(s);
        assert_eq!(cost("2.5"), Ok(ParamValue::Real(2.5)));
        assert!(cost("nan").is_err() && cost("inf").is_err() && cost("-1").is_err() && cost("0").is_err());
    }

    #[test]
    fn options_given_win_over_the_preset_which_wins_over_the_scene() {
        use clap::Parser;
        #[derive(Parser)]
        struct T {
            #[command(flatten)]
            b: BuildArgs,
        }
        let scene = BuildParams { strategy: Strategy::EqualCount, max_leaf_size: 2, ..BuildParams::default() };
        let parse = |args: &[&str]| T::parse_from([&["t"], args].concat()).b;
        let plain = parse(&[]);
        assert_eq!(plain.params(None), BuildParams::default());
        assert_eq!(plain.params(Some(&scene)), scene, "a scene file's settings, as the app starts from them");
        assert_eq!(plain.trace_options(), TraceOptions::default());
        let handout = parse(&["--preset", "handout"]);
        assert_eq!(handout.params(Some(&scene)), Preset::Handout.build());
        assert_eq!(handout.trace_options(), Preset::Handout.trace_options());
        assert_eq!(handout.compare_layouts(), vec![Layout::Binary]);
        let mine = parse(&["--preset", "handout", "--max-leaf-size", "8", "--triangle-test", "watertight"]);
        let p = mine.params(None);
        assert_eq!((p.strategy, p.layout, p.max_leaf_size), (Strategy::Midpoint, Layout::Binary, 8));
        assert_eq!(
            mine.trace_options(),
            TraceOptions { test: TriangleTest::Watertight, ..Preset::Handout.trace_options() }
        );
        assert_eq!(parse(&["-s", "sah-sweep"]).params(Some(&scene)).strategy, Strategy::SahSweep);
        assert_eq!(parse(&[]).compare_layouts(), Layout::ALL.to_vec());
    }

    /// Every row of the option tables is an option of every subcommand that builds, the flags the
    /// app writes parse back to the build they came from, and a scene file keeps every number.
    #[test]
    fn every_build_parameter_is_a_flag_and_a_scene_key_and_reads_back() {
        use crate::options::{ParamOption, BUILD_PARAMS};
        use clap::{CommandFactory, Parser};
        let cli = super::super::Cli::command();
        let builds: Vec<&clap::Command> =
            cli.get_subcommands().filter(|c| c.get_arguments().any(|a| a.get_long() == Some("strategy"))).collect();
        assert!(builds.len() >= 5, "render, stats, compare, trace, inspect… take the build options");
        for c in &builds {
            for o in &BUILD_PARAMS {
                assert!(
                    c.get_arguments().any(|a| a.get_long() == Some(o.name)),
                    "{} has no --{}",
                    c.get_name(),
                    o.name
                );
            }
        }
        // Every number away from its default, each within its limits.
        let mut p = BuildParams { strategy: Strategy::Sbvh, layout: Layout::Binary, ..BuildParams::default() };
        for o in &BUILD_PARAMS {
            let v = match o.limits() {
                crate::bvh::ParamLimits::Whole(l) => ParamValue::Whole(if l.default == l.max { l.min } else { l.max }),
                crate::bvh::ParamLimits::Real(l) => ParamValue::Real((l.default + l.max) * 0.5),
            };
            o.param.set(&mut p, v);
            assert_ne!(o.param.get(&p), o.limits().default_value(), "{}", o.name);
        }
        let build = SceneBuild { bvh: p, top: None };
        let words: Vec<String> = crate::explain::words::build_flags(&build, TraceOptions::default())
            .iter()
            .flat_map(|w| w.split(' ').map(str::to_string).collect::<Vec<_>>())
            .collect();
        #[derive(Parser)]
        struct T {
            #[command(flatten)]
            b: BuildArgs,
        }
        let back = T::parse_from(std::iter::once("t".to_string()).chain(words)).b;
        assert_eq!(back.params(None), p, "the flags read back to the build");
        let camera = Camera::framing_up(&Aabb::from_points(&[Vec3::ZERO, Vec3::ONE]), 64, 48, UpAxis::Y, 45.0);
        let text = crate::scene::write_scene_file(&camera, &[], &p);
        let json: serde_json::Value = serde_json::from_str(&text).unwrap();
        for o in &BUILD_PARAMS {
            assert_eq!(json["bvh"][o.key], ParamOption::to_json(o.param.get(&p)), "the scene file's {}", o.key);
        }
        let mut scene = json.clone();
        scene["meshes"] = serde_json::json!([{ "file": "x.obj" }]);
        let desc = crate::scene::parse_scene_file(std::path::Path::new("s.json"), &scene.to_string()).unwrap();
        assert_eq!(desc.build, Some(p), "a scene file reads back every number");
    }
}
