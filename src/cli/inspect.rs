//! `bvhscope inspect MESH --node N`: one node of the binary tree as built, explained (the app's
//! node inspector): its figures, its children, and per axis the SAH cost of splitting its
//! triangles at every candidate plane with each strategy's choice marked (`explain::inspect`).

use super::args::{BuildArgs, ViewArgs};
use crate::bvh::wide::wide_group_in;
use crate::bvh::{Hierarchy, SceneBvh, TreeView};
use crate::cli::error::CliError;
use crate::cli::load::{build_scene, load_mesh};
use crate::explain::inspect::text::{dump_text, no_split_text, sbvh_text, wide_group_text};
use crate::explain::inspect::{inspect, CurvePoint, Inspection};
use crate::options::{Choice, Named};
use clap::Args;
use std::fmt::Write;
use std::path::PathBuf;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum InspectFormat {
    Text,
    Json,
    /// The exact sweep's curves: `axis,position,left_count,right_count,cost`.
    Csv,
}

const INSPECT_FORMATS: [Named<InspectFormat>; 3] = [
    Named { value: InspectFormat::Text, name: "text", label: "Text", help: "plain text, to read" },
    Named { value: InspectFormat::Json, name: "json", label: "JSON", help: "one JSON document, for scripts" },
    Named {
        value: InspectFormat::Csv,
        name: "csv",
        label: "CSV",
        help: "the exact sweep's curves: axis,position,left_count,right_count,cost",
    },
];
bvhscope_core::choice!(InspectFormat, INSPECT_FORMATS, 3);

#[derive(Args, Debug)]
pub struct InspectArgs {
    #[arg(help = crate::cli::args::MESH_HELP)]
    pub mesh: PathBuf,
    /// The node: its id in the binary tree as built (0 is the root; the app's tree view shows
    /// the same ids); with --bvh, the dump's own id of the node.
    #[arg(long, default_value_t = 0)]
    pub node: u32,
    /// Explain a node of a BVH written by another program (bvhscope-bvh, as `check` reads it)
    /// instead of a build; a 4-wide dump is binarised as the app's tree view shows it.
    #[arg(long, value_name = "DUMP")]
    pub bvh: Option<PathBuf>,
    #[command(flatten)]
    pub dump_limit: super::args::DumpLimit,
    #[command(flatten)]
    pub build: BuildArgs,
    /// The frame whose primary rays are counted per node (the Tree window's visits; camera and
    /// size as `render` takes them).
    #[command(flatten)]
    pub view_args: ViewArgs,
    #[arg(long, value_parser = crate::cli::args::choice::<InspectFormat>(), default_value = "text")]
    pub format: InspectFormat,
}

const AXES: [&str; 3] = ["x", "y", "z"];

/// A split's cost term by term, as JSON fields.
fn terms_json(t: &crate::explain::inspect::CostTerms) -> serde_json::Value {
    serde_json::json!({ "left_count": t.left, "right_count": t.right, "area_left_ratio": t.area_left,
        "area_right_ratio": t.area_right, "traversal_term": t.traversal, "left_term": t.left_term,
        "right_term": t.right_term, "cost": t.cost })
}

fn points_json(points: &[CurvePoint], sah: crate::bvh::SahCost) -> serde_json::Value {
    points
        .iter()
        .map(|p| {
            let mut v = terms_json(&p.terms(sah));
            v["position"] = p.position.into();
            v
        })
        .collect()
}

fn json(ins: &Inspection, path: &[u32]) -> serde_json::Value {
    let curves: serde_json::Map<String, serde_json::Value> = (0..3)
        .map(|a| {
            let v = serde_json::json!({ "sweep": points_json(&ins.sweep[a], ins.sah),
                "binned": points_json(&ins.binned[a], ins.sah), "spatial": points_json(&ins.spatial[a], ins.sah) });
            (AXES[a].to_string(), v)
        })
        .collect();
    let markers: serde_json::Map<String, serde_json::Value> = ins
        .markers
        .iter()
        .map(|(s, m)| {
            let v = m.map_or(serde_json::Value::Null, |m| {
                let mut v = terms_json(&m.terms(ins.sah));
                v["axis"] = AXES[m.axis as usize].into();
                v["position"] = m.position.into();
                v
            });
            (s.named().name.to_string(), v)
        })
        .collect();
    let b = |v: glam::Vec3A| v.to_array();
    serde_json::json!({
        "node": ins.node, "depth": ins.depth, "parent": ins.parent, "path": path, "children": ins.children,
        "split_axis": ins.split_axis.map(|a| AXES[a as usize]),
        "triangles": ins.triangles,
        "bounds": { "min": b(ins.bounds.min), "max": b(ins.bounds.max) },
        "centroid_bounds": { "min": b(ins.centroid_bounds.min), "max": b(ins.centroid_bounds.max) },
        "area": ins.area, "area_ratio_to_parent": ins.area_ratio, "subtree_sah_cost": ins.subtree_sah,
        "child_overlap": ins.child_overlap, "leaf_cost": ins.leaf_cost, "epo_contribution": ins.epo_share,
        "bins": ins.bins, "curves": curves, "markers": markers, "own_cost": ins.own_cost,
        "sbvh": ins.sbvh.map(|e| serde_json::json!({
            "split": e.split.map(|s| s.kind), "overlap_ratio": e.overlap_ratio,
            "spatial_priced": e.spatial_priced, "budget": e.budget, "over_budget": e.over_budget,
        })),
    })
}

