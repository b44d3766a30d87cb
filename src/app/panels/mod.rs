//! The panels around the viewport; each reads and changes the app state, nothing more.

pub mod build;
pub mod menu;
pub mod stats;
pub mod status;
pub mod view;
pub mod windows;
