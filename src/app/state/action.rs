//! Everything that changes the app's state, as values. Panels, windows, the viewport and the
//! keyboard only read the state and emit actions; `BvhscopeApp::act` is the one place that
//! changes it, and `BvhscopeApp::reconcile` the one place that decides, from the state alone,
//! what to rebuild and what to re-render (the egui demo app's split of state and UI).

use super::settings::Settings;
use crate::app::jobs::Pick;
use crate::app::views::{Metric, NodeStep};
use crate::bvh::Preset;
use crate::render::{PairView, UpAxis};
use std::path::PathBuf;

#[derive(Clone, Debug, PartialEq)]
pub enum Action {
    /// Ask for a mesh or scene with the file dialog.
    Open,
    /// Open the typed-path window to open a file.
    OpenPath,
    OpenFile(PathBuf),
    ShowBuiltin,
    /// Save the view as PNG through the file dialog.
    SavePng,
    /// Save the view as PNG to a typed path.
    SavePngTyped,
    /// Export the statistics as CSV through the file dialog.
    ExportStats,
    ExportStatsJson,
    /// Export the counts behind the heatmap (one CSV row per pixel).
    ExportCounts,
    SaveScene,
    /// A file was chosen (dialog or typed path) for `Pick`.
    Picked(Pick, PathBuf),
    /// The file dialog for `Pick` is not available: the typed-path window instead, its field
    /// holding the suggested file.
    NoFileDialog(Pick),
    /// File ▸ Open BVH…: a dump for the current mesh, by the dialog, a typed path, or a file.
    OpenBvh,
    OpenBvhPath,
    ImportFile(PathBuf),
    /// File ▸ Export BVH…: the current tree as a dump.
    ExportBvh,
    /// Show the imported tree (true) or the chosen strategy's build (false).
    UseImported(bool),
    /// The Imported BVH window (the checker's findings).
    ShowImported(bool),
    /// The red mask over the pixels whose hit through the imported tree is wrong.
    WrongMask(bool),
    /// File ▸ Open grade report…: a class's grade.json (`bvhscope grade`), by the dialog, a typed
    /// path, or a file (or report folder) dropped; its students listed in the Grade report window.
    OpenGradeReport,
    OpenGradeReportPath,
    OpenGradeReportFile(PathBuf),
    /// The Grade report window.
    ShowGrade(bool),
    /// Student `i` of the report: their tree against SAH binned, or why there is none to show.
    ChooseStudent(usize),
    /// Select a node or a triangle as the dump names them (a finding's).
    SelectDumpNode(u32),
    SelectTriangle(u32),
    /// The typed-path window's text changed.
    PathText(String),
    /// The typed-path window's field has taken the keyboard.
    PathFocused,
    ClosePathWindow,

    /// Camera: orbit by a mouse drag in points, pan by a drag over a viewport of that height,
    /// zoom by a scroll amount.
    Orbit(f32, f32),
    Pan {
        dx: f32,
        dy: f32,
        height: f32,
    },
    Zoom(f32),
    FrameMesh,
    ResetView,
    /// The viewport's rectangle this frame, the image's within it (the film letterboxed, or the
    /// whole viewport) and the image size it renders at.
    Viewport {
        rect: egui::Rect,
        image: egui::Rect,
        pixels: (u32, u32),
    },

    /// Show view number `i` of `View::ALL` (shortcuts 1..5, the View menu).
    View(usize),
    ToggleBoxes,
    DepthUp,
    DepthDown,
    NextStrategy,
    NextColormap,
    ApplyPreset(Preset),
    /// Orbit about another axis (the camera goes back to that axis's default view).
    SetUpAxis(UpAxis),
    /// The build or view panel's form, edited: the settings as they now are.
    Edit(Box<Settings>),

    /// Pin the ray of pixel (x, y) of the image on screen (0-based, from the top left).
    PinPixel(u32, u32),
    /// Pin secondary ray `k` of pixel (x, y) (the View panel's ray kind, from its camera ray's
    /// hit), to walk it.
    PinSecondary(u32, u32, usize),
    /// Pin the ray typed in the Ray window.
    PinTyped,
    /// The Ray window's typed origin and direction changed.
    RayText {
        origin: String,
        dir: String,
    },
    Unpin(usize),
    UnpinAll,
    SelectPinned(usize),
    /// Show step `k` (0-based) of the selected pinned ray.
    RayStep(usize),
    /// Step forwards (or back) by so many steps.
    RayStepBy(i64),
    RayPlay(bool),
    /// Open the Ray window with nothing pinned (to type a ray).
    ShowRayWindow,

