//! `bvhscope render`: ray-cast a mesh to a PNG.

use super::args::{BuildArgs, DeviceArgs, ViewArgs};
use super::{device, progress};
use crate::bvh::SceneBvh;
use crate::cli::error::CliError;
use crate::cli::load::load_mesh;
use crate::files::file_name;
use crate::gpu_path::GpuTree;
use crate::render::boxes::{draw_segments, Segment};
use crate::render::{
    draw_legend, render_progressive, view_image, Camera, ColorMap, Frame, HeatRange, PairView, RenderSettings, View,
};
use crate::work::WorkControl;
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct RenderArgs {
    #[arg(help = crate::cli::args::MESH_HELP)]
    pub mesh: PathBuf,
    #[command(flatten)]
    pub build: BuildArgs,
    #[command(flatten)]
    pub device: DeviceArgs,
    /// What to show.
    #[arg(long, value_parser = super::args::choice::<View>(), default_value = "normals")]
    pub view: View,
    /// Output PNG.
    #[arg(long, short, default_value = "out.png")]
    pub output: PathBuf,
    #[command(flatten)]
    pub view_args: ViewArgs,
    #[command(flatten)]
    pub rays: super::rays::RayArgs,
    /// Colour map of heatmaps.
    #[arg(long, value_parser = super::args::choice::<ColorMap>(), default_value = "viridis")]
    pub colormap: ColorMap,
    /// Fixed heatmap range MIN:MAX (default: the frame's own min and max); negative numbers as
    /// they are (`--range -5:5`).
    #[arg(long, value_parser = parse_range, allow_hyphen_values = true)]
    pub range: Option<(f32, f32)>,
    /// Also write the counts behind the heatmap, one CSV row per pixel: x, y (0-based, from the
    /// top left), nodes_visited, box_tests, leaves_visited, triangle_tests, hit_triangle (-1: miss);
    /// with secondary rays: x, y, rays, their summed counts, hit_triangle, and the primary ray's
    /// nodes_visited and triangle_tests.
    #[arg(long, value_name = "FILE.csv")]
    pub counts: Option<PathBuf>,
    /// Compare with a second build that differs only in its split strategy: the PNG shows the
    /// difference of the heatmap's metric, this strategy's minus the build's, per pixel (blue:
    /// less work, red: more; --range MIN:MAX sets ±max(|MIN|, |MAX|)).
    #[arg(long, value_parser = super::args::choice::<crate::bvh::Strategy>(), value_name = "STRATEGY")]
    pub against: Option<crate::bvh::Strategy>,
    /// Print the heatmap's histogram as CSV (`bin_low,bin_high,pixels`): BINS equal bins over the
    /// legend's range, the bars under the app's legend (which has 32).
    #[arg(long, value_name = "BINS", value_parser = clap::value_parser!(u32).range(1..=10000))]
    pub histogram: Option<u32>,
    /// Render through a BVH written by another program (bvhscope-bvh, as `check` reads it) instead
    /// of building one; with --against, it is A.
    #[arg(long, value_name = "FILE")]
    pub bvh: Option<PathBuf>,
    #[command(flatten)]
    pub dump_limit: super::args::DumpLimit,
    /// With --against and no --range: the colour scale's ends at ± this percentile of |B − A| over
    /// the pixels where the builds differ (100: the largest difference; one outlier pixel would
    /// leave the rest nearly white) [default: 99].
    #[arg(long, value_parser = parse_percentile, requires = "against", conflicts_with = "range")]
    pub percentile: Option<f32>,
    /// With --against: also write the difference as CSV, one row per pixel: x, y, a, b, b_minus_a.
    #[arg(long, value_name = "FILE.csv", requires = "against")]
    pub difference: Option<PathBuf>,
    /// With --against: what the PNG shows, as the app's Compare shows it (its Save view writes
    /// the same file).
    #[arg(long, value_parser = super::args::choice::<PairView>(), default_value = "difference", requires = "against")]
    pub pair_view: PairView,
    /// With --pair-view wipe: where the line is, from 0 (the left edge) to 1 (the right).
    #[arg(long, value_parser = parse_wipe, default_value = "0.5", requires = "against")]
    pub wipe: f32,
    /// Draw the boxes of the BVH's nodes at DEPTH (0: the root, up to the tree's deepest level)
    /// over the image, as the app's node boxes at that depth: each in its node's colour; over a
    /// two-level scene, each mesh's BVH at DEPTH placed by every instance and the top level's boxes
    /// at depth 1, white. On the view's image (not the legend); with --against, A's boxes left of
    /// the split and B's right of it, A's over a difference.
    #[arg(long, value_name = "DEPTH")]
    pub boxes: Option<u32>,
}

