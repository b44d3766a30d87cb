//! The CSV's header and records, one per student in the order given: what `grade.csv` holds.
//! The fields are plain text (numbers with fixed decimals, empty where nothing was measured);
//! the `csv` crate quotes them by RFC 4180 where the CLI writes them (the core has no CSV writer).
//! A text cell that a spreadsheet would take for a formula (a student's file named `=1+2.json`,
//! `@SUM(…)`) starts with a `'` (`text`, OWASP's "CSV injection"); the numbers are written as
//! they are, a negative one included.

use super::measure::leaf_sizes_text;
use super::GradeRow;

pub const HEADER: [&str; 27] = [
    "rank",
    "student",
    "verdict",
    "good",
    "reason",
    "defects",
    "warnings",
    "layout",
    "nodes",
    "leaves",
    "max_depth",
    "leaf_sizes",
    "sah_cost",
    "sah_cost_vs_sah_tree",
    "epo",
    "nodes_per_ray",
    "tri_tests_per_ray",
    "root_box_nodes_per_ray",
    "root_box_tri_tests_per_ray",
    "trace_ns_per_ray",
    "speedup_over_linear",
    "memory_bytes",
    "not_good_because",
    "rays_checked",
    "wrong_rays",
    "dump",
    "submission",
];

fn opt<T: ToString>(v: Option<T>) -> String {
    v.map_or(String::new(), |v| v.to_string())
}

/// A text cell as a spreadsheet shows it: one starting with `=`, `+`, `-`, `@`, a tab or a
/// carriage return (what starts a formula) gets a leading `'`, which makes it text.
fn text(cell: &str) -> String {
    if cell.starts_with(['=', '+', '-', '@', '\t', '\r']) {
        format!("'{cell}")
    } else {
        cell.to_string()
    }
}

/// The header, then one record per row.
pub fn csv_records(rows: &[GradeRow]) -> Vec<Vec<String>> {
    let mut out = vec![HEADER.map(String::from).to_vec()];
    for r in rows {
        let q = r.quality.as_ref();
        let f = |digits: usize, v: Option<f64>| {
            v.filter(|v| v.is_finite()).map_or(String::new(), |v| format!("{v:.digits$}"))
        };
        out.push(vec![
            opt(r.rank),
            text(&r.name),
            r.verdict.label().to_string(),
            opt(r.good.map(|g| if g { "yes" } else { "no" })),
            text(&r.reason),
            r.defects.to_string(),
            r.warnings.to_string(),
            opt(q.map(|q| q.layout)),
            opt(q.map(|q| q.nodes)),
            opt(q.map(|q| q.leaves)),
            opt(q.map(|q| q.max_depth)),
            q.map_or(String::new(), |q| leaf_sizes_text(&q.leaf_sizes)),
            f(3, q.map(|q| q.sah_cost)),
            f(4, r.versus_sah.map(|v| v.sah_cost)),
            f(4, q.and_then(|q| q.epo)),
            f(3, q.map(|q| q.nodes_per_ray)),
            f(3, q.map(|q| q.tri_tests_per_ray)),
            f(3, q.map(|q| q.root_nodes_per_ray)),
            f(3, q.map(|q| q.root_tri_tests_per_ray)),
            f(1, q.map(|q| q.trace_ns_per_ray)),
            f(1, q.map(|q| q.speedup_over_linear)),
            opt(q.map(|q| q.memory_bytes)),
            text(&r.misses.join("; ")),
            r.rays_checked.to_string(),
            r.wrong_rays.to_string(),
            r.dump.as_ref().map_or(String::new(), |p| text(&p.display().to_string())),
            text(&r.submission.display().to_string()),
        ]);
    }
    out
}
