//! Bounding volume hierarchies: the flat node array, the top-down builder with one file per split
//! strategy, ordered traversal generic over a statistics sink, tree statistics, and the linear scan
//! every BVH is checked against.

mod accel;
mod any;
pub mod builders;
mod counters;
pub mod epo;
mod hierarchy;
pub mod imported;
mod linear;
mod node;
pub mod packet;
pub mod params;
mod preset;
pub mod reach;
mod scene_bvh;
mod stack;
mod stats;
pub mod trace;
pub(crate) mod traverse;
pub mod tree;
pub mod two_level;
pub mod wide;

pub use accel::{Accelerator, Hit, TraceOptions, TraversalOrder};
pub use any::AnyBvh;
pub use builders::strategy::Builder;
pub use builders::{lbvh, morton, reinsert, sbvh, split};
pub use counters::{NoStats, NodeId, RayCounters, TraversalStats};
pub use hierarchy::Hierarchy;
pub use linear::LinearScan;
pub use node::{Bvh, BvhNode, TRAVERSAL_STACK_SIZE};
pub use params::{BuildParams, BuildReport, Layout, Limits, Param, ParamLimits, ParamValue, SahCost, Strategy};
pub use preset::Preset;
pub use scene_bvh::{SceneBuild, SceneBvh};
pub use stats::{fmt_ms, TreeStats};
pub use trace::{trace_query_into, trace_ray, StepKind, StepOut, Trace, TraceLevel, TraceStep};
pub use tree::{NodeKind, TreeNode, TreeView};
pub use two_level::TwoLevelBvh;
pub use wide::WideBvh;
