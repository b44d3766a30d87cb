//! What the user chose, remembered across runs (eframe persistence).

use crate::bvh::{BuildParams, Layout, Preset, TraceOptions};
use crate::gpu_path::{Device, GpuNodes};
use crate::render::{ColorMap, HeatRange, SecondarySpec, UpAxis, View};
use std::collections::HashMap;
use std::path::PathBuf;

/// How many recent files the File menu remembers.
pub const MAX_RECENT: usize = 10;

#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct Settings {
    /// The single BVH's parameters, or the bottom level's (each mesh's BVH) with two levels.
    pub build: BuildParams,
    /// For scene files: a top-level BVH over the mesh placements over one BVH per mesh.
    pub two_level: bool,
    /// The top level's parameters (always the binary layout).
    pub top_build: BuildParams,
    /// Which level's boxes the overlay draws (two-level BVH).
    pub box_level: BoxLevel,
    /// Depth of the top level's boxes (`box_depth` is the bottom level's, or the single BVH's).
    pub top_box_depth: u32,
    pub trace: TraceOptions,
    pub view: View,
    /// Which rays the heatmaps count: the camera's, or shadow, ao or bounce rays from its hits
    /// (the CLI's `--ray-kind`, `--samples`, `--ao-length`, `--light`, `--seed`).
    pub rays: SecondarySpec,
    pub colormap: ColorMap,
    /// Fixed heatmap ranges, per view (a view without one uses its frame's own min..max). Each
    /// view has its own because their scales differ (nodes visited 0..60, combined cost 0..250);
    /// cleared when a scene is opened, whose scale is its own too, so not saved either.
    #[serde(skip)]
    pub fixed_ranges: HashMap<View, (f32, f32)>,
    /// Compare's difference B − A on a fixed ±range (as `render --difference --range -R:R`);
    /// `None`: its own 99th percentile. Per view, cleared with the scene as `fixed_ranges`.
    #[serde(skip)]
    pub diff_ranges: HashMap<View, f32>,
    /// Which axis of the mesh points up (the orbit and the default camera follow it).
    pub up_axis: UpAxis,
    pub show_boxes: bool,
    pub box_depth: u32,
    /// Also draw leaves shallower than `box_depth`.
    pub boxes_leaves_above: bool,
    /// Draw only the parts of the boxes in front of the surface (depth-tested against the
    /// ray-cast image), so deep levels do not hide the mesh.
    pub boxes_in_front: bool,
    /// Coarse passes first (off: each frame at full resolution at once).
    pub progressive: bool,
    /// What the image is rendered at: the viewport's size, or a scene file's film (its camera's
    /// size and aspect, letterboxed in the viewport), so the figures are the scene's frame's.
    pub film: Film,
    /// Where frames are traced (and lbvh, ploc built): the CPU or the GPU (`app::state::gpu`).
    pub device: Device,
    /// The node format the GPU walks.
    pub gpu_nodes: GpuNodes,
    pub recent_files: Vec<PathBuf>,
    /// The size of everything on screen (Ctrl +/−; 1: egui's own).
    pub ui_scale: f32,
    /// Presenting to a room (View › Present): everything at least `PRESENT_SCALE`, the Node
    /// view's plots half its tile tall.
    pub present: bool,
    /// The heatmap legend folded to its colour bar beside or below the image (more room for it).
    pub legend_folded: bool,
}

/// Presenting: text of at least 18 px (egui's body text is 12.5 px at scale 1).
pub const PRESENT_SCALE: f32 = 1.5;
/// The sizes Ctrl +/− choose among.
pub const UI_SCALES: std::ops::RangeInclusive<f32> = 0.75..=2.5;

impl Settings {
    /// The scale the screen is drawn at.
    pub fn zoom(&self) -> f32 {
        let s = self.ui_scale.clamp(*UI_SCALES.start(), *UI_SCALES.end());
        if self.present {
            s.max(PRESENT_SCALE)
        } else {
            s
        }
    }
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            build: BuildParams::default(),
            two_level: true,
            top_build: BuildParams { max_leaf_size: 1, layout: Layout::Binary, ..BuildParams::default() },
            box_level: BoxLevel::Both,
            top_box_depth: 1,
            trace: TraceOptions::default(),
            view: View::Normals,
            rays: SecondarySpec::default(),
            colormap: ColorMap::Viridis,
            fixed_ranges: HashMap::new(),
            diff_ranges: HashMap::new(),
            up_axis: UpAxis::Y,
            show_boxes: false,
            box_depth: 3,
            boxes_leaves_above: false,
            boxes_in_front: false,
            progressive: true,
            film: Film::Scene,
            device: Device::Cpu,
            gpu_nodes: GpuNodes::Binary,
            recent_files: Vec::new(),
            ui_scale: 1.0,
            present: false,
            legend_folded: false,
        }
    }
}

/// What the image is rendered at.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Film {
    /// The viewport's own size and aspect.
    Viewport,
    /// A scene file's camera size (the viewport's when the scene has none), letterboxed.
    #[default]
    Scene,
}

