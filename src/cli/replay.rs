//! `bvhscope replay MESH`: the build played back as an animated PNG, one frame per step on a log
//! scale of the number of splits k (the first splits change the most), each the heatmap of the tree
//! after k splits on one colour scale; and the table of k, the partial tree's SAH cost and the mean
//! of the heatmap's metric, for a lab report (`bvh::replay`).

use super::args::{BuildArgs, ViewArgs};
use super::render::file_name;
use super::{build_scene, load_mesh, progress, CliError};
use crate::bvh::replay::Replay;
use crate::bvh::{Layout, SceneBvh};
use crate::render::{draw_legend, render, ColorMap, Legend, RenderSettings, View};
use clap::Args;
use std::fmt::Write;
use std::path::PathBuf;
use std::sync::Arc;

#[derive(Args, Debug)]
pub struct ReplayArgs {
    /// The mesh (.obj) or scene (.json, one level).
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

/// `frames` split counts from 0 to `n`, as near a log scale of k + 1 as distinct counts allow
/// (where the scale's steps round to the same count, the next counts are taken: the first
/// splits are shown one by one). Fewer only when the tree has fewer steps: `n + 1`.
pub fn steps(n: usize, frames: u32) -> Vec<usize> {
    let frames = (frames as usize).min(n + 1).max(1);
    let top = ((n + 1) as f64).ln();
    let mut ks: Vec<usize> = Vec::with_capacity(frames);
    for i in 0..frames {
        let on_scale = ((top * i as f64 / (frames - 1).max(1) as f64).exp().round() as usize).saturating_sub(1);
        // Distinct and increasing, and room left for the frames still to come.
        let lowest = ks.last().map_or(0, |&k| k + 1);
        let highest = n - (frames - 1 - i);
        ks.push(on_scale.clamp(lowest, highest));
    }
    ks
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
    let SceneBvh::Single { bvh, mesh, .. } = build_scene(&scene, &a.build.scene_build(params))? else {
        unreachable!("one level was asked for")
    };
    if params.layout != Layout::Binary {
        eprintln!("note: the replay is of the binary tree as built (the 4-wide layout is collapsed from it)");
    }
    let replay = Replay::of(Arc::new(bvh.binary_tree(&mesh).into_owned()));
    let camera = a.view_args.camera(&scene.bounds(), scene.camera.as_ref())?;
    let settings = RenderSettings { trace: a.build.trace(), count: true, progressive: false };
    let ks = steps(replay.splits(), a.frames);
    if ks.len() < a.frames as usize {
        eprintln!(
            "note: the tree has {} splits, so {} frames (one per step from the root alone to the finished tree), not {}",
            replay.splits(),
            ks.len(),
            a.frames
        );
    }
    let cost = params.cost;
    // Each step's metric per pixel; then one colour scale for all of them.
    let values: Vec<Vec<f32>> = progress::with_spinner("rendering the steps", || {
        ks.iter()
            .map(|&k| {
                let partial = replay.partial(k);
                let f = render(&partial, &*mesh, &camera, &settings);
                // Every pixel of the complete frame (a warp view's are its groups' values).
                crate::render::grid_values(&f, a.view, cost)
            })
            .collect()
    });
    let max = values.iter().flatten().copied().fold(0f32, f32::max).max(1e-20);
    let subject = format!("{}, {}, log scale", file_name(&a.mesh), params.strategy.label());
    let mut table = format!("{:>8}  {:>12}  mean {} per ray\n", "splits", "SAH cost", a.view.label().to_lowercase());
    // An LBVH tree's splits follow the Morton order: each step names the newest one's bit.
    let morton = crate::bvh::lbvh::MortonOrder::of(&replay.tree);
    let mut images = Vec::new();
    for (&k, v) in ks.iter().zip(&values) {
        let mean = v.iter().map(|&x| x as f64).sum::<f64>() / v.len().max(1) as f64;
        let newest = k.checked_sub(1).map(|i| replay.order[i]);
        let split = match (&morton, newest) {
            (Some(m), Some(n)) => morton_text(m, &replay, n).map_or(String::new(), |t| format!("  node {n}: {t}")),
            _ => String::new(),
        };
        let _ = writeln!(table, "{k:>8}  {:>12.3}  {mean:.3}{split}", replay.sah[k]);
        // One scale for every step, 0 to the largest value of any, logarithmic: the first steps
        // cost hundreds of times what the last do, and both should show.
        let log_max = (1.0 + max).ln();
        let img = image::RgbImage::from_fn(camera.width, camera.height, |x, y| {
            image::Rgb(a.colormap.map((1.0 + v[(y * camera.width + x) as usize]).ln() / log_max))
        });
        let legend = Legend {
            title: format!(
                "{}: {k}/{} splits, SAH {:.1}",
                a.view.label().to_lowercase(),
                replay.splits(),
                replay.sah[k]
            ),
            subject: subject.clone(),
            note: String::new(),
            colormap: a.colormap,
            range_min: 0.0,
            range_max: max,
            min: v.iter().copied().fold(f32::INFINITY, f32::min),
            max: v.iter().copied().fold(0.0, f32::max),
            mean,
        };
        images.push(draw_legend(&img, &legend));
    }
    crate::render::animation::write_animation(&a.output, &images, a.delay_ms)?;
    eprintln!("wrote {} ({} frames, {}x{})", a.output.display(), images.len(), images[0].width(), images[0].height());
    Ok(table)
}

/// An LBVH split in the Morton order's words (the Replay window shows the same): where the codes
/// of the node's slots flip, and how many slots go each way.
pub fn morton_text(order: &crate::bvh::lbvh::MortonOrder, r: &Replay, node: u32) -> Option<String> {
    let h = &r.hierarchy;
    let (first, count) = (h.first[node as usize], h.count[node as usize]);
    let s = order.split(first, count)?;
    let axis = ["x", "y", "z"][s.axis as usize];
    Some(format!(
        "Morton bit {} ({axis}, grid level {}): slots {first}..{} | {}..{} of the Morton order",
        s.bit,
        s.level,
        first + s.left,
        first + s.left,
        first + count
    ))
}

#[cfg(test)]
mod tests {
    use super::steps;

    /// The frames asked for, distinct, from the root alone to the finished tree, near a log scale;
    /// fewer only when the tree has fewer steps.
    #[test]
    fn steps_are_as_many_as_asked_and_distinct() {
        for (n, frames) in [(1000, 24), (1000, 20), (30, 24), (200_000, 400), (5, 2)] {
            let ks = steps(n, frames);
            assert_eq!(ks.len(), frames as usize, "{n} {frames}");
            assert_eq!((ks[0], *ks.last().unwrap()), (0, n));
            assert!(ks.windows(2).all(|w| w[0] < w[1]), "{ks:?}");
        }
        assert_eq!(steps(3, 24), [0, 1, 2, 3], "a tree of three splits has four steps");
        // Far along, the log scale itself: the middle frame of 1,000 splits in 21 is near √1001.
        assert!((25..=40).contains(&steps(1000, 21)[10]));
    }
}
