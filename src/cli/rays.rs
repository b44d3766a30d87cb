//! The rays a command traces: `--ray-kind primary|shadow|ao|bounce` (`all` for `compare`), and
//! the secondary rays' parameters, declared once for every command that traces a frame.

use super::args::parse_vec3;
use crate::cli::error::CliError;
use crate::render::secondary::{DEFAULT_AO_LENGTH, DEFAULT_SAMPLES, DEFAULT_SEED, MAX_SAMPLES};
use crate::render::{Camera, RayKind, SecondaryRays, SecondarySpec};
use crate::{geometry::Aabb, options::Choice};
use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use clap::Args;
use glam::Vec3;

/// `--ray-kind`: one kind, or every kind (`compare`'s table).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RayKinds {
    One(RayKind),
    All,
}

fn kinds() -> impl TypedValueParser<Value = RayKinds> {
    let mut values: Vec<_> = RayKind::TABLE.iter().map(|n| PossibleValue::new(n.name).help(n.help)).collect();
    values.push(PossibleValue::new("all").help("every kind, one after another (compare's table)"));
    PossibleValuesParser::new(values).map(|s| RayKind::from_name(&s).map_or(RayKinds::All, RayKinds::One))
}

#[derive(Args, Debug, Clone)]
pub struct RayArgs {
    /// Which rays the heatmaps count. Secondary kinds start at each pixel's primary hit; a
    /// pixel's value is the mean over its secondary rays, and pixels whose camera ray missed are
    /// marked grey.
    #[arg(long, value_parser = kinds(), default_value = "primary")]
    pub ray_kind: RayKinds,
    /// Rays per pixel for ao and bounce (the same rays for the same seed, whatever traces them).
    #[arg(long, default_value_t = DEFAULT_SAMPLES, value_parser = clap::value_parser!(u32).range(1..=MAX_SAMPLES as i64))]
    pub samples: u32,
    /// Length of ao rays as a share of the scene's diagonal (0.1: 10 %).
    #[arg(long, default_value_t = DEFAULT_AO_LENGTH, value_parser = parse_share)]
    pub ao_length: f32,
    /// The point light of shadow rays, X,Y,Z [default: half the scene's diagonal above the camera].
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true, value_name = "X,Y,Z")]
    pub light: Option<Vec3>,
    /// The seed of the secondary rays' directions.
    #[arg(long, default_value_t = DEFAULT_SEED)]
    pub seed: u64,
}

fn parse_share(s: &str) -> Result<f32, String> {
    match s.trim().parse::<f32>() {
        Ok(v) if v > 0.0 && v <= 100.0 => Ok(v),
        _ => Err(format!("'{s}' is not a share of the diagonal above 0 (at most 100)")),
    }
}

impl RayArgs {
    /// The parameters for `kind`.
    pub fn spec(&self, kind: RayKind) -> SecondarySpec {
        SecondarySpec { kind, samples: self.samples, ao_length: self.ao_length, light: self.light, seed: self.seed }
    }

    /// The one kind a command that traces one frame traces (`all` is `compare`'s).
    pub fn one(&self, command: &str) -> Result<RayKind, CliError> {
        match self.ray_kind {
            RayKinds::One(k) => Ok(k),
            RayKinds::All => Err(CliError::Usage(format!(
                "--ray-kind all is for compare's table; {command} traces one kind: primary, shadow, ao or bounce"
            ))),
        }
    }

    /// The kinds in order: one, or all four.
    pub fn kinds(&self) -> Vec<RayKind> {
        match self.ray_kind {
            RayKinds::One(k) => vec![k],
            RayKinds::All => RayKind::ALL.to_vec(),
        }
    }

    /// The render settings' secondary rays for `kind` on `camera` (`None` for primary rays).
    pub fn secondary(&self, kind: RayKind, bounds: &Aabb, camera: &Camera) -> Option<SecondaryRays> {
        kind.is_secondary().then(|| SecondaryRays::new(self.spec(kind), bounds, camera))
    }
}