/// The overlay's choice of level for a two-level BVH.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum BoxLevel {
    Top,
    Bottom,
    #[default]
    Both,
}

impl BoxLevel {
    pub const ALL: [BoxLevel; 3] = [BoxLevel::Top, BoxLevel::Bottom, BoxLevel::Both];

    pub fn label(self) -> &'static str {
        match self {
            BoxLevel::Top => "Top level",
            BoxLevel::Bottom => "Bottom level",
            BoxLevel::Both => "Both",
        }
    }

    pub fn shows_top(self) -> bool {
        self != BoxLevel::Bottom
    }

    pub fn shows_bottom(self) -> bool {
        self != BoxLevel::Top
    }
}

impl Settings {
    /// The heatmap range of the current view.
    pub fn heat_range(&self) -> HeatRange {
        match self.fixed_ranges.get(&self.view) {
            Some(&(min, max)) => HeatRange::Fixed { min, max },
            None => HeatRange::Auto,
        }
    }

    /// Set what `preset` sets (the rest stays).
    pub fn apply_preset(&mut self, preset: Preset) {
        let p = preset.build();
        self.build = BuildParams {
            strategy: p.strategy,
            layout: p.layout,
            max_leaf_size: p.max_leaf_size,
            cost: p.cost,
            ..self.build
        };
        self.trace = preset.trace_options();
        self.two_level = preset.two_level();
    }

    /// Whether the settings are `preset`'s.
    pub fn is_preset(&self, preset: Preset) -> bool {
        preset.is_applied(&self.build, &self.trace, self.two_level)
    }

    /// Put `path` at the top of the recent files.
    pub fn remember(&mut self, path: PathBuf) {
        let path = path.canonicalize().unwrap_or(path);
        self.recent_files.retain(|p| p != &path);
        self.recent_files.insert(0, path);
        self.recent_files.truncate(MAX_RECENT);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    /// eframe's storage in memory, to check what the app saves comes back on the next start.
    #[derive(Default)]
    struct MemoryStorage(HashMap<String, String>);

    impl eframe::Storage for MemoryStorage {
        fn get_string(&self, key: &str) -> Option<String> {
            self.0.get(key).cloned()
        }
        fn set_string(&mut self, key: &str, value: String) {
            self.0.insert(key.to_string(), value);
        }
        fn remove_string(&mut self, key: &str) {
            self.0.remove(key);
        }
        fn flush(&mut self) {}
    }

    #[test]
    fn settings_and_recent_files_survive_a_restart() {
        let mut s = Settings::default();
        s.build.strategy = crate::bvh::Strategy::Midpoint;
        s.view = View::TriTests;
        s.colormap = ColorMap::Turbo;
        s.up_axis = UpAxis::Z;
        s.boxes_in_front = true;
        for i in 0..12 {
            s.remember(PathBuf::from(format!("/nonexistent/mesh{i}.obj")));
        }
        s.remember(PathBuf::from("/nonexistent/mesh3.obj"));
        assert_eq!(s.recent_files.len(), MAX_RECENT);
        assert_eq!(s.recent_files[0], PathBuf::from("/nonexistent/mesh3.obj"), "reopened file moves to the top");
        assert_eq!(s.recent_files.iter().filter(|p| p.ends_with("mesh3.obj")).count(), 1);

        let mut storage = MemoryStorage::default();
        eframe::set_value(&mut storage, eframe::APP_KEY, &s);
        let back: Settings = eframe::get_value(&storage, eframe::APP_KEY).expect("saved settings load");
        assert_eq!(back, s);
    }

    #[test]
    fn a_fixed_range_belongs_to_its_view() {
        let mut s = Settings { view: View::Visits, ..Settings::default() };
        s.fixed_ranges.insert(View::Visits, (0.0, 56.0));
        assert_eq!(s.heat_range(), HeatRange::Fixed { min: 0.0, max: 56.0 });
        s.view = View::Cost;
        assert_eq!(s.heat_range(), HeatRange::Auto, "nodes visited's scale is not combined cost's");
    }

    #[test]
    fn the_handout_preset_is_applied_and_recognised() {
        let mut s = Settings::default();
        assert!(!s.is_preset(Preset::Handout));
        s.apply_preset(Preset::Handout);
        assert!(s.is_preset(Preset::Handout));
        assert_eq!(s.build.strategy, crate::bvh::Strategy::Midpoint);
        assert_eq!(s.build.max_leaf_size, Preset::HANDOUT_MAX_LEAF_SIZE);
        assert!(!s.two_level);
        s.build.max_leaf_size = 8;
        assert!(!s.is_preset(Preset::Handout), "a changed leaf size is no longer the handout's");
    }

    #[test]
    fn settings_from_an_older_version_fill_missing_fields_with_defaults() {
        let mut storage = MemoryStorage::default();
        eframe::Storage::set_string(&mut storage, eframe::APP_KEY, "(view: Depth)".into());
        let back: Settings = eframe::get_value(&storage, eframe::APP_KEY).expect("partial settings load");
        assert_eq!(back.view, View::Depth);
        assert_eq!(back.build, BuildParams::default());
    }
}
