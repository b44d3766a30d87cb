//! The state of each explain view, plain data the app's state holds: the node explainer (Tree
//! and Node windows), the pinned rays, the build replay, side by side, an imported dump, a
//! class's grade report.

pub mod compare;
pub mod grade;
pub mod import;
pub mod node;
pub mod ray;
pub mod replay;

pub use compare::CompareView;
pub use grade::{GradeView, Pending};
pub use import::{ImportView, ImportedTree};
pub use node::{Metric, NodeView, Step as NodeStep};
pub use ray::{PinnedRay, RayView, SecondaryOf};
pub use replay::ReplayView;
