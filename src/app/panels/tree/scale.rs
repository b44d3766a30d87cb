//! The icicle's colour scale: how a node's value of the chosen metric becomes a colour, and the
//! bar under the icicle that says so with its end values. Shares (SAH, EPO) and visits span
//! orders of magnitude: a linear or square-root scale to the largest left all but a few nodes at
//! its dark end (the EPO share "saturated"), so those are drawn on a log scale from the smallest
//! non-zero value present to the largest; overlap and depth on a linear one from 0.

use crate::app::views::node::Metric;
use crate::render::ColorMap;
use egui::{Color32, Sense};

/// A metric's values mapped onto the colour map.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scale {
    /// The values at the colour map's two ends.
    pub lo: f64,
    pub hi: f64,
    pub log: bool,
}

impl Scale {
    /// The scale for `metric` over the values present (`None`: not known yet).
    pub fn of(metric: Metric, values: &[Option<f64>]) -> Option<Scale> {
        let known = values.iter().flatten().copied().filter(|v| v.is_finite());
        let hi = known.clone().fold(f64::NEG_INFINITY, f64::max);
        if hi <= 0.0 || !hi.is_finite() {
            return None;
        }
        let spans = matches!(metric, Metric::Visits | Metric::Sah | Metric::Epo);
        let lo = known.filter(|&v| v > 0.0).fold(f64::INFINITY, f64::min);
        if spans && lo < hi {
            Some(Scale { lo, hi, log: true })
        } else {
            Some(Scale { lo: 0.0, hi, log: false })
        }
    }

    /// Where `v` lies on the scale, 0 to 1 (on a log scale, 0 and below the smallest at 0).
    pub fn t(&self, v: f64) -> f32 {
        let t = if self.log {
            if v <= 0.0 {
                0.0
            } else {
                (v / self.lo).ln() / (self.hi / self.lo).ln()
            }
        } else {
            (v - self.lo) / (self.hi - self.lo)
        };
        t.clamp(0.0, 1.0) as f32
    }

    pub fn color(&self, v: f64) -> Color32 {
        let [r, g, b] = ColorMap::Viridis.map(self.t(v));
        Color32::from_rgb(r, g, b)
    }

    /// What the bar says: "Colour scale: EPO share, log, 1.2e-6 to 0.0345".
    pub fn text(&self, metric: Metric) -> String {
        let kind = if self.log { "log" } else { "linear" };
        format!("Colour scale: {}, {kind}, {} to {}", metric.label(), number(self.lo), number(self.hi))
    }
}

/// A value as the scale's ends print it: whole numbers whole, small ones in scientific notation.
fn number(v: f64) -> String {
    if v == v.round() && v.abs() < 1e9 {
        format!("{v:.0}")
    } else if v.abs() >= 0.01 {
        format!("{v:.4}")
    } else {
        format!("{v:.2e}")
    }
}

/// The bar: the colour map from end to end, its end values under it, the scale named.
pub fn bar(ui: &mut egui::Ui, scale: &Scale, metric: Metric) {
    ui.horizontal(|ui| {
        ui.label(number(scale.lo));
        let (rect, _) = ui.allocate_exact_size(egui::vec2(160.0, 12.0), Sense::hover());
        let steps = 64;
        for k in 0..steps {
            let t = k as f32 / (steps - 1) as f32;
            let [r, g, b] = ColorMap::Viridis.map(t);
            let x0 = rect.left() + rect.width() * k as f32 / steps as f32;
            let x1 = rect.left() + rect.width() * (k + 1) as f32 / steps as f32;
            let r8 = egui::Rect::from_min_max(egui::pos2(x0, rect.top()), egui::pos2(x1 + 0.5, rect.bottom()));
            ui.painter().rect_filled(r8, 0.0, Color32::from_rgb(r, g, b));
        }
        ui.label(number(scale.hi));
        let kind = if scale.log { "log scale" } else { "linear" };
        ui.weak(format!("{} ({kind})", metric.label()));
    })
    .response
    .widget_info(|| egui::WidgetInfo::labeled(egui::Role::Label, true, scale.text(metric)));
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Shares spread over six decades: each decade its own colour, evenly spaced, the largest at
    /// the top and the smallest at the bottom; under the old square root to the largest, the
    /// five lowest decades all fell in the bottom tenth of the map.
    #[test]
    fn shares_over_decades_do_not_saturate() {
        let values: Vec<Option<f64>> = (0..=6).map(|k| Some(10f64.powi(-k))).chain([Some(0.0), None]).collect();
        let s = Scale::of(Metric::Epo, &values).unwrap();
        assert!(s.log && s.lo == 1e-6 && s.hi == 1.0, "{s:?}");
        let ts: Vec<f32> = (0..=6).rev().map(|k| s.t(10f64.powi(-k))).collect();
        for (k, t) in ts.iter().enumerate() {
            assert!((t - k as f32 / 6.0).abs() < 1e-5, "decade {k}: {t}");
        }
        assert_eq!(s.t(0.0), 0.0);
        let colours: Vec<Color32> = (0..=6).map(|k| s.color(10f64.powi(-k))).collect();
        for (i, c) in colours.iter().enumerate() {
            assert!(!colours[..i].contains(c), "decade {i} shares a colour");
        }
        assert_eq!(s.text(Metric::Epo), "Colour scale: EPO share, log, 1.00e-6 to 1");
    }

    #[test]
    fn overlap_and_depth_are_linear_from_zero_and_nothing_known_has_no_scale() {
        let s = Scale::of(Metric::Depth, &[Some(0.0), Some(4.0), Some(8.0)]).unwrap();
        assert_eq!(s, Scale { lo: 0.0, hi: 8.0, log: false });
        assert_eq!(s.t(4.0), 0.5);
        assert_eq!(Scale::of(Metric::Visits, &[None, None]), None);
        assert_eq!(Scale::of(Metric::Epo, &[Some(0.0)]), None);
    }
}
