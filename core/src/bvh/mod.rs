//! Bounding volume hierarchies: the flat node array, the top-down builder with one file per split
//! strategy, ordered traversal generic over a statistics sink, tree statistics, and the linear scan
//! every BVH is checked against.

mod accel;
mod any;
mod build;
mod counters;
pub mod epo;
pub mod imported;
pub mod inspect;
pub mod lbvh;
mod linear;
mod node;
pub mod packet;
mod params;
mod ploc;
mod preset;
pub mod reinsert;
pub mod replay;
pub mod sbvh;
mod scene_bvh;
mod simd;
pub mod split;
mod stack;
mod stats;
mod subtree;
pub mod trace;
mod traverse;
pub mod tree;
pub mod two_level;
pub mod visits;
pub mod wide;

pub use accel::{Accelerator, Hit, TraceOptions, TraversalOrder};
pub use any::AnyBvh;
pub use build::{BuildParams, BuildReport, Layout, SahCost};
pub use counters::{NoStats, RayCounters, TraversalStats};
pub use linear::LinearScan;
pub use node::{Bvh, BvhNode, TRAVERSAL_STACK_SIZE};
pub use preset::Preset;
pub use scene_bvh::{SceneBuild, SceneBvh};
pub use split::SplitStrategy;
pub use stats::{fmt_ms, TreeStats};
pub use trace::{trace_ray, NodeId, Step, StepKind, Trace, TraceLevel};
pub use tree::{NodeKind, NodeView, TreeView};
pub use two_level::TwoLevelBvh;
pub use wide::WideBvh;