/// Width of the lines of `--boxes` in pixels (top-level boxes twice it).
const BOX_WIDTH: f32 = 1.5;

/// The lines of `--boxes` over the camera's image of `bvh` (`which`: A or B, for the error); a
/// depth the tree does not have is refused, as the app's depth slider ends at its deepest level.
fn box_lines(a: &RenderArgs, bvh: &SceneBvh, camera: &Camera, which: &str) -> Result<Vec<Segment>, CliError> {
    use crate::render::boxes::{box_segments, boxes_at, max_depths, BoxPick};
    let Some(depth) = a.boxes else { return Ok(Vec::new()) };
    let (max, _) = max_depths(bvh);
    if depth > max {
        return Err(CliError::Usage(format!(
            "--boxes {depth}: {which}'s deepest level is {max} (--boxes takes 0, the root, to {max})"
        )));
    }
    let boxes = boxes_at(bvh, &BoxPick::at(bvh, depth));
    let size = glam::Vec2::new(camera.width as f32, camera.height as f32);
    Ok(box_segments(&boxes, camera, size, BOX_WIDTH, None))
}

fn parse_wipe(s: &str) -> Result<f32, String> {
    match s.trim().parse::<f32>() {
        Ok(w) if (0.0..=1.0).contains(&w) => Ok(w),
        _ => Err(format!("'{s}' is not a place from 0 (the left edge) to 1 (the right)")),
    }
}

/// The GPU's walks are of camera rays: secondary rays would need their hit points and any-hit
/// walks in the shaders, which they do not have, so the GPU says so instead of answering wrong.
pub(super) fn gpu_traces_primary_only(kind: crate::render::RayKind) -> CliError {
    CliError::Usage(format!(
        "the GPU path traces primary rays only: --ray-kind {} runs on the CPU (leave out --device gpu)",
        kind.name()
    ))
}

fn parse_percentile(s: &str) -> Result<f32, String> {
    match s.trim().parse::<f32>() {
        Ok(p) if p > 0.0 && p <= 100.0 => Ok(p),
        _ => Err(format!("'{s}' is not a percentile above 0, at most 100")),
    }
}

fn parse_range(s: &str) -> Result<(f32, f32), String> {
    let (a, b) = s.split_once(':').ok_or_else(|| format!("'{s}' is not MIN:MAX"))?;
    let (a, b) = (a.trim().parse::<f32>(), b.trim().parse::<f32>());
    match (a, b) {
        (Ok(a), Ok(b)) if a.is_finite() && b.is_finite() && a < b => Ok((a, b)),
        _ => Err(format!("'{s}' is not MIN:MAX with MIN < MAX")),
    }
}

/// Before anything is loaded or traced: every output named for what it holds, none of them an
/// input (the mesh, the dump) or another output.
fn check_outputs(a: &RenderArgs) -> Result<(), CliError> {
    use crate::files::{refuse_inputs, refuse_same_outputs, CSV, PNG};
    PNG.check(&a.output)?;
    let mut outputs = vec![(a.output.as_path(), "the image (-o)")];
    if let Some(c) = &a.counts {
        CSV.check(c)?;
        outputs.push((c, "the counts (--counts)"));
    }
    if let Some(d) = &a.difference {
        CSV.check(d)?;
        outputs.push((d, "the difference (--difference)"));
    }
    refuse_same_outputs(&outputs)?;
    let mut inputs = vec![(a.mesh.as_path(), "the mesh")];
    if let Some(b) = &a.bvh {
        inputs.push((b, "the BVH dump (--bvh)"));
    }
    for (o, _) in outputs {
        refuse_inputs(o, &inputs)?;
    }
    Ok(())
}

