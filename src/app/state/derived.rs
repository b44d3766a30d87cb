//! Images derived from the frame on screen for the overlays, each cached while its inputs stay
//! the same: the side-by-side pair and their difference, the selected node's mask, the legend's
//! histogram and its threshold's mask, the imported tree's wrong pixels; and the figures of the
//! current build and of B, as the statistics panel and its exports read them.

use super::app::{BvhscopeApp, MaskCache};
use super::figures::{MeasuredRays, RaysKey, Shown, StrategyFigures};
use crate::app::jobs::Timed;
use crate::app::views::{compare, node};
use crate::bvh::TreeStats;
use std::sync::Arc;

/// Bins of the legend's histogram.
pub const HISTOGRAM_BINS: usize = 32;

impl BvhscopeApp {
    /// The side-by-side images (A's and B's on one scale, and their difference), once both frames
    /// of one camera are there (cached for the pair and the view).
    pub fn compare_images(&self, ctx: &egui::Context) -> Option<Arc<compare::CompareImages>> {
        use crate::render::diff;
        let (shown, b) = self.shown_pair()?;
        let (view, colormap, cost) = (shown.style.view, shown.style.colormap, shown.style.cost);
        let mut cache = self.compare_cache.borrow_mut();
        if let Some(c) = cache.as_ref() {
            if Arc::ptr_eq(&c.a_frame, &shown.frame)
                && Arc::ptr_eq(&c.b_frame, &b.frame)
                && c.view == view
                && c.colormap == colormap
                && c.range == shown.style.range
                && c.diff_range == self.settings.diff_ranges.get(&view).copied()
            {
                return Some(c.clone());
            }
        }
        let texture = |name: &str, img: image::RgbImage| {
            let c = egui::ColorImage::from_rgb([img.width() as usize, img.height() as usize], img.as_raw());
            ctx.load_texture(name, c, egui::TextureOptions::NEAREST)
        };
        let style = self.pair_style(shown);
        let (img_a, img_b, legend) = crate::render::pair::pair_images(&shown.frame, &b.frame, &style);
        let diff_range = self.settings.diff_ranges.get(&view).copied();
        let diff = diff::difference(&shown.frame, &b.frame, view, cost).map(|d| {
            let (img, legend) = diff::difference_image(shown.frame.width(), &d, view, style.diff_range);
            (texture("compare-diff", img), d, legend)
        });
        let images = Arc::new(compare::CompareImages {
            a_frame: shown.frame.clone(),
            b_frame: b.frame.clone(),
            view,
            colormap,
            range: shown.style.range,
            diff_range,
            a: texture("compare-a", img_a),
            b: texture("compare-b", img_b),
            diff,
            legend,
        });
        *cache = Some(images.clone());
        Some(images)
    }

    /// Compare's pair as it is on screen: A's frame (complete) and B's of the same camera; `None`
    /// outside Compare or while B is not there yet (the images and the exports both ask).
    pub(in crate::app) fn shown_pair(&self) -> Option<(&Shown, &compare::CompareB)> {
        if !self.compare.on {
            return None;
        }
        let shown = self.shown.as_ref().filter(|s| s.frame.is_complete() && s.partial.is_none())?;
        let b = self.compare.b.as_ref().filter(|b| b.camera == shown.camera && b.scene_id == self.scene_id)?;
        Some((shown, b))
    }

    /// How the pair on screen is drawn: `shown`'s view, colour map and range, the difference's range.
    pub fn pair_style(&self, shown: &Shown) -> crate::render::pair::PairStyle {
        let s = shown.style;
        let diff_range = self.settings.diff_ranges.get(&s.view).copied().into();
        crate::render::pair::PairStyle { view: s.view, colormap: s.colormap, cost: s.cost, range: s.range, diff_range }
    }

