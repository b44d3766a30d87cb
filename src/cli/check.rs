//! `bvhscope check MESH --bvh FILE`: a BVH written by another program, checked against the mesh
//! and the linear scan (`explain::check`), then set next to bvhscope's strategies on the same mesh.
//! Exit 0: correct (warnings allowed); 1: defects; 2: the input cannot be read. (`export-bvh`,
//! which writes a built-in strategy's tree in that format, is `export_bvh.rs`.)

use super::args::{BuildArgs, DumpLimit, ViewArgs};
use super::progress;
use crate::bvh::{epo, AnyBvh, BuildParams, Strategy, TreeStats, TreeView};
use crate::cli::error::CliError;
use crate::cli::load::load_mesh;
use crate::dump::BvhDump;
use crate::explain::check::{check, Finding, Group, Subject, FINDINGS_LISTED, LISTED, MAX_RAYS};
use crate::options::Named;
use crate::render::{render, RenderSettings};
use clap::Args;
use std::fmt::Write;
use std::path::PathBuf;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CheckFormat {
    Text,
    Json,
}

const CHECK_FORMATS: [Named<CheckFormat>; 2] = [
    Named { value: CheckFormat::Text, name: "text", label: "Text", help: "plain text, to read" },
    Named { value: CheckFormat::Json, name: "json", label: "JSON", help: "one JSON document, for scripts" },
];
bvhscope_core::choice!(CheckFormat, CHECK_FORMATS, 2);

#[derive(Args, Debug)]
pub struct CheckArgs {
    #[arg(help = crate::cli::args::MESH_HELP)]
    pub mesh: PathBuf,
    /// The BVH: bvhscope-bvh JSON, .json.gz, or the text form (see the README), built over the
    /// mesh's triangles numbered as its file lists them (faces in file order).
    #[arg(long)]
    pub bvh: PathBuf,
    /// Random rays traced against the linear scan, besides the frame's primary rays and the rays
    /// aimed at every triangle's corners, edge midpoints and centre (at most 100,000,000; they
    /// are traced in batches, memory does not grow with their count).
    #[arg(long, default_value_t = 100_000, value_parser = clap::value_parser!(u64).range(0..=MAX_RAYS))]
    pub rays: u64,
    #[command(flatten)]
    pub dump_limit: DumpLimit,
    /// The frame whose primary rays are traced and counted.
    #[command(flatten)]
    pub view_args: ViewArgs,
    #[command(flatten)]
    pub build: BuildArgs,
    #[arg(long, value_parser = crate::cli::args::choice::<CheckFormat>(), default_value = "text")]
    pub format: CheckFormat,
    /// Leave out the quality table (it builds every strategy and measures each tree's EPO: most
    /// of the time on a big mesh).
    #[arg(long)]
    pub no_compare: bool,
    /// List every case of each finding (by default a finding lists its first few and how many
    /// there are in all).
    #[arg(long)]
    pub all: bool,
}

/// The frame checked unless `--size` says otherwise (the grader's).
pub const CHECK_SIZE: (u32, u32) = (480, 270);

/// A scene camera's size shrunk to fit 480x360, its shape kept (never enlarged).
pub fn fit((w, h): (u32, u32)) -> (u32, u32) {
    let s = (480.0 / w as f64).min(360.0 / h as f64).min(1.0);
    (((w as f64 * s).round() as u32).max(1), ((h as f64 * s).round() as u32).max(1))
}

/// One row of the quality table.
#[derive(serde::Serialize)]
struct QualityRow {
    name: String,
    nodes: usize,
    max_depth: u32,
    sah_cost: f64,
    /// Of binary trees (`bvh::epo` sums over a binary tree's nodes).
    epo: Option<f64>,
    nodes_per_ray: f64,
    tri_tests_per_ray: f64,
}

fn quality(
    name: String,
    bvh: &AnyBvh,
    mesh: &crate::mesh::Mesh,
    camera: &crate::render::Camera,
    trace: crate::bvh::TraceOptions,
) -> QualityRow {
    // Every row against the mesh's box, the imported tree's too (`TreeStats::against`).
    let s = TreeStats::against(bvh, &mesh.bounds());
    let f = render(bvh, mesh, camera, &RenderSettings { trace, count: true, progressive: false, secondary: None });
    let r = f.ray_summary();
    QualityRow {
        name,
        nodes: s.nodes,
        max_depth: s.max_depth,
        sah_cost: s.sah_cost,
        epo: match bvh {
            AnyBvh::Binary(b) => Some(epo::of(b)),
            AnyBvh::Wide(_) | AnyBvh::Wide8(_) => None,
        },
        nodes_per_ray: r.mean_nodes_visited,
        tri_tests_per_ray: r.mean_triangle_tests,
    }
}