/// The frame of `bvh` on `camera`: rendered on the CPU, or traced on the GPU when there is one
/// (in `a`'s node format).
fn frame_of(
    a: &RenderArgs,
    gpu: Option<&bvhscope_gpu::Gpu>,
    bvh: &SceneBvh,
    camera: &Camera,
    settings: &RenderSettings,
    label: &str,
) -> Result<Frame, CliError> {
    match gpu {
        Some(gpu) => {
            let (tree, mesh) = GpuTree::upload(gpu, bvh, a.device.nodes())?;
            Ok(tree.frame(gpu, &mesh, camera, settings.trace, settings.count)?.0)
        }
        None => {
            let control = WorkControl::new();
            progress::with_bar(label, &control, || {
                render_progressive(bvh, bvh, camera, settings, &Default::default(), &control, |_, _| {})
            })
            .map_err(|_| CliError::Usage("render cancelled".into()))
        }
    }
}

/// `render --against`: render the second build on the same camera and write B − A.
#[allow(clippy::too_many_arguments)]
fn run_against(
    a: &RenderArgs,
    gpu: Option<&bvhscope_gpu::Gpu>,
    loaded: &crate::scene::Scene,
    camera: &crate::render::Camera,
    settings: &RenderSettings,
    frame_a: &crate::render::Frame,
    params_a: &crate::bvh::SceneBuild,
    label_a: &str,
    against: crate::bvh::Strategy,
    boxes_a: &[Segment],
) -> Result<(), CliError> {
    use crate::render::diff::{difference, tally, DiffRange};
    use crate::render::pair::{difference_csv, pair_picture, PairStyle};
    if !a.view.is_heatmap() && (a.pair_view == PairView::Difference || a.difference.is_some()) {
        return Err(CliError::Usage(
            "--against compares two builds' heatmaps: add --view visits, tri-tests or cost".into(),
        ));
    }
    let params_a = *params_a;
    let params_b =
        crate::bvh::SceneBuild { bvh: crate::bvh::BuildParams { strategy: against, ..params_a.bvh }, ..params_a };
    let (bvh_b, _) = crate::cli::load::build_scene(gpu, loaded, &params_b)?;
    let boxes_b = match a.pair_view {
        PairView::Difference => Vec::new(),
        _ => box_lines(a, &bvh_b, camera, "B (--against)")?,
    };
    let frame_b = frame_of(a, gpu, &bvh_b, camera, settings, "rendering the second build")?;
    let cost = params_a.bvh.cost;
    if let Some(path) = &a.difference {
        let text = difference_csv(frame_a, &frame_b, a.view, cost).expect("two complete counted frames of one camera");
        crate::files::write_bytes(path, text.as_bytes())?;
    }
    let style = PairStyle {
        view: a.view,
        colormap: a.colormap,
        cost,
        range: a.range.map_or(HeatRange::Auto, |(min, max)| HeatRange::Fixed { min, max }),
        diff_range: match (a.range, a.percentile) {
            (Some((lo, hi)), _) => DiffRange::Fixed(lo.abs().max(hi.abs())),
            (None, p) => DiffRange::Percentile(p.unwrap_or(crate::render::diff::DEFAULT_PERCENTILE)),
        },
    };
    let subject = format!("{}: A {label_a}, B {}", file_name(&a.mesh), bvh_b.label());
    let mut img = pair_picture(frame_a, &frame_b, a.pair_view, a.wipe, &style, &subject)
        .expect("two complete frames of one camera, counted for a heatmap");
    // A's boxes over a difference; else each build's on its side of the split's white line (two
    // pixels: x0 - 1 and x0).
    let w = camera.width;
    let (a_columns, b_columns) = match a.pair_view {
        PairView::Difference => (0..w, 0..0),
        show => {
            let x0 = crate::render::pair::split_column(w, if show == PairView::Wipe { a.wipe } else { 0.5 });
            (0..x0.saturating_sub(1), x0 + 1..w)
        }
    };
    draw_segments(&mut img, boxes_a, a_columns, 0..camera.height);
    draw_segments(&mut img, &boxes_b, b_columns, 0..camera.height);
    crate::files::write_png(&a.output, &img)?;
    let (w, h, b_label) = (camera.width, camera.height, bvh_b.label());
    match difference(frame_a, &frame_b, a.view, cost) {
        Some(d) => {
            let (less, same, more) = tally(&d);
            let mean = d.iter().map(|&v| v as f64).sum::<f64>() / d.len().max(1) as f64;
            eprintln!(
                "wrote {} ({w}x{h} {} of {}, B {b_label} against A {label_a}: B does less work at {less} pixels, the same at {same}, more at {more}; mean B - A {mean:.3})",
                a.output.display(),
                a.pair_view.name(),
                a.view.label().to_lowercase(),
            )
        }
        None => eprintln!(
            "wrote {} ({w}x{h} {} of {}, A {label_a} and B {b_label})",
            a.output.display(),
            a.pair_view.name(),
            a.view.label().to_lowercase()
        ),
    }
    Ok(())
}