    /// A mask over `shown`'s frame that dims every pixel whose hit is not a triangle of `node`'s
    /// subtree (cached for the frame and the node).
    pub fn node_mask(
        &self,
        ctx: &egui::Context,
        shown: &Shown,
        e: &Arc<node::Explained>,
        node: u32,
    ) -> Option<egui::TextureHandle> {
        let f = &shown.frame;
        if !f.is_complete() {
            return None;
        }
        let mut cache = self.mask_cache.borrow_mut();
        if let Some(c) = cache.as_ref() {
            if Arc::ptr_eq(&c.frame, f) && Arc::ptr_eq(&c.tree, e) && c.node == node {
                return Some(c.texture.clone());
            }
        }
        let (w, h) = (f.width() as usize, f.height() as usize);
        let h_ = &e.hierarchy;
        let mut pixels = Vec::with_capacity(w * h);
        for y in 0..h {
            for x in 0..w {
                let s = f.sample(x as u32, y as u32);
                // (A triangle cut by spatial splits is in the node if any of its parts is.)
                let inside = s.is_hit() && h_.slots_of_prim(s.prim).any(|slot| h_.holds(node as usize, slot));
                pixels.push(if inside { egui::Color32::TRANSPARENT } else { egui::Color32::from_black_alpha(150) });
            }
        }
        let image = egui::ColorImage::new([w, h], pixels);
        let tex = ctx.load_texture("node-mask", image, egui::TextureOptions::NEAREST);
        *cache = Some(MaskCache { frame: f.clone(), tree: e.clone(), node, texture: tex.clone() });
        Some(tex)
    }

    /// The legend's histogram of the heatmap on screen (`render::histogram` over the legend's
    /// range, `HISTOGRAM_BINS` bins; cached for the frame and view).
    pub fn legend_histogram(&self) -> Option<Vec<u32>> {
        let shown = self.shown.as_ref()?;
        let legend = shown.legend.as_ref()?;
        let view = shown.style.view;
        let mut cache = self.histogram_cache.borrow_mut();
        if let Some((f, v, h)) = cache.as_ref() {
            if Arc::ptr_eq(f, &shown.frame) && *v == view {
                return Some(h.clone());
            }
        }
        let h = crate::render::histogram(
            &shown.frame,
            view,
            shown.style.cost,
            legend.range_min,
            legend.range_max,
            HISTOGRAM_BINS,
        );
        *cache = Some((shown.frame.clone(), view, h.clone()));
        Some(h)
    }

    /// A mask over the heatmap on screen dimming the pixels at or below the threshold (cached).
    pub fn threshold_mask(&self, ctx: &egui::Context, shown: &Shown) -> Option<egui::TextureHandle> {
        let t = self.threshold?;
        shown.legend.as_ref()?;
        let (f, view) = (&shown.frame, shown.style.view);
        if !f.is_complete() || !f.counted() {
            return None;
        }
        let mut cache = self.threshold_cache.borrow_mut();
        if let Some((cf, cv, ct, tex)) = cache.as_ref() {
            if Arc::ptr_eq(cf, f) && *cv == view && *ct == t {
                return Some(tex.clone());
            }
        }
        let (w, h) = (f.width(), f.height());
        // A complete frame's values, pixel by pixel (a warp view's are its groups').
        let pixels = crate::render::grid_values(f, view, shown.style.cost)
            .into_iter()
            .map(|v| if v > t { egui::Color32::TRANSPARENT } else { egui::Color32::from_black_alpha(170) })
            .collect();
        let tex = ctx.load_texture(
            "threshold-mask",
            egui::ColorImage::new([w as usize, h as usize], pixels),
            egui::TextureOptions::NEAREST,
        );
        *cache = Some((f.clone(), view, t, tex.clone()));
        Some(tex)
    }
}

impl BvhscopeApp {
    /// Figures of the current strategy for the statistics panel.
    pub fn current_figures(&self) -> Option<StrategyFigures> {
        self.current_bvh().map(|b| StrategyFigures {
            label: b.bvh.label(),
            // The end-point overlap comes with the prepared tree, a moment after the image.
            stats: {
                let e = self.nodes.current(Some(&b.bvh));
                TreeStats {
                    epo: e.map(|e| e.epo),
                    epo_error: e.and_then(|e| e.epo_error),
                    walk_bytes: b.bvh.walk_bytes(self.settings.trace),
                    ..b.stats.clone()
                }
            },
            build_ms: b.bvh.build_time().as_secs_f64() * 1e3,
            rays: self.rays,
            frame_ms: self
                .last_full_frame
                .filter(|_| self.shown.as_ref().is_some_and(|s| Arc::ptr_eq(&s.bvh, &b.bvh)))
                .map(|d| d.as_secs_f64() * 1e3),
            speedup: self.fresh_speedup().map(|t| t.speedup),
        })
    }

