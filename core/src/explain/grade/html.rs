//! `grade.html`: one self-contained page (no network: style, script and images inline, the
//! images as base64 PNG) that a teacher can send. At the top how the class was graded and
//! bvhscope's reference trees, then the class table (sortable), then a section per student: the
//! verdict and its first cause, the figures, the leaf sizes, the heatmap of their tree and its
//! difference from the SAH tree, and every finding with its node and triangle numbers.
//!
//! Written as a stream, one student at a time, each image read back from the report folder as
//! it is written out: the page's size does not become the program's memory.

use super::measure::Quality;
use super::page::{SCRIPT, STYLE};
use super::{GradeRow, Graded, ReportDir, Setup, Verdict, HTML_FILE};
use crate::files::FileError;
use crate::render::legend::fmt_value;
use std::fmt::Write as _;
use std::io::Write;

/// An image larger than this is left out of the page (the report's are some 100 kB).
const MAX_IMAGE: u64 = 64 << 20;

/// Write the page into the report folder.
pub fn write_html(setup: &Setup, graded: &Graded, out: &ReportDir) -> Result<(), FileError> {
    let path = out.path_while_written(HTML_FILE);
    let werr = |source| FileError::Write { path: path.clone(), source };
    crate::files::write_atomically(&path, |w| {
        w.write_all(head(setup, graded).as_bytes()).map_err(werr)?;
        w.write_all(class_table(graded).as_bytes()).map_err(werr)?;
        w.write_all(b"<h2>Students</h2>\n").map_err(werr)?;
        for row in &graded.rows {
            student(w, row, out).map_err(werr)?;
        }
        write!(w, "<script>{SCRIPT}</script>\n</body>\n</html>\n").map_err(werr)
    })
}

/// Text made safe in HTML text and attribute values.
pub fn esc(s: &str) -> String {
    let mut o = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => o.push_str("&amp;"),
            '<' => o.push_str("&lt;"),
            '>' => o.push_str("&gt;"),
            '"' => o.push_str("&quot;"),
            '\'' => o.push_str("&#39;"),
            c => o.push(c),
        }
    }
    o
}