pub fn run(a: &RenderArgs) -> Result<(), CliError> {
    check_outputs(a)?;
    let gpu = device::open(&a.device)?;
    let loaded = load_mesh(&a.mesh)?;
    let camera = a.view_args.camera(&loaded.bounds(), loaded.camera.as_ref())?;
    let mut params = a.build.params(loaded.build.as_ref());
    if gpu.is_some() {
        params = device::gpu_params(&a.build, loaded.build.as_ref(), params)?;
        device::check_traceable(&a.build.scene_build(params), a.build.trace_options())?;
    }
    let bvh = match &a.bvh {
        Some(path) => a.dump_limit.import(&loaded, path)?,
        None => crate::cli::load::build_scene(gpu.as_ref(), &loaded, &a.build.scene_build(params))?.0,
    };
    let boxes = box_lines(a, &bvh, &camera, "the BVH")?;
    let kind = a.rays.one("render")?;
    if gpu.is_some() && kind.is_secondary() {
        return Err(gpu_traces_primary_only(kind));
    }
    let count = a.view.is_heatmap() || a.counts.is_some();
    let secondary = a.rays.secondary(kind, &loaded.bounds(), &camera);
    let settings = RenderSettings { trace: a.build.trace_options(), count, progressive: false, secondary };
    let total = camera.width as u64 * camera.height as u64;
    let frame = frame_of(a, gpu.as_ref(), &bvh, &camera, &settings, "rendering")?;
    // What A is called in captions: the build, or the imported file.
    let label_a = bvh.label();
    if let Some(path) = &a.counts {
        let text = frame.counts_csv().expect("the frame was counted and is complete");
        crate::files::write_bytes(path, text.as_bytes())?;
    }
    if let Some(against) = a.against {
        return run_against(
            a,
            gpu.as_ref(),
            &loaded,
            &camera,
            &settings,
            &frame,
            &bvh.build_params(),
            &label_a,
            against,
            &boxes,
        );
    }
    let range = a.range.map_or(HeatRange::Auto, |(min, max)| HeatRange::Fixed { min, max });
    let (mut img, mut legend) = view_image(&frame, a.view, a.colormap, range, params.cost);
    draw_segments(&mut img, &boxes, 0..camera.width, 0..camera.height);
    if let Some(l) = &mut legend {
        l.subject = format!("{}, {label_a}", file_name(&a.mesh));
        if let Some(sec) = &secondary {
            l.subject = format!("{}, {} rays", l.subject, sec.spec.kind.name());
        }
    }
    if let (Some(bins), Some(l)) = (a.histogram, &legend) {
        let counts = crate::render::histogram(&frame, a.view, params.cost, l.range_min, l.range_max, bins as usize);
        let (lo, hi) = (l.range_min as f64, l.range_max as f64);
        let edge = |i: usize| (lo + (hi - lo) * i as f64 / bins as f64) as f32;
        let mut o = String::from("bin_low,bin_high,pixels\n");
        for (i, c) in counts.iter().enumerate() {
            o += &format!("{},{},{c}\n", edge(i), edge(i + 1));
        }
        super::out(&o);
    } else if a.histogram.is_some() {
        return Err(CliError::Usage("--histogram is of a heatmap: add --view visits, tri-tests or cost".into()));
    }
    let img = match &legend {
        Some(l) => draw_legend(&img, l),
        None => img,
    };
    crate::files::write_png(&a.output, &img)?;
    let hits = frame.hit_count();
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
        // The legend's own numbers, as the app's legend and the PNG's say them.
        let v = |x: f32| crate::render::legend::fmt_value(x as f64);
        eprint!("; {}: min {} mean {:.2} max {}", l.title, v(l.min), l.mean, v(l.max));
    }
    if let Some(depth) = a.boxes {
        eprint!("; node boxes at depth {depth}");
    }
    if let Some(gpu) = &gpu {
        eprint!("; traced on the GPU, {} nodes: {}", a.device.nodes().label(), gpu.name());
    }
    eprintln!(")");
    Ok(())
}