    /// The timing against the linear scan of the tree, camera and traversal on screen, if there
    /// is one (an older tree's or camera's is stale).
    pub fn fresh_speedup(&self) -> Option<&Timed> {
        let shown = self.shown.as_ref()?;
        self.speedup
            .as_ref()
            .filter(|t| Arc::ptr_eq(&t.bvh, &shown.bvh) && t.camera == shown.camera && t.trace == shown.trace)
    }

    /// Why `f`'s per-ray figures are not of the image on screen (a phrase for their tooltips:
    /// "of a 703×646 image; the image is 703×459"), or `None` when they are: measured on another
    /// image size, camera, ray kind, seed or traversal, or the image is of another tree (the build
    /// replay's partial one). Figures shown unmarked must be the image's (issue 59).
    pub fn stale_figures(&self, f: &StrategyFigures) -> Option<String> {
        let (r, shown) = (f.rays.as_ref()?, self.shown.as_ref()?);
        let rays = r.key().stale_because(&shown.rays_key());
        let tree =
            shown.partial.is_some().then_some("of the whole tree; the image shows the build replay's partial tree");
        match (rays, tree) {
            (Some(r), Some(t)) => Some(format!("{r}, and {t}")),
            (r, t) => r.or(t.map(str::to_string)),
        }
    }

    /// The rays the statistics' second column is set against: the current figures' own, or
    /// before there are any, the image's.
    pub fn figures_key(&self) -> Option<RaysKey> {
        self.rays.map(|r| r.key()).or_else(|| self.shown.as_ref().map(Shown::rays_key))
    }

    /// B's figures for the statistics panel's second column, while comparing side by side.
    pub fn compare_figures(&self) -> Option<StrategyFigures> {
        let b = self.compare.b.as_ref().filter(|b| self.compare.on && b.scene_id == self.scene_id)?;
        Some(StrategyFigures {
            label: format!("B: {}", b.bvh.label()),
            stats: TreeStats { walk_bytes: b.bvh.walk_bytes(b.trace), ..b.stats.clone() },
            build_ms: b.bvh.build_time().as_secs_f64() * 1e3,
            rays: Some(MeasuredRays {
                summary: b.summary,
                camera: b.camera,
                trace: b.trace,
                secondary: b.frame.secondary().copied(),
            }),
            frame_ms: None,
            speedup: None,
        })
    }
}

impl BvhscopeApp {
    /// The red mask over the frame on screen: its pixels whose hit is wrong (cached per result).
    pub fn wrong_mask(&self, ctx: &egui::Context) -> Option<(egui::TextureHandle, usize)> {
        let s = self.shown.as_ref().filter(|s| self.import.mask && s.frame.is_complete())?;
        let w = self.import.wrong_for(&s.bvh, &s.camera, &s.trace)?;
        let mut cache = self.wrong_cache.borrow_mut();
        if let Some((bvh, camera, trace, tex)) = cache.as_ref() {
            if self.import.wrong_for(bvh, camera, trace).is_some_and(|c| std::ptr::eq(c, w)) {
                return Some((tex.clone(), w.pixels.len()));
            }
        }
        let (width, height) = (s.camera.width as usize, s.camera.height as usize);
        let mut image = egui::ColorImage::new([width, height], vec![egui::Color32::TRANSPARENT; width * height]);
        for &(x, y) in &w.pixels {
            image.pixels[y as usize * width + x as usize] = egui::Color32::from_rgba_unmultiplied(255, 0, 0, 200);
        }
        let tex = ctx.load_texture("wrong-pixels", image, egui::TextureOptions::NEAREST);
        *cache = Some((w.bvh.clone(), w.camera, w.trace, tex.clone()));
        Some((tex, w.pixels.len()))
    }
}
