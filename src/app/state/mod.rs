//! The app's state and the actions that change it: `BvhscopeApp` (`app.rs`) with what it reads
//! without changing anything (`derived.rs`: images and figures derived from it, cached;
//! `gpu.rs`: whether the GPU traces and builds), the `Action`s the panels emit (`action.rs`) and
//! the keys that emit them (`shortcuts.rs`), the settings, the camera, the docked layout, the
//! figures shown and the overlay's boxes.

pub mod action;
mod app;
mod built;
mod derived;
pub mod dock;
mod figures;
mod gpu;
mod lesson;
pub mod orbit;
pub mod overlay;
mod settings;
pub mod shortcuts;

pub use action::{Action, Actions};
pub use app::{AppOptions, BvhscopeApp};
pub use built::{BuildCache, BuiltBvh};
pub use dock::{Pane, DOCK_KEY};
pub use figures::{MeasuredRays, Message, MessageKind, PathWindow, RaysKey, Shown, StrategyFigures};
pub use lesson::{Applying, LessonState, Stage};
pub use orbit::OrbitCamera;
pub use overlay::OverlayBox;
pub use settings::{BoxLevel, Film, Settings, PRESENT_SCALE, UI_SCALES};
