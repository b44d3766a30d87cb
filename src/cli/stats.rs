//! `bvhscope stats`: the statistics of one BVH.

use super::args::BuildArgs;
use super::{load_mesh, progress, CliError};
use crate::bvh::{AnyBvh, TreeStats};
use clap::{Args, ValueEnum};
use std::fmt::Write;
use std::path::PathBuf;

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum StatsFormat {
    Text,
    Json,
}

#[derive(Args, Debug)]
pub struct StatsArgs {
    /// The mesh (.obj) or scene (.json: bvhscope's or Moer-lite's).
    pub mesh: PathBuf,
    #[command(flatten)]
    pub build: BuildArgs,
    #[arg(long, value_enum, default_value = "text")]
    pub format: StatsFormat,
}

pub fn run(a: &StatsArgs) -> Result<(), CliError> {
    let loaded = load_mesh(&a.mesh)?;
    let (mesh, report) = (loaded.mesh, loaded.report);
    let params = a.build.params(a.build.strategy);
    let bvh = progress::with_spinner("building the BVH", || AnyBvh::build(&mesh, &params));
    let s = TreeStats::of(&bvh);
    match a.format {
        StatsFormat::Json => {
            let v = serde_json::json!({ "mesh": report, "params": params, "stats": s });
            println!("{}", serde_json::to_string_pretty(&v).expect("plain data serialises"));
        }
        StatsFormat::Text => print!("{}", format_text(&report, &params, &s)),
    }
    Ok(())
}

/// The statistics as a human-readable block.
pub fn format_text(report: &crate::mesh::LoadReport, params: &crate::bvh::BuildParams, s: &TreeStats) -> String {
    let mut o = String::new();
    let _ = writeln!(o, "mesh            {}", report.path.display());
    let _ = writeln!(
        o,
        "triangles       {} ({} degenerate skipped), {} vertices, {} groups",
        report.triangles, report.degenerate_skipped, report.vertices, report.groups
    );
    let _ = writeln!(
        o,
        "strategy        {}, {} layout (max leaf size {}, {} SAH bins)",
        params.strategy.label(),
        params.layout.label(),
        params.max_leaf_size,
        params.sah_bins
    );
    let _ = writeln!(
        o,
        "build           {:.2} ms (setup {:.2}, split {:.2}, reorder {:.2})",
        s.build_total_ms, s.build_setup_ms, s.build_split_ms, s.build_reorder_ms
    );
    let _ = writeln!(o, "nodes           {} ({} interior, {} leaves)", s.nodes, s.interior_nodes, s.leaves);
    let _ = writeln!(o, "depth           max {}, mean leaf depth {:.2}", s.max_depth, s.mean_leaf_depth);
    let _ = writeln!(
        o,
        "SAH cost        {:.3} (C_trav = {}, C_isect = {}, normalised by root area)",
        s.sah_cost, s.sah_constants.traversal, s.sah_constants.intersection
    );
    let _ = writeln!(
        o,
        "memory          {} bytes ({:.1} per triangle, nodes + indices)",
        s.memory_bytes,
        s.memory_bytes as f64 / s.triangles.max(1) as f64
    );
    if s.fallback_splits > 0 || s.depth_limited_splits > 0 {
        let _ = writeln!(
            o,
            "fallbacks       {} equal-count splits where the strategy found none, {} below the depth limit",
            s.fallback_splits, s.depth_limited_splits
        );
    }
    let _ = writeln!(o, "leaf sizes      (triangles: leaves)");
    let most = s.leaf_size_histogram.iter().copied().max().unwrap_or(1).max(1);
    for (k, &n) in s.leaf_size_histogram.iter().enumerate().filter(|(_, &n)| n > 0) {
        let bar = "#".repeat((n * 40).div_ceil(most));
        let _ = writeln!(o, "  {k:>3}: {n:>8}  {bar}");
    }
    o
}