pub fn run(a: &CheckArgs) -> Result<(), CliError> {
    let (o, defects) = output(a)?;
    super::out(&o);
    if defects > 0 {
        return Err(CliError::Defects(defects));
    }
    Ok(())
}

/// What `run` prints, and the number of defects (the app's tests compare it with the Imported BVH
/// window).
pub fn output(a: &CheckArgs) -> Result<(String, usize), CliError> {
    let scene = load_mesh(&a.mesh)?;
    let mesh = scene.flat_mesh().map_err(|e| CliError::Usage(format!("{}: {e}", a.mesh.display())))?;
    let dump = BvhDump::read(&a.bvh, a.dump_limit.bytes(&mesh)).map_err(|e| CliError::Usage(e.to_string()))?;
    // The frame's primary rays are checked one by one against the linear scan: a small frame
    // unless --size asks for more (a 1280x720 frame over the lab's monkey took seconds alone).
    let size = a.view_args.size.unwrap_or_else(|| scene.camera.map_or(CHECK_SIZE, |c| fit((c.width, c.height))));
    let view = super::args::ViewArgs { size: Some(size), ..a.view_args.clone() };
    let camera = view.camera(&scene.bounds(), scene.camera.as_ref())?;
    let trace = a.build.trace_options();
    let subject = Subject { dump: &dump, dump_path: &a.bvh, mesh: &mesh, mesh_path: &a.mesh };
    let control = crate::work::WorkControl::new();
    let checked =
        progress::with_bar("checking the BVH", &control, || check(&subject, &camera, a.rays, trace, &control))
            .map_err(|_| CliError::Usage("check cancelled".into()))?;
    let (findings, imported) = (checked.findings, checked.tree);
    let defects = findings.iter().filter(|f| f.defect).count();
    // The imported tree next to bvhscope's strategies, on the same mesh, frame and constants.
    let mut table = Vec::new();
    if let Some((t, names)) = imported.as_ref().filter(|_| !a.no_compare) {
        table.push(quality(names.label(), t, &mesh, &camera, trace));
        // bvhscope's trees in the imported one's layout.
        let layout = t.params().layout;
        for s in Strategy::ALL {
            let b = AnyBvh::build(&mesh, &BuildParams { strategy: s, layout, ..BuildParams::default() });
            table.push(quality(format!("{}, {}", s.label(), layout.name()), &b, &mesh, &camera, trace));
        }
    }
    let mut o = String::new();
    match a.format {
        CheckFormat::Json => {
            let v = serde_json::json!({
                "defects": defects,
                "findings": findings,
                "quality": table,
                "camera": camera,
                "wrong_pixels": checked.wrong_pixels,
            });
            let _ = writeln!(o, "{}", serde_json::to_string_pretty(&v).expect("plain data serialises"));
        }
        CheckFormat::Text => o = text(&a.bvh, &findings, &table, if a.all { usize::MAX } else { LISTED }),
    }
    Ok((o, defects))
}

fn text(path: &std::path::Path, findings: &[Finding], table: &[QualityRow], list: usize) -> String {
    let mut o = String::new();
    let defects = findings.iter().filter(|f| f.defect).count();
    let warnings = findings.len() - defects;
    let _ = writeln!(o, "{}: {defects} defects, {warnings} warnings", path.display());
    for g in Group::ALL {
        let here: Vec<&Finding> = findings.iter().filter(|f| f.group == g).collect();
        if here.is_empty() {
            continue;
        }
        let d = here.iter().filter(|f| f.defect).count();
        let _ = writeln!(o, "\n{} ({d} defects, {} warnings)", g.label(), here.len() - d);
        // A tree whose every box is wrong has a root cause per box: the first few say what is
        // wrong, `--all` lists every one.
        let shown = if list == usize::MAX { here.len() } else { FINDINGS_LISTED };
        for f in here.iter().take(shown) {
            let _ = writeln!(o, "  {} {}", if f.defect { "defect: " } else { "warning:" }, f.line(list));
        }
        if here.len() > shown {
            let _ = writeln!(o, "  … {} more in this group (--all lists every one)", here.len() - shown);
        }
    }
    if !table.is_empty() {
        let w = table.iter().map(|q| q.name.chars().count()).max().unwrap_or(4).max(4);
        let _ = writeln!(
            o,
            "\n{:<w$} {:>8} {:>6} {:>9} {:>7} {:>12} {:>15}",
            "tree", "nodes", "depth", "SAH cost", "EPO", "nodes / ray", "tri tests / ray"
        );
        for q in table {
            let _ = writeln!(
                o,
                "{:<w$} {:>8} {:>6} {:>9.2} {:>7} {:>12.2} {:>15.2}",
                q.name,
                q.nodes,
                q.max_depth,
                q.sah_cost,
                q.epo.map_or("–".into(), |e| format!("{e:.3}")),
                q.nodes_per_ray,
                q.tri_tests_per_ray
            );
        }
    }
    o
}
