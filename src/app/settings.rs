//! What the user chose, remembered across runs (eframe persistence).

use crate::bvh::{BuildParams, TraceOptions};
use crate::render::{ColorMap, HeatRange, View};
use std::path::PathBuf;

/// How many recent files the File menu remembers.
pub const MAX_RECENT: usize = 10;

#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct Settings {
    pub build: BuildParams,
    pub trace: TraceOptions,
    pub view: View,
    pub colormap: ColorMap,
    /// Heatmap range: the frame's own min..max, or `fixed_range`.
    pub auto_range: bool,
    pub fixed_range: (f32, f32),
    pub show_boxes: bool,
    pub box_depth: u32,
    /// Also draw leaves shallower than `box_depth`.
    pub boxes_leaves_above: bool,
    /// Coarse passes first (off: each frame at full resolution at once).
    pub progressive: bool,
    pub recent_files: Vec<PathBuf>,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            build: BuildParams::default(),
            trace: TraceOptions::default(),
            view: View::Normals,
            colormap: ColorMap::Viridis,
            auto_range: true,
            fixed_range: (0.0, 100.0),
            show_boxes: false,
            box_depth: 3,
            boxes_leaves_above: false,
            progressive: true,
            recent_files: Vec::new(),
        }
    }
}

impl Settings {
    pub fn heat_range(&self) -> HeatRange {
        if self.auto_range {
            HeatRange::Auto
        } else {
            HeatRange::Fixed { min: self.fixed_range.0, max: self.fixed_range.1 }
        }
    }

    /// Put `path` at the top of the recent files.
    pub fn remember(&mut self, path: PathBuf) {
        let path = path.canonicalize().unwrap_or(path);
        self.recent_files.retain(|p| p != &path);
        self.recent_files.insert(0, path);
        self.recent_files.truncate(MAX_RECENT);
    }
}
