//! A build replay (`explain::replay`) as a film: `frames` steps from the root alone to the finished
//! tree, each the heatmap of the partial tree on one logarithmic colour scale with its legend, and
//! the table of each step's SAH cost and mean cost per ray. One implementation for `bvhscope
//! replay` and the app's Replay window, which write the same files.

use crate::bvh::morton::MortonOrder;
use crate::bvh::{SahCost, TraceOptions};
use crate::explain::replay::Replay;
use crate::mesh::Mesh;
use crate::render::{
    draw_legend_wrapped, grid_values, legend_rows, render_progressive, Camera, ColorMap, Legend, LegendRows,
    RenderSettings, View,
};
use crate::work::{Cancelled, WorkControl};
use image::RgbImage;
use std::fmt::Write;

/// What a film shows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FilmSettings {
    pub view: View,
    pub colormap: ColorMap,
    /// Frames asked for (`steps` gives that many unless the tree has fewer steps).
    pub frames: u32,
    pub trace: TraceOptions,
    pub cost: SahCost,
}

/// One step of the film.
#[derive(Clone, Debug, PartialEq)]
pub struct FilmStep {
    /// Splits made.
    pub splits: usize,
    pub sah: f64,
    /// The heatmap's mean over the frame.
    pub mean: f64,
    /// For an LBVH tree, the newest split in the Morton order's words.
    pub split: Option<String>,
}

/// A build's replay as frames: one image per step shown, and what each step was.
pub struct ReplayFilm {
    pub images: Vec<RgbImage>,
    pub steps: Vec<FilmStep>,
}

/// `frames` split counts from 0 to `n`, as near a log scale of k + 1 as distinct counts allow
/// (where the scale's steps round to the same count, the next counts are taken: the first splits
/// are shown one by one). Fewer only when the tree has fewer steps: `n + 1`.
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