/// Standard base64 (RFC 4648, with padding), for the inline images.
pub fn base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut o = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for c in bytes.chunks(3) {
        let n = (c[0] as u32) << 16 | (*c.get(1).unwrap_or(&0) as u32) << 8 | *c.get(2).unwrap_or(&0) as u32;
        for k in 0..4 {
            if k <= c.len() {
                o.push(A[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                o.push('=');
            }
        }
    }
    o
}

fn num(v: f64, digits: usize) -> String {
    if v.is_finite() {
        format!("{v:.digits$}")
    } else {
        "–".into()
    }
}

fn bytes_text(b: usize) -> String {
    if b >= 1 << 20 {
        format!("{:.1} MB", b as f64 / (1 << 20) as f64)
    } else {
        format!("{:.1} kB", b as f64 / 1024.0)
    }
}

fn head(setup: &Setup, graded: &Graded) -> String {
    let c = &setup.camera;
    let t = &graded.references.timing;
    let mesh = esc(&setup.given_path.display().to_string());
    let mut o = format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>BVH grades: {mesh}</title>\n<style>{STYLE}</style>\n</head>\n<body>\n<h1>BVH grades: {mesh}</h1>\n"
    );
    let v = |v: glam::Vec3| format!("{}, {}, {}", fmt_value(v.x as f64), fmt_value(v.y as f64), fmt_value(v.z as f64));
    let _ = writeln!(
        o,
        "<p class=\"setup\">{} triangles. Camera {}×{} from ({}) towards ({}), vertical field of view {}°. Each submission is checked on the camera's {} primary rays and {} random rays against the linear scan; traversal {}, {} triangle test.</p>",
        setup.mesh.triangle_count(),
        c.width,
        c.height,
        v(c.position),
        v(c.look_at),
        fmt_value(c.vfov_deg as f64),
        c.width as u64 * c.height as u64,
        setup.rays,
        esc(setup.trace.order.label()),
        esc(setup.trace.test.label())
    );
    let _ = writeln!(
        o,
        "<p class=\"setup\">One yardstick for every tree: the SAH cost is normalised by the area of the mesh's box (what its triangles span), and the per-ray figures \"in the mesh's box\" are the work of every ray over the rays that enter that box, whatever each tree's own root box; a tree whose root box is larger (a degenerate triangle kept, a loose box) is told by how much and why among its findings.</p>\n<p class=\"setup\">Trace time: {} primary rays spread over the frame, traced one at a time on one thread, closest hit, no shading. Each tree is timed in the same rounds as bvhscope's SAH tree of its layout, {} rays at a time, the trees taking turns, the fastest of {} runs of each kept: its time relative to the SAH tree's is what a busy machine leaves alone, and its speed-up over the linear scan is the SAH tree's (the linear scan timed on {} of the rays: {} µs per ray) over that ratio.</p>",
        t.rays,
        super::measure::PIECE,
        t.runs,
        t.linear_rays,
        num(t.linear_ns_per_ray / 1e3, 1)
    );
    if let Some(s) = &setup.secondary {
        let _ = writeln!(
            o,
            "<p class=\"setup\">Heatmaps: nodes visited per ray of the {} from each pixel's hit (the mean of a pixel's rays; grey where the camera ray missed). The figures and the ranks are of the camera's rays.</p>",
            esc(&s.spec.describe())
        );
    }
    let _ = writeln!(
        o,
        "<p class=\"setup\"><b>Ranked by</b> {} (correct submissions only).",
        esc(setup.rubric.rank_by.describe())
    );
    let good = setup.rubric.to_json();
    let good = good.get("good").map(|g| g.to_string()).unwrap_or_default();
    let rubric_from =
        setup.rubric.file.as_ref().map_or("the default rubric".to_string(), |p| format!("rubric {}", p.display()));
    let _ = writeln!(o, " <b>Good</b>: {} ({}).</p>", esc(&good), esc(&rubric_from));
    let pretty = serde_json::to_string_pretty(&setup.rubric.to_json()).unwrap_or_default();
    let _ = writeln!(o, "<details><summary>The rubric used</summary><pre>{}</pre></details>", esc(&pretty));
    o += "<h2>bvhscope's reference trees</h2>\n<table>\n<thead><tr><th>tree</th><th class=\"n\">SAH cost</th><th class=\"n\">EPO</th><th class=\"n\">nodes / ray</th><th class=\"n\">tri tests / ray</th><th class=\"n\">ns / ray</th><th class=\"n\">speed-up</th><th class=\"n\">memory</th><th class=\"n\">nodes</th><th class=\"n\">depth</th></tr></thead>\n<tbody>\n";
    for r in graded.references.trees() {
        let q = &r.quality;
        let _ = writeln!(
            o,
            "<tr><td>{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td class=\"n\">{}×</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td class=\"n\">{}</td></tr>",
            esc(&r.name),
            num(q.sah_cost, 2),
            q.epo.map_or("–".into(), |e| num(e, 3)),
            num(q.nodes_per_ray, 2),
            num(q.tri_tests_per_ray, 2),
            num(q.trace_ns_per_ray, 0),
            num(q.speedup_over_linear, 0),
            bytes_text(q.memory_bytes),
            q.nodes,
            q.max_depth
        );
    }
    o += "</tbody>\n</table>\n";
    o
}

fn badge(v: Verdict) -> String {
    let class = match v {
        Verdict::Correct => "correct",
        Verdict::Defects => "defects",
        Verdict::WrongMesh => "wrong_mesh",
        Verdict::Unreadable => "unreadable",
        Verdict::NoDump => "no_dump",
        Verdict::TimedOut => "timed_out",
    };
    format!("<span class=\"badge {class}\">{}</span>", v.label())
}