/// The node's figures and each strategy's choice, as a human-readable block.
pub fn text(ins: &Inspection, path: &[u32]) -> String {
    let mut o = String::new();
    let crumbs = path.iter().map(|n| n.to_string()).collect::<Vec<_>>().join(" > ");
    let _ = writeln!(o, "node            {} (depth {}; path {crumbs})", ins.node, ins.depth);
    match (ins.children, ins.split_axis) {
        (Some([l, r]), Some(a)) => {
            let _ = writeln!(o, "children        {l} and {r}, split on {}", AXES[a as usize]);
        }
        _ => {
            let _ = writeln!(o, "leaf");
        }
    }
    let _ = writeln!(o, "triangles       {}", ins.triangles);
    let (lo, hi) = (ins.bounds.min, ins.bounds.max);
    let _ = writeln!(o, "box             ({}, {}, {}) .. ({}, {}, {})", lo.x, lo.y, lo.z, hi.x, hi.y, hi.z);
    let ratio = ins.area_ratio.map_or(String::new(), |r| format!(", {:.1}% of its parent's", 100.0 * r));
    let _ = writeln!(o, "surface area    {:.6}{ratio}", ins.area);
    let _ = writeln!(o, "subtree SAH     {:.3} (relative to this node's area)", ins.subtree_sah);
    if let Some(ov) = ins.child_overlap {
        let _ = writeln!(o, "child overlap   volume {:.6}, area {:.6}", ov.volume, ov.area);
    }
    let _ = writeln!(o, "EPO share       {:.4} (this node's term of the tree's end-point overlap)", ins.epo_share);
    let _ = writeln!(o, "as a leaf       cost {:.3} (C_isect x triangles)", ins.leaf_cost);
    let _ = writeln!(o);
    let _ = writeln!(o, "where each strategy splits these triangles (cost C_trav + C_isect (A_L n_L + A_R n_R) / A):");
    for (s, m) in &ins.markers {
        match m {
            Some(m) => {
                let _ = writeln!(
                    o,
                    "  {:<12}  {} = {:<12}  {:>6} | {:<6}  cost {:.3}",
                    s.named().name,
                    AXES[m.axis as usize],
                    m.position,
                    m.left,
                    m.right,
                    m.cost
                );
                let _ = writeln!(o, "  {:<12}  {}", "", m.terms(ins.sah).text());
            }
            None => {
                let _ = writeln!(o, "  {:<12}  {}", s.named().name, no_split_text(*s));
            }
        }
    }
    if let Some(c) = ins.own_cost {
        let _ = writeln!(
            o,
            "  {:<12}  the split this tree made: cost {c:.3} (its children's boxes as stored)",
            "this tree"
        );
    }
    if let Some(line) = sbvh_text(ins) {
        let _ = writeln!(o, "{line}");
    }
    let _ = writeln!(o);
    let min = |c: &[CurvePoint]| c.iter().min_by(|p, q| p.cost.total_cmp(&q.cost)).copied();
    let show = |p: Option<CurvePoint>| p.map_or("-".to_string(), |p| format!("{:.3} at {}", p.cost, p.position));
    for (a, axis) in AXES.iter().enumerate() {
        let (sweep, binned, spatial) = (&ins.sweep[a], &ins.binned[a], &ins.spatial[a]);
        let cuts = if spatial.is_empty() {
            String::new()
        } else {
            format!("; {} spatial planes, cheapest {}", spatial.len(), show(min(spatial)))
        };
        let _ = writeln!(
            o,
            "axis {axis}          {} candidate planes, cheapest {}; {} bins' planes, cheapest {}{cuts}",
            sweep.len(),
            show(min(sweep)),
            binned.len(),
            show(min(binned))
        );
    }
    o
}

