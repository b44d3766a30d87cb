//! `bvhscope render`: ray-cast a mesh to a PNG.

use super::args::{BuildArgs, ViewArgs};
use super::{build_scene, load_mesh, progress, CliError};
use crate::render::{draw_legend, render_progressive, view_image, ColorMap, HeatRange, RenderSettings, View};
use crate::work::WorkControl;
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct RenderArgs {
    /// The mesh (.obj) or scene (.json: bvhscope's or Moer-lite's).
    pub mesh: PathBuf,
    #[command(flatten)]
    pub build: BuildArgs,
    /// What to show.
    #[arg(long, value_parser = super::args::choice::<View>(), default_value = "normals")]
    pub view: View,
    /// Output PNG.
    #[arg(long, short, default_value = "out.png")]
    pub output: PathBuf,
    #[command(flatten)]
    pub view_args: ViewArgs,
    /// Colour map of heatmaps.
    #[arg(long, value_parser = super::args::choice::<ColorMap>(), default_value = "viridis")]
    pub colormap: ColorMap,
    /// Fixed heatmap range MIN:MAX (default: the frame's own min and max).
    #[arg(long, value_parser = parse_range)]
    pub range: Option<(f32, f32)>,
    /// Also write the counts behind the heatmap, one CSV row per pixel: x, y (0-based, from the
    /// top left), nodes_visited, box_tests, leaves_visited, triangle_tests, hit_triangle (-1: miss).
    #[arg(long, value_name = "FILE.csv")]
    pub counts: Option<PathBuf>,
}

fn parse_range(s: &str) -> Result<(f32, f32), String> {
    let (a, b) = s.split_once(':').ok_or_else(|| format!("'{s}' is not MIN:MAX"))?;
    let (a, b) = (a.trim().parse::<f32>(), b.trim().parse::<f32>());
    match (a, b) {
        (Ok(a), Ok(b)) if a.is_finite() && b.is_finite() && a < b => Ok((a, b)),
        _ => Err(format!("'{s}' is not MIN:MAX with MIN < MAX")),
    }
}

/// The file name of a path, for captions.
pub(crate) fn file_name(p: &std::path::Path) -> String {
    p.file_name().map_or_else(|| p.display().to_string(), |n| n.to_string_lossy().into_owned())
}

pub fn run(a: &RenderArgs) -> Result<(), CliError> {
    let loaded = load_mesh(&a.mesh)?;
    let camera = a.view_args.camera(&loaded.bounds(), loaded.camera.as_ref())?;
    let params = a.build.params(loaded.build.as_ref());
    let bvh = build_scene(&loaded, &a.build.scene_build(params))?;
    let count = a.view.is_heatmap() || a.counts.is_some();
    let settings = RenderSettings { trace: a.build.trace(), count, progressive: false };
    let total = camera.width as u64 * camera.height as u64;
    let control = WorkControl::new();
    let frame = progress::with_bar("rendering", &control, || {
        render_progressive(&bvh, &bvh, &camera, &settings, &Default::default(), &control, |_, _| {})
    })
    .map_err(|_| CliError::Usage("render cancelled".into()))?;
    if let Some(path) = &a.counts {
        let text = frame.counts_csv().expect("the frame was counted and is complete");
        std::fs::write(path, text).map_err(|source| CliError::Write { path: path.clone(), source })?;
    }
    let range = a.range.map_or(HeatRange::Auto, |(min, max)| HeatRange::Fixed { min, max });
    let (img, mut legend) = view_image(&frame, a.view, a.colormap, range, params.cost);
    if let Some(l) = &mut legend {
        l.subject = format!("{}, {}", file_name(&a.mesh), bvh.build_params().label());
    }
    let img = match &legend {
        Some(l) => draw_legend(&img, l),
        None => img,
    };
    img.save(&a.output).map_err(|e| CliError::Write {
        path: a.output.clone(),
        source: match e {
            image::ImageError::IoError(io) => io,
            other => std::io::Error::other(other.to_string()),
        },
    })?;
    let hits = frame.traced().filter(|(s, _)| s.is_hit()).count();
    let legend_note = if legend.is_some() { " with the legend below" } else { "" };
    eprint!(
        "wrote {} ({}x{} image, {}x{} render{legend_note}; {} of {} pixels hit",
        a.output.display(),
        img.width(),
        img.height(),
        camera.width,
        camera.height,
        hits,
        total
    );
    if let Some(l) = legend {
        eprint!("; {}: min {} mean {:.2} max {}", l.title, l.min, l.mean, l.max);
    }
    eprintln!(")");
    Ok(())
}