/// An LBVH split in the Morton order's words (the Replay window shows the same): where the codes
/// of the node's slots flip, and how many slots go each way.
pub fn morton_text(order: &MortonOrder, r: &Replay, node: u32) -> Option<String> {
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

/// The film of `replay` over `mesh` seen by `camera`; `subject` names it in each legend (mesh,
/// strategy). `control` counts the steps and can stop it.
pub fn film(
    replay: &Replay,
    mesh: &Mesh,
    camera: &Camera,
    s: &FilmSettings,
    subject: &str,
    control: &WorkControl,
) -> Result<ReplayFilm, Cancelled> {
    let settings = RenderSettings { trace: s.trace, count: true, progressive: false, secondary: None };
    let ks = steps(replay.splits(), s.frames);
    // Each step's metric per pixel; then one colour scale for all of them.
    let pass = WorkControl::new();
    let mut values = Vec::with_capacity(ks.len());
    for &k in &ks {
        control.check()?;
        let partial = replay.partial(k);
        let f = render_progressive(&partial, mesh, camera, &settings, &Default::default(), &pass, |_, _| {})?;
        values.push(grid_values(&f, s.view, s.cost));
        control.add_done(1);
    }
    let max = values.iter().flatten().copied().fold(0f32, f32::max).max(1e-20);
    let morton = MortonOrder::of(&replay.tree);
    let (mut frames, mut out) = (Vec::new(), Vec::new());
    let (w, h) = (camera.width, camera.height);
    for (&k, v) in ks.iter().zip(&values) {
        let mean = v.iter().map(|&x| x as f64).sum::<f64>() / v.len().max(1) as f64;
        let newest = k.checked_sub(1).map(|i| replay.order[i]);
        let split = match (&morton, newest) {
            (Some(m), Some(n)) => morton_text(m, replay, n).map(|t| format!("node {n}: {t}")),
            _ => None,
        };
        // One scale for every step, 0 to the largest value of any, logarithmic: the first steps
        // cost hundreds of times what the last do, and both should show. (A complete frame has a
        // value per pixel, a warp view its group's.)
        let log_max = (1.0 + max).ln();
        let img = RgbImage::from_fn(w, h, |x, y| {
            let value = v.get((y * w + x) as usize).copied().unwrap_or(0.0);
            image::Rgb(s.colormap.map((1.0 + value).ln() / log_max))
        });
        let legend = Legend {
            title: format!(
                "{}: {k}/{} splits, SAH {:.1}",
                s.view.label().to_lowercase(),
                replay.splits(),
                replay.sah[k]
            ),
            subject: subject.to_string(),
            note: String::new(),
            colormap: s.colormap,
            range_min: 0.0,
            range_max: max,
            min: v.iter().copied().fold(f32::INFINITY, f32::min),
            max: v.iter().copied().fold(0.0, f32::max),
            mean,
        };
        frames.push((img, legend));
        out.push(FilmStep { splits: k, sah: replay.sah[k], mean, split });
    }
    // One strip for the whole film: each text at the body's size on as many rows as its longest
    // frame needs. Fitted frame by frame, a headline that grew a digit shrank to half size and
    // jumped between frames, and a GIF's frames must share one size anyway.
    let rows = frames.iter().fold(LegendRows::default(), |r, (img, l)| r.max(legend_rows(img.width(), l)));
    // Each plain frame let go once its strip is drawn: a long film holds one set of images, not two.
    let images = frames.into_iter().map(|(img, l)| draw_legend_wrapped(&img, &l, rows)).collect();
    Ok(ReplayFilm { images, steps: out })
}

impl ReplayFilm {
    /// The table `bvhscope replay` prints: splits, SAH cost, mean of the view per ray.
    pub fn table(&self, view: View) -> String {
        let mut t = format!("{:>8}  {:>12}  mean {} per ray\n", "splits", "SAH cost", view.label().to_lowercase());
        for s in &self.steps {
            let split = s.split.as_ref().map_or(String::new(), |x| format!("  {x}"));
            let _ = writeln!(t, "{:>8}  {:>12.3}  {:.3}{split}", s.splits, s.sah, s.mean);
        }
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::{BuildParams, Bvh, Layout};
    use crate::mesh::generate;
    use std::sync::Arc;

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

    /// A film has a frame per step, each with its legend strip, the first the root alone (one leaf
    /// of every triangle), the last the finished tree; a cancelled control stops it.
    #[test]
    fn a_film_has_a_frame_per_step_from_the_root_to_the_finished_tree() {
        let mesh = generate::torus_knot(2, 3, 0.3, 48, 6);
        let tree = Arc::new(Bvh::build(&mesh, &BuildParams { layout: Layout::Binary, ..BuildParams::default() }));
        let replay = Replay::of(tree);
        let camera = Camera::framing_up(&mesh.bounds(), 40, 30, crate::render::UpAxis::Y, 45.0);
        let s = FilmSettings {
            view: View::Cost,
            colormap: ColorMap::Viridis,
            frames: 6,
            trace: TraceOptions::default(),
            cost: SahCost::default(),
        };
        let f = film(&replay, &mesh, &camera, &s, "knot", &WorkControl::new()).unwrap();
        assert_eq!(f.images.len(), 6);
        assert!(f.images.iter().all(|i| i.width() >= 40 && i.height() > 30));
        assert_eq!((f.steps[0].splits, f.steps[5].splits), (0, replay.splits()));
        assert_eq!(f.steps[0].sah, mesh.triangle_count() as f64);
        assert_eq!(f.table(View::Cost).lines().count(), 7);
        let stop = WorkControl::new();
        stop.cancel();
        assert!(film(&replay, &mesh, &camera, &s, "knot", &stop).is_err());
    }

    /// Rows of `img` from `from` down that have a light pixel (text; the colour bar is darker in red
    /// only at its start, so runs are taken from the top and the bottom of the strip).
    fn inked_runs(img: &RgbImage, from: u32) -> Vec<(u32, u32)> {
        let inked = |y: u32| (0..img.width()).any(|x| img.get_pixel(x, y).0.iter().all(|&c| c > 200));
        let mut runs: Vec<(u32, u32)> = Vec::new();
        for y in (from..img.height()).filter(|&y| inked(y)) {
            match runs.last_mut() {
                Some((_, end)) if *end == y => *end = y + 1,
                _ => runs.push((y, y + 1)),
            }
        }
        runs
    }

    /// A headline too long for the frame ("combined cost: 12/4095 splits, SAH 1078.7" in a frame
    /// 480 pixels wide) keeps the body text's size on every frame, wrapped rather than shrunk to
    /// half size (issue 59: 7-pixel headlines jumping between frames of a replay GIF), and every
    /// frame has the same size.
    #[test]
    fn a_long_headline_wraps_at_the_body_size_on_every_frame() {
        let mesh = generate::torus_knot(2, 3, 0.3, 64, 8);
        let tree = Arc::new(Bvh::build(&mesh, &BuildParams { layout: Layout::Binary, ..BuildParams::default() }));
        let replay = Replay::of(tree);
        let camera = Camera::framing_up(&mesh.bounds(), 480, 24, crate::render::UpAxis::Y, 45.0);
        let s = FilmSettings {
            view: View::Cost,
            colormap: ColorMap::Viridis,
            frames: 8,
            trace: TraceOptions::default(),
            cost: SahCost::default(),
        };
        let f = film(&replay, &mesh, &camera, &s, "knot", &WorkControl::new()).unwrap();
        let size = (f.images[0].width(), f.images[0].height());
        assert!(f.images.iter().all(|i| (i.width(), i.height()) == size), "one size for every frame");
        let mut headline = None;
        for (i, img) in f.images.iter().enumerate() {
            let runs = inked_runs(img, 24);
            // The headline's first row of glyphs, and the min / mean / max line at the bottom.
            let (title, summary) = (runs[0], *runs.last().unwrap());
            let (title_h, body_h) = (title.1 - title.0, summary.1 - summary.0);
            assert!(title_h >= body_h, "frame {i}: a headline {title_h} px high under body text {body_h} px high");
            // Its top in one place (its ink's height varies with descenders: "splits," or not).
            assert_eq!(*headline.get_or_insert(title.0), title.0, "frame {i}: the headline's place");
            // Wrapped, not cut off: no ink at the strip's right edge.
            let right = (title.0..title.1).any(|y| (size.0 - 4..size.0).any(|x| img.get_pixel(x, y).0[0] > 200));
            assert!(!right, "frame {i}: the headline runs off the frame");
        }
    }
}