/// The exact sweep's curves as CSV.
pub fn csv(ins: &Inspection) -> String {
    let mut w = csv::Writer::from_writer(Vec::new());
    let _ = w.write_record([
        "axis",
        "position",
        "left_count",
        "right_count",
        "area_left_ratio",
        "area_right_ratio",
        "left_term",
        "right_term",
        "cost",
    ]);
    for (a, points) in ins.sweep.iter().enumerate() {
        for p in points {
            let t = p.terms(ins.sah);
            let _ = w.write_record([
                AXES[a].to_string(),
                p.position.to_string(),
                p.left.to_string(),
                p.right.to_string(),
                t.area_left.to_string(),
                t.area_right.to_string(),
                t.left_term.to_string(),
                t.right_term.to_string(),
                p.cost.to_string(),
            ]);
        }
    }
    String::from_utf8(w.into_inner().expect("writing to memory")).expect("CSV of numbers is UTF-8")
}

pub fn run(a: &InspectArgs) -> Result<(), CliError> {
    super::out(&output(a)?);
    Ok(())
}

/// What `run` prints.
pub fn output(a: &InspectArgs) -> Result<String, CliError> {
    if a.build.two_level {
        return Err(CliError::Usage(
            "inspect explains a node of one BVH; leave out --two-level (a scene is then flattened)".into(),
        ));
    }
    let scene = load_mesh(&a.mesh)?;
    let params = a.build.params(scene.build.as_ref());
    let built = match &a.bvh {
        Some(path) => a.dump_limit.import(&scene, path)?,
        None => build_scene(None, &scene, &a.build.scene_build(params))?.0,
    };
    let SceneBvh::Single { bvh, .. } = &built else { unreachable!("one level was asked for") };
    let tree = built.binary_tree().expect("a single BVH has a binary tree");
    let h = Hierarchy::of(&tree);
    // An imported tree's node by the dump's id.
    let names = built.import();
    let node = match names {
        Some(n) if a.node as usize >= n.dump_nodes => {
            let last = n.dump_nodes.saturating_sub(1);
            return Err(CliError::Usage(format!(
                "--node {}: the dump has {} nodes (0 to {last})",
                a.node, n.dump_nodes
            )));
        }
        Some(n) => n.binary_node_of_dump(a.node).ok_or_else(|| {
            CliError::Usage(format!(
                "--node {}: the dump's node {} is not reached from its root (or is an empty leaf, which no ray enters)",
                a.node, a.node
            ))
        })?,
        None => a.node,
    };
    let Some(ins) = inspect(&tree, &h, node) else {
        return Err(CliError::Usage(format!(
            "--node {}: the tree has {} nodes (0 to {})",
            a.node,
            tree.nodes.len(),
            tree.nodes.len() - 1
        )));
    };
    let path = h.path(node);
    // The visits of the frame's primary rays, through the binary tree (as the Tree window counts).
    let camera = a.view_args.camera(&scene.bounds(), scene.camera.as_ref())?;
    let visits =
        crate::explain::visits::frame_visits(&tree, &camera, a.build.trace_options(), &crate::work::WorkControl::new())
            .map_err(|_| CliError::Usage("cancelled".into()))?
            .counts[node as usize];
    // A built wide tree is collapsed from the binary one; an imported one is not.
    let wide = names.is_none().then(|| wide_group_in(bvh.params().layout, &tree.nodes, &h, node)).flatten();
    let dump_id = names.map(|n| n.dump_of_binary_node(node));
    Ok(match a.format {
        InspectFormat::Csv => csv(&ins),
        InspectFormat::Json => {
            let mut v = json(&ins, &path);
            v["visits"] = serde_json::json!(visits);
            v["camera"] = serde_json::json!(camera);
            if let Some(d) = dump_id {
                v["dump_node"] = serde_json::json!(d);
            }
            if let Some(g) = &wide {
                v["wide_node"] = serde_json::json!({ "width": g.width, "top": g.top, "collapsed": g.collapsed, "children": g.children });
            }
            format!("{}\n", serde_json::to_string_pretty(&v).expect("plain data serialises"))
        }
        InspectFormat::Text => {
            let p = bvh.params();
            let build = match names {
                Some(n) => format!("{} (dump node {})", n.label(), dump_text(dump_id.flatten())),
                None => {
                    format!("{}, max leaf size {}, {} SAH bins", p.strategy.label(), p.max_leaf_size, p.sah_bins)
                }
            };
            let wide = wide.map_or(String::new(), |g| format!("\n{}\n", wide_group_text(node, &g)));
            let visits = format!(
                "visits          {visits} of the {}x{} frame's primary rays entered it (binary traversal)\n",
                camera.width, camera.height
            );
            format!("build           {build} (the binary tree)\n{}{visits}{wide}", text(&ins, &path))
        }
    })
}
