//! Bounding volume hierarchies: the flat node array, the top-down builder with one file per split
//! strategy, ordered traversal generic over a statistics sink, tree statistics, and the linear scan
//! every BVH is checked against.

mod accel;
mod any;
pub mod build;
mod counters;
pub mod epo;
pub mod imported;
pub mod inspect;
mod linear;
mod node;
pub mod packet;
mod params;
mod preset;
pub mod replay;
mod scene_bvh;
mod simd;
mod stack;
mod stats;
pub mod trace;
mod traverse;
pub mod tree;
pub mod two_level;
pub mod visits;
pub mod wide;

pub use accel::{Accelerator, Hit, TraceOptions, TraversalOrder};
pub use any::AnyBvh;
pub use build::{lbvh, morton, reinsert, sbvh, split};
pub use counters::{NoStats, RayCounters, TraversalStats};
pub use linear::LinearScan;
pub use node::{Bvh, BvhNode, TRAVERSAL_STACK_SIZE};
pub use params::{BuildParams, BuildReport, Layout, SahCost};
pub use preset::Preset;
pub use scene_bvh::{SceneBuild, SceneBvh};
pub use split::SplitStrategy;
pub use stats::{fmt_ms, TreeStats};
pub use trace::{trace_ray, NodeId, Step, StepKind, Trace, TraceLevel};
pub use tree::{NodeKind, NodeView, TreeView};
pub use two_level::TwoLevelBvh;
pub use wide::WideBvh;
