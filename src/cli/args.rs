//! Arguments shared by the subcommands, and clap's value lists for the core's enums (so `--help`
//! lists every strategy, view, order, test and colour map under its kebab-case name).

use crate::bvh::{BuildParams, Layout, SahCost, SceneBuild, SplitStrategy, TraceOptions, TraversalOrder};
use crate::geometry::{Aabb, TriangleTest};
use crate::render::{Camera, ColorMap, View};
use clap::builder::PossibleValue;
use clap::{Args, ValueEnum};
use glam::Vec3;

impl ValueEnum for SplitStrategy {
    fn value_variants<'a>() -> &'a [Self] {
        &SplitStrategy::ALL
    }
    fn to_possible_value(&self) -> Option<PossibleValue> {
        Some(PossibleValue::new(self.short_name()).help(self.description()))
    }
}

impl ValueEnum for Layout {
    fn value_variants<'a>() -> &'a [Self] {
        &Layout::ALL
    }
    fn to_possible_value(&self) -> Option<PossibleValue> {
        Some(PossibleValue::new(self.short_name()).help(self.label()))
    }
}

impl ValueEnum for View {
    fn value_variants<'a>() -> &'a [Self] {
        &View::ALL
    }
    fn to_possible_value(&self) -> Option<PossibleValue> {
        Some(PossibleValue::new(self.short_name()).help(self.label()))
    }
}

impl ValueEnum for TraversalOrder {
    fn value_variants<'a>() -> &'a [Self] {
        &TraversalOrder::ALL
    }
    fn to_possible_value(&self) -> Option<PossibleValue> {
        let name = match self {
            TraversalOrder::SplitAxisSign => "split-axis",
            TraversalOrder::EntryDistance => "entry-distance",
        };
        Some(PossibleValue::new(name).help(self.label()))
    }
}

impl ValueEnum for TriangleTest {
    fn value_variants<'a>() -> &'a [Self] {
        &TriangleTest::ALL
    }
    fn to_possible_value(&self) -> Option<PossibleValue> {
        let name = match self {
            TriangleTest::Watertight => "watertight",
            TriangleTest::MollerTrumbore => "moller-trumbore",
        };
        Some(PossibleValue::new(name).help(self.label()))
    }
}

impl ValueEnum for ColorMap {
    fn value_variants<'a>() -> &'a [Self] {
        &ColorMap::ALL
    }
    fn to_possible_value(&self) -> Option<PossibleValue> {
        Some(PossibleValue::new(self.label()))
    }
}

/// How to build and traverse the BVH.
#[derive(Args, Debug, Clone)]
pub struct BuildArgs {
    /// Split strategy.
    #[arg(long, short, value_enum, default_value = "sah")]
    pub strategy: SplitStrategy,
    /// Most triangles in a leaf (1..=255).
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(1..=255))]
    pub max_leaf_size: u32,
    /// Bins per axis for the binned SAH (2..=256); nodes of fewer than 3·bins triangles use a
    /// third of their count (at least 4, never more than asked for).
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u32).range(2..=256))]
    pub bins: u32,
    /// SAH cost of one traversal step (relative to one triangle test), a positive number.
    #[arg(long, default_value_t = 1.0, value_parser = parse_positive)]
    pub traversal_cost: f32,
    /// Node layout for traversal [default: wide4; `compare` shows both unless one is given].
    #[arg(long, value_enum)]
    pub layout: Option<Layout>,
    /// Child visited first at interior nodes of the binary layout (the wide one always takes the
    /// nearest first).
    #[arg(long, value_enum, default_value = "entry-distance")]
    pub order: TraversalOrder,
    /// Ray–triangle test.
    #[arg(long = "triangle-test", value_enum, default_value = "watertight")]
    pub test: TriangleTest,
    /// Build two levels: a top-level BVH over the scene's mesh placements and one BVH per mesh
    /// (the options above then apply to the meshes' BVHs). An OBJ is one placement of itself.
    #[arg(long)]
    pub two_level: bool,
    /// Split strategy of the top level [default: --strategy].
    #[arg(long, value_enum, requires = "two_level")]
    pub top_strategy: Option<SplitStrategy>,
    /// Most placements in a top-level leaf (1..=255).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=255), requires = "two_level")]
    pub top_max_leaf_size: u32,
}