    /// Open (or close) the Tree and Node windows.
    ShowTree(bool),
    /// Select node `n` of the binary tree as built (tree view, icicle, breadcrumb).
    SelectNode(u32),
    /// Select the leaf that holds the hit of pixel (x, y) of the image on screen.
    SelectPixelNode(u32, u32),
    /// Move the selection to the parent, a child or the sibling.
    NodeStep(NodeStep),
    /// Open or close a row of the tree view.
    ToggleOpen(u32),
    /// What the icicle colours by.
    SetMetric(Metric),

    /// Side by side: show B (another strategy's build) next to A.
    Compare(bool),
    CompareStrategy(crate::bvh::Strategy),
    /// B's leaf size, layout and traversal.
    CompareB {
        max_leaf_size: u32,
        layout: crate::bvh::Layout,
        trace: crate::bvh::TraceOptions,
    },
    CompareMode(PairView),
    /// Where the wipe line is, 0 (left) to 1 (right).
    Wipe(f32),
    /// Open (or close) the Replay window: the viewport shows the tree after some splits.
    ShowReplay(bool),
    /// Show the tree after `k` splits.
    ReplayStep(usize),
    ReplayPlay(bool),
    /// Write the replay as an animation (.gif or .png), as `bvhscope replay -o` does.
    ExportReplay,
    /// Stop writing it.
    CancelFilm,
    /// Highlight the pixels whose heatmap value is above this (None: no highlight).
    SetThreshold(Option<f32>),

    /// Toggle the Help window.
    Help,
    SetHelp(bool),
    /// Dismiss message `i` of the viewport's messages.
    Dismiss(usize),
    /// Dismiss the `n` oldest messages (those folded out of sight).
    DismissEarlier(usize),
    /// The Node window's cost curves on one scale for the three axes, or each on its own.
    SharedCostScale(bool),
    /// Time the current BVH against the linear scan on the frame on screen (or stop timing).
    TimeLinear(bool),
    /// Pin the ray of the pixel with the most work in the heatmap on screen (`false`), or of the
    /// next one after the last pinned so (`true`), as `bvhscope trace --hottest K` traces it.
    Hottest {
        next: bool,
    },
    /// Put the selected pinned ray's `bvhscope trace` command on the clipboard.
    CopyTraceCommand,
    /// Presenting to a room: large text, large plots (View › Present), or the other way (F5).
    Present(bool),
    TogglePresent,
    /// The screen's scale: set, or a step of 10 % up or down (Ctrl +/−).
    UiScale(f32),
    UiScaleBy(i32),
    /// The docked layout as a fresh start has it.
    ResetLayout,
    /// The heatmap legend folded to its colour bar (`true`) or shown whole.
    FoldLegend(bool),
    /// The camera: a lesson step's, or (`None`) the scene's own (the mesh's default view).
    SetCamera(Option<crate::render::Camera>),

    /// Lessons (`state::lesson`): File ▸ Open lesson… by the dialog, by a typed path, or a file
    /// (opened at its first step).
    OpenLesson,
    OpenLessonPath,
    OpenLessonFile(PathBuf),
    /// Go to step `k` (0-based) of the open lesson.
    LessonGo(usize),
    /// The clicker's keys: the step's answer if it has one not shown yet, else the next step; the
    /// previous step (its answer shown), or the answer hidden again.
    LessonNext,
    LessonPrevious,
    /// Lesson ▸ New lesson: no steps yet, the band ready to type in.
    NewLesson,
    /// What the app shows, as a step after the one on screen (or in place of it).
    AddStep,
    ReplaceStep,
    /// The band's fields: the lesson's title and the step's caption, question and answer.
    LessonText {
        title: String,
        caption: String,
        question: String,
        answer: String,
    },
    /// The band's fields shown (to type the captions) or the captions as the room sees them.
    LessonEditing(bool),
    /// Save the lesson through the file dialog.
    SaveLesson,
    CloseLesson,
}

/// Where panels put the actions they emit during one frame.
pub type Actions = Vec<Action>;