fn short(s: &str, n: usize) -> String {
    if s.chars().count() <= n {
        s.to_string()
    } else {
        format!("{}…", s.chars().take(n).collect::<String>())
    }
}

fn class_table(graded: &Graded) -> String {
    let rows = &graded.rows;
    let count = |v: Verdict| rows.iter().filter(|r| r.verdict == v).count();
    let mut o = format!(
        "<h2>Class</h2>\n<p class=\"setup\">{} submissions: {} correct, {} with defects, {} for the wrong mesh, {} unreadable, {} without a dump, {} timed out; graded in {:.1} s. Click a heading to sort.</p>\n",
        rows.len(),
        count(Verdict::Correct),
        count(Verdict::Defects),
        count(Verdict::WrongMesh),
        count(Verdict::Unreadable),
        count(Verdict::NoDump),
        count(Verdict::TimedOut),
        graded.seconds
    );
    o += "<table id=\"class\">\n<thead><tr><th class=\"n\">rank</th><th>student</th><th>verdict</th><th>good</th><th class=\"n\">SAH cost</th><th class=\"n\">vs SAH tree</th><th class=\"n\">EPO</th><th class=\"n\">nodes / ray</th><th class=\"n\">tri tests / ray</th><th class=\"n\">ns / ray</th><th class=\"n\">speed-up</th><th class=\"n\">memory</th><th class=\"n\">depth</th><th>first cause</th></tr></thead>\n<tbody>\n";
    for r in rows {
        let q = r.quality.as_ref();
        let cell = |v: Option<f64>, shown: String| match v.filter(|v| v.is_finite()) {
            Some(v) => format!("<td class=\"n\" data-v=\"{v}\">{shown}</td>"),
            None => "<td class=\"n\" data-v=\"\">–</td>".into(),
        };
        let rank = r.rank.map_or("<td class=\"n\" data-v=\"\">–</td>".into(), |k| {
            format!("<td class=\"n\" data-v=\"{k}\">{k}</td>")
        });
        let good = match r.good {
            Some(true) => "<td data-v=\"1\" class=\"good\">good</td>".to_string(),
            Some(false) => {
                format!("<td data-v=\"0\" class=\"notgood\" title=\"{}\">not yet</td>", esc(&r.misses.join("; ")))
            }
            None => "<td data-v=\"\"></td>".into(),
        };
        let vs = r.versus_sah.map(|v| v.sah_cost);
        let _ = writeln!(
            o,
            "<tr>{rank}<td class=\"name\" data-v=\"{name}\"><a href=\"#s-{slug}\">{name}</a></td><td data-v=\"{verdict}\">{badge}</td>{good}{}{}{}{}{}{}{}{}{}<td class=\"reason\" title=\"{reason}\">{reason_short}</td></tr>",
            cell(q.map(|q| q.sah_cost), q.map_or(String::new(), |q| num(q.sah_cost, 2))),
            cell(vs, vs.map_or(String::new(), |v| format!("{:+.1} %", (v - 1.0) * 100.0))),
            cell(q.and_then(|q| q.epo), q.and_then(|q| q.epo).map_or(String::new(), |e| num(e, 3))),
            cell(q.map(|q| q.nodes_per_ray), q.map_or(String::new(), |q| num(q.nodes_per_ray, 2))),
            cell(q.map(|q| q.tri_tests_per_ray), q.map_or(String::new(), |q| num(q.tri_tests_per_ray, 2))),
            cell(q.map(|q| q.trace_ns_per_ray), q.map_or(String::new(), |q| num(q.trace_ns_per_ray, 0))),
            cell(q.map(|q| q.speedup_over_linear), q.map_or(String::new(), |q| format!("{}×", num(q.speedup_over_linear, 0)))),
            cell(q.map(|q| q.memory_bytes as f64), q.map_or(String::new(), |q| bytes_text(q.memory_bytes))),
            cell(q.map(|q| q.max_depth as f64), q.map_or(String::new(), |q| q.max_depth.to_string())),
            name = esc(&r.name),
            slug = esc(&r.slug),
            verdict = r.verdict.label(),
            badge = badge(r.verdict),
            reason = esc(&r.reason),
            reason_short = esc(&short(&r.reason, 160)),
        );
    }
    o += "</tbody>\n</table>\n";
    o
}

