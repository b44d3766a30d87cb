//! The ray-cast renderer shared by the CLI and the app: a pinhole camera, one ray per pixel in
//! progressive passes over tiles (rayon), per-pixel counters, and conversion of the result into
//! images: normals, depth, and heatmaps of traversal work with a legend.
//! Node boxes as line segments over an image, and drawn into it: `boxes` (the app's overlay, `render --boxes`).

pub mod animation;
pub mod boxes;
mod camera;
mod colormap;
pub mod diff;
mod exact_stats;
mod frame;
mod incoherent;
pub mod legend;
pub mod pair;
mod ray_summary;
mod raycast;
mod sample;
pub mod secondary;
mod views;
pub mod warp;

pub use camera::{Camera, CameraError, RayGen, RayGenParts, UpAxis};
pub use colormap::ColorMap;
pub use frame::{Frame, FramePool, FromHitsError};
pub use incoherent::incoherent_rays;
pub use legend::{draw_legend, draw_legend_wrapped, legend_height, legend_rows, LegendRows};
pub use pair::PairView;
pub use ray_summary::RaySummary;
pub use raycast::{
    render, render_passes, render_passes_counts_after, render_progressive, PassInfo, RenderSettings, PASS_STRIDES,
};
pub use sample::PixelSample;
pub use secondary::{RayKind, SecondaryRays, SecondarySpec};
pub use views::{
    full_size, grid_values, histogram, hottest, metric_stats, view_image, HeatRange, Legend, View, NO_RAYS,
};