impl BuildArgs {
    pub fn params(&self, strategy: SplitStrategy) -> BuildParams {
        self.params_with(strategy, self.layout.unwrap_or_default())
    }

    pub fn params_with(&self, strategy: SplitStrategy, layout: Layout) -> BuildParams {
        BuildParams {
            strategy,
            layout,
            max_leaf_size: self.max_leaf_size,
            sah_bins: self.bins,
            cost: SahCost { traversal: self.traversal_cost, ..SahCost::default() },
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
        TraceOptions { order: self.order, test: self.test }
    }
}

/// The camera and image size of a render.
#[derive(Args, Debug, Clone)]
pub struct ViewArgs {
    /// Image size, WIDTHxHEIGHT [default: the scene's, else 1280x720].
    #[arg(long, value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// Camera as EYE:TARGET[:UP], each X,Y,Z (e.g. 0,1,5:0,0,0). Default: frames the mesh.
    #[arg(long, value_parser = parse_camera, allow_hyphen_values = true)]
    pub camera: Option<(Vec3, Vec3, Vec3)>,
    /// Vertical field of view in degrees (between 0 and 180).
    #[arg(long, default_value_t = 45.0, value_parser = parse_fov)]
    pub fov: f32,
}

impl ViewArgs {
    /// The camera: `--camera` if given, else the scene's, else one framing the mesh; the size is
    /// `--size`, else the scene's, else 1280x720.
    pub fn camera(&self, bounds: &Aabb, scene: Option<&Camera>) -> Result<Camera, super::CliError> {
        let (w, h) = self.size.or(scene.map(|c| (c.width, c.height))).unwrap_or((1280, 720));
        let cam = match (self.camera, scene) {
            (Some((position, look_at, up)), _) => {
                Camera { position, look_at, up, vfov_deg: self.fov, width: w, height: h }
            }
            (None, Some(c)) => Camera { width: w, height: h, ..*c },
            (None, None) => Camera::framing_from(bounds, w, h, Camera::DEFAULT_VIEW_FROM, self.fov),
        };
        cam.validate().map_err(|e| super::CliError::Usage(format!("--camera: {e}")))?;
        Ok(cam)
    }
}

/// A vertical field of view strictly between 0 and 180 degrees.
pub fn parse_fov(s: &str) -> Result<f32, String> {
    match s.trim().parse::<f32>() {
        Ok(v) if v > 0.0 && v < 180.0 => Ok(v),
        _ => Err(format!("'{s}' is not an angle between 0 and 180 degrees")),
    }
}

/// A finite number greater than zero.
pub fn parse_positive(s: &str) -> Result<f32, String> {
    match s.trim().parse::<f32>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(format!("'{s}' is not a positive number")),
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

fn parse_vec3(s: &str) -> Result<Vec3, String> {
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

/// `0,1,5:0,0,0[:0,1,0]` → (eye, target, up).
pub fn parse_camera(s: &str) -> Result<(Vec3, Vec3, Vec3), String> {
    let parts: Vec<&str> = s.split(':').collect();
    match parts[..] {
        [eye, target] => Ok((parse_vec3(eye)?, parse_vec3(target)?, Vec3::Y)),
        [eye, target, up] => Ok((parse_vec3(eye)?, parse_vec3(target)?, parse_vec3(up)?)),
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
        assert_eq!((e, t, u), (Vec3::new(0.0, 1.0, 5.0), Vec3::ZERO, Vec3::Y));
        assert_eq!(parse_camera("1,2,3:4,5,6:0,0,1").unwrap().2, Vec3::Z);
        assert!(parse_camera("1,2:0,0,0").is_err() && parse_camera("nan,0,0:0,0,0").is_err());
        assert_eq!(parse_positive("2.5"), Ok(2.5));
        assert!(parse_positive("nan").is_err() && parse_positive("inf").is_err() && parse_positive("-1").is_err());
        assert!(parse_positive("0").is_err());
    }
}