fn figures(q: &Quality, row: &GradeRow) -> String {
    let mut o = String::from("<div class=\"figures\">");
    let mut f = |label: &str, value: String| {
        let _ = write!(o, "<div><span>{label}</span> {}</div>", esc(&value));
    };
    f("layout", q.layout.into());
    f("SAH cost", num(q.sah_cost, 2));
    if let Some(v) = row.versus_sah {
        f("vs SAH tree", format!("{:+.1} %", (v.sah_cost - 1.0) * 100.0));
    }
    f("EPO", q.epo.map_or_else(|| q.epo_skipped.clone().unwrap_or_default(), |e| num(e, 3)));
    f("nodes / ray", format!("{} (in the mesh's box {})", num(q.nodes_per_ray, 2), num(q.root_nodes_per_ray, 2)));
    f(
        "tri tests / ray",
        format!("{} (in the mesh's box {})", num(q.tri_tests_per_ray, 2), num(q.root_tri_tests_per_ray, 2)),
    );
    f("trace", format!("{} ns / ray", num(q.trace_ns_per_ray, 0)));
    f("speed-up over linear", format!("{}×", num(q.speedup_over_linear, 0)));
    f("memory", bytes_text(q.memory_bytes));
    f("nodes", format!("{} ({} leaves)", q.nodes, q.leaves));
    f("depth", format!("{} (mean leaf {:.1})", q.max_depth, q.mean_leaf_depth));
    o += "</div>\n";
    o
}

/// The leaf sizes as bars: the sizes that occur, the first 15, then the rest together.
fn histogram(h: &[usize]) -> String {
    let sizes: Vec<(usize, usize)> = h.iter().copied().enumerate().filter(|&(_, c)| c > 0).collect();
    let mut shown: Vec<(String, usize)> = sizes.iter().take(15).map(|&(k, c)| (k.to_string(), c)).collect();
    if sizes.len() > 15 {
        let rest: usize = sizes[15..].iter().map(|&(_, c)| c).sum();
        shown.push((format!("{}–{}", sizes[15].0, sizes[sizes.len() - 1].0), rest));
    }
    let top = shown.iter().map(|s| s.1).max().unwrap_or(1).max(1);
    let mut o = String::from("<details><summary>Leaf sizes (triangles per leaf: leaves)</summary><div class=\"hist\">");
    for (label, c) in shown {
        let w = (c as f64 / top as f64 * 100.0).max(0.5);
        let _ = write!(o, "<span>{label}</span><div class=\"bar\" style=\"width:{w:.1}%\"></div><span>{c}</span>");
    }
    o += "</div></details>\n";
    o
}

