//! `bvhscope replay MESH`: the build played back as an animated PNG, one frame per step on a log
//! scale of the number of splits k (the first splits change the most), each the heatmap of the tree
//! after k splits on one colour scale; and the table of k, the partial tree's SAH cost and the mean
//! of the heatmap's metric, for a lab report (`explain::replay`).

use super::args::{BuildArgs, ViewArgs};
use super::progress;
use crate::bvh::{Layout, SceneBvh};
use crate::cli::error::CliError;
use crate::cli::load::{build_scene, load_mesh};
use crate::explain::replay::Replay;
use crate::explain::replay_film::{film, steps, FilmSettings};
use crate::files::file_name;
use crate::render::{ColorMap, View};
use clap::Args;
use std::path::PathBuf;
use std::sync::Arc;

#[derive(Args, Debug)]
pub struct ReplayArgs {
    #[arg(help = crate::cli::args::MESH_HELP)]
    pub mesh: PathBuf,
    #[command(flatten)]
    pub build: BuildArgs,
    #[command(flatten)]
    pub view_args: ViewArgs,
    /// The heatmap each frame shows (combined cost by default: it falls as the tree grows, while
    /// nodes visited rise and triangle tests fall).
    #[arg(long, value_parser = super::args::choice::<View>(), default_value = "cost")]
    pub view: View,
    #[arg(long, value_parser = super::args::choice::<ColorMap>(), default_value = "viridis")]
    pub colormap: ColorMap,
    /// Frames (steps on a log scale of k, from the root alone to the finished tree).
    #[arg(long, default_value_t = 24, value_parser = clap::value_parser!(u32).range(2..=400))]
    pub frames: u32,
    /// How long each frame shows, in milliseconds.
    #[arg(long, default_value_t = 400, value_parser = clap::value_parser!(u16).range(20..))]
    pub delay_ms: u16,
    /// The animation to write: .gif (a GIF, for slides) or .png (an animated PNG, every colour
    /// exact).
    #[arg(long, short, default_value = "build.png")]
    pub output: PathBuf,
}

pub fn run(a: &ReplayArgs) -> Result<(), CliError> {
    super::out(&output(a)?);
    Ok(())
}

/// Write the animated PNG; the table `run` prints.
pub fn output(a: &ReplayArgs) -> Result<String, CliError> {
    if a.build.two_level {
        return Err(CliError::Usage("replay plays back one BVH's build; leave out --two-level".into()));
    }
    if !a.view.is_heatmap() {
        return Err(CliError::Usage("replay shows a heatmap: --view visits, tri-tests or cost".into()));
    }
    crate::render::animation::ANIMATION.check(&a.output)?;
    crate::files::refuse_inputs(&a.output, &[(&a.mesh, "the mesh")])?;
    let scene = load_mesh(&a.mesh)?;
    let params = a.build.params(scene.build.as_ref());
    let (SceneBvh::Single { bvh, mesh, .. }, _) = build_scene(None, &scene, &a.build.scene_build(params))? else {
        unreachable!("one level was asked for")
    };
    if params.layout != Layout::Binary {
        eprintln!("note: the replay is of the binary tree as built (the 4-wide layout is collapsed from it)");
    }
    let replay = Replay::of(Arc::new(bvh.binary_tree(&mesh).into_owned()));
    let camera = a.view_args.camera(&scene.bounds(), scene.camera.as_ref())?;
    let frames = steps(replay.splits(), a.frames).len();
    if frames < a.frames as usize {
        eprintln!(
            "note: the tree has {} splits, so {frames} frames (one per step from the root alone to the finished tree), not {}",
            replay.splits(),
            a.frames
        );
    }
    let settings = FilmSettings {
        view: a.view,
        colormap: a.colormap,
        frames: a.frames,
        trace: a.build.trace_options(),
        cost: params.cost,
    };
    let subject = format!("{}, {}, log scale", file_name(&a.mesh), params.strategy.label());
    let control = crate::work::WorkControl::new();
    control.set_total(frames as u64);
    let f = progress::with_bar("rendering the steps", &control, || {
        film(&replay, &mesh, &camera, &settings, &subject, &control)
    })
    .map_err(|_| CliError::Usage("replay cancelled".into()))?;
    let (images, table) = (&f.images, f.table(a.view));
    crate::render::animation::write_animation(&a.output, images, a.delay_ms)?;
    eprintln!("wrote {} ({} frames, {}x{})", a.output.display(), images.len(), images[0].width(), images[0].height());
    Ok(table)
}