fn student(w: &mut impl Write, row: &GradeRow, out: &ReportDir) -> std::io::Result<()> {
    let mut o = format!("<section class=\"student\" id=\"s-{}\">\n<h3>{} ", esc(&row.slug), esc(&row.name));
    o += &badge(row.verdict);
    if let Some(k) = row.rank {
        let _ = write!(o, " <span class=\"badge correct\">rank {k} of the class</span>");
    }
    match row.good {
        Some(true) => o += " <span class=\"good\">good</span>",
        Some(false) => o += " <span class=\"notgood\">not yet good</span>",
        None => {}
    }
    o += "</h3>\n";
    let file = row.dump.as_ref().unwrap_or(&row.submission);
    let _ = writeln!(o, "<div class=\"setup\">{}</div>", esc(&file.display().to_string()));
    if !row.reason.is_empty() {
        let _ = writeln!(o, "<p class=\"reason-line\"><b>First cause:</b> {}</p>", esc(&row.reason));
    }
    if !row.misses.is_empty() {
        let _ = writeln!(o, "<p class=\"reason-line\"><b>Not yet good:</b> {}</p>", esc(&row.misses.join("; ")));
    }
    if let Some(q) = &row.quality {
        o += &figures(q, row);
        o += &histogram(&q.leaf_sizes);
    }
    w.write_all(o.as_bytes())?;
    if let Some(img) = &row.images {
        // The key's colours from the difference image's own map: blue for less work, red for more.
        let key = |x: f32| {
            let [r, g, b] = crate::render::ColorMap::Diverging.map(x);
            format!("<span class=\"key\" style=\"background:#{r:02x}{g:02x}{b:02x}\"></span>")
        };
        let difference = format!(
            "This tree minus bvhscope's SAH tree, nodes visited per pixel: {} blue where it visits fewer, {} red where it visits more, white where they agree; the scale is ± the 99th percentile of this tree's differences (in the legend).",
            key(0.15),
            key(0.85)
        );
        w.write_all(b"<div class=\"images\">\n")?;
        for (rel, caption, alt) in [
            (
                &img.visits,
                "Nodes visited per pixel by this tree (bright: more), on the class's scale for its layout.",
                "nodes visited per pixel",
            ),
            (&img.difference, difference.as_str(), "nodes visited per pixel, this tree minus the SAH tree"),
        ] {
            match out.read_image(rel, MAX_IMAGE) {
                Some(bytes) => {
                    write!(w, "<figure><img alt=\"{}: {alt}\" src=\"data:image/png;base64,", esc(&row.name))?;
                    // In slices, so the encoded text never holds more than a few kB besides the image.
                    for part in bytes.chunks(3 * 4096) {
                        w.write_all(base64(part).as_bytes())?;
                    }
                    writeln!(w, "\"><figcaption>{caption}</figcaption></figure>")?;
                }
                None => writeln!(w, "<p>(image {} missing)</p>", esc(rel))?,
            }
        }
        w.write_all(b"</div>\n")?;
    }
    let mut o = String::new();
    if !row.findings.is_empty() {
        o += "<table class=\"findings\"><thead><tr><th>check</th><th>finding</th><th class=\"n\">node</th><th class=\"n\">triangle</th><th>what</th></tr></thead><tbody>\n";
        for f in &row.findings {
            let (class, kind) = match (f.defect, f.required) {
                (true, true) => ("defect", "defect"),
                (true, false) => ("waived", "defect (not required)"),
                (false, _) => ("warning", "warning"),
            };
            let _ = writeln!(
                o,
                "<tr><td>{}</td><td class=\"{class}\">{kind}</td><td class=\"n\">{}</td><td class=\"n\">{}</td><td>{}</td></tr>",
                f.group.label(),
                f.node.map_or(String::new(), |n| n.to_string()),
                f.triangle.map_or(String::new(), |t| t.to_string()),
                esc(&f.line)
            );
        }
        o += "</tbody></table>\n";
        if row.findings_total > row.findings.len() {
            let _ = writeln!(
                o,
                "<p class=\"setup\">… {} more findings (the first twelve of each check are listed; <code>bvhscope check MESH --bvh FILE --all</code> lists every one).</p>",
                row.findings_total - row.findings.len()
            );
        }
    } else if row.verdict == Verdict::Correct {
        let _ = writeln!(o, "<p>No findings: {} rays hit what the linear scan hits.</p>", row.rays_checked);
    }
    for n in &row.notes {
        let _ = writeln!(o, "<p class=\"setup\">Note: {}</p>", esc(n));
    }
    o += "</section>\n";
    w.write_all(o.as_bytes())
}
