//! One submission graded: its dump read (bounded), checked (`check::check_with`: the rays on every
//! thread), its tree measured and timed, its two images written, its row made; then all of it
//! dropped but the row. Nothing about a submission stops the class: an unreadable file, a
//! missing folder, a tree that takes too long (`Setup::max_seconds`, enforced through the
//! checker's and the renderer's cancel points) and even a panic become the row's verdict.

use super::measure::{measure, timed};
use super::{FindingLine, GradeRow, Images, References, ReportDir, Setup, Submission, Verdict, VersusSah};
use crate::bvh::imported::Imported;
use crate::bvh::{AnyBvh, Bvh, TreeView};
use crate::dump::BvhDump;
use crate::explain::check::{check_with, wrong_mesh, Group, Reference, Subject, FINDINGS_LISTED, LISTED};
use crate::render::diff::{difference, difference_image};
use crate::render::{draw_legend, view_image, ColorMap, HeatRange, View};
use crate::work::{Cancelled, WorkControl};
use std::panic::AssertUnwindSafe;
use std::time::{Duration, Instant};

/// Grade one submission: never fails, never panics out (a panic becomes the row's reason).
pub fn evaluate(sub: &Submission, setup: &Setup, refs: &mut References, out: &ReportDir) -> GradeRow {
    let start = Instant::now();
    let limit = Duration::from_secs_f64(setup.max_seconds.max(0.001));
    let graded = std::panic::catch_unwind(AssertUnwindSafe(|| {
        let (row, traced) = match with_deadline(limit, |control| checked(sub, setup, &refs.truth, control))? {
            CheckedDump::Finished(row) => return Ok(row),
            CheckedDump::Traced(row, tree) => (row, tree),
        };
        // Outside the submission's time: references of a layout the class had not met yet.
        let layout = traced.0.params().layout;
        let spent = start.elapsed();
        refs.ensure(layout, setup);
        let left = limit.saturating_sub(spent).max(Duration::from_millis(1));
        with_deadline(left, |control| measured(row, sub, &traced, setup, refs, out, control))
    }));
    let mut row = match graded {
        Ok(Ok(row)) => row,
        Ok(Err(Cancelled)) => GradeRow::not_checked(
            sub,
            Verdict::TimedOut,
            format!(
                "grading it took over {} s, the limit (--max-seconds): a tree whose boxes overlap makes every ray visit most nodes",
                setup.max_seconds
            ),
        ),
        Err(panic) => {
            let what = panic
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_else(|| "a panic".into());
            let reason = format!("bvhscope failed while grading it ({what}); please report this with the file");
            GradeRow::not_checked(sub, Verdict::Unreadable, reason)
        }
    };
    row.seconds = start.elapsed().as_secs_f64();
    row
}

/// Run `work` with a control that is cancelled once `limit` has passed.
fn with_deadline<T>(limit: Duration, work: impl FnOnce(&WorkControl) -> T) -> T {
    let control = WorkControl::new();
    crate::work::watched(
        |ended| {
            let start = Instant::now();
            while !ended.after(Duration::from_millis(20)) {
                if start.elapsed() >= limit {
                    control.cancel();
                    return;
                }
            }
        },
        || work(&control),
    )
}

/// What the check left: a finished row, or a row and the tree to measure.
enum CheckedDump {
    Finished(GradeRow),
    /// Boxed: the tree is large beside a row, and most rows have none.
    Traced(GradeRow, Box<(AnyBvh, Imported)>),
}

/// The dump read and checked: the row's verdict, reason and findings.
fn checked(
    sub: &Submission,
    setup: &Setup,
    truth: &Reference,
    control: &WorkControl,
) -> Result<CheckedDump, Cancelled> {
    let Some(path) = &sub.dump else {
        let why = sub.problem.clone().unwrap_or_else(|| "no dump".into());
        return Ok(CheckedDump::Finished(GradeRow::not_checked(
            sub,
            Verdict::NoDump,
            format!("{}: {why}", sub.path.display()),
        )));
    };
    let dump = match BvhDump::read(path, setup.dump_limit) {
        Ok(d) => d,
        // In bvhscope's words only: the file may be anything (its first line must not reach
        // the class's report).
        Err(e) => {
            return Ok(CheckedDump::Finished(GradeRow::not_checked(sub, Verdict::Unreadable, e.without_content())))
        }
    };
    let subject = Subject { dump: &dump, dump_path: path, mesh: setup.mesh, mesh_path: setup.mesh_path };
    let checked = check_with(&subject, truth, &setup.camera, setup.rays, setup.trace, control)?;
    let required = &setup.rubric.required;
    let findings: Vec<FindingLine> = checked
        .findings
        .iter()
        .map(|f| FindingLine {
            group: f.group,
            defect: f.defect,
            required: required.contains(&f.group),
            node: f.node,
            triangle: f.triangle,
            line: f.line(LISTED),
            cases: f.examples.len().max(1),
        })
        .collect();
    let mut row = GradeRow::not_checked(sub, Verdict::Correct, String::new());
    row.defects = findings.iter().filter(|f| f.defect).count();
    row.warnings = findings.len() - row.defects;
    row.rays_checked = checked.rays;
    row.wrong_rays = checked.wrong_rays;
    let first_required = findings.iter().find(|f| f.defect && f.required);
    if let (Some(w), true) = (wrong_mesh(&subject), row.defects > 0) {
        (row.verdict, row.reason) = (Verdict::WrongMesh, w.text);
    } else if let Some(f) = first_required {
        (row.verdict, row.reason) = (Verdict::Defects, format!("{}: {}", f.group.label(), f.line));
    }
    // The first few of each group are kept, as `check` prints them (its `LISTED` cases each):
    // the report's rows stay short, and the count says how many there are in all.
    row.findings_total = findings.len();
    let mut kept = [0usize; 4];
    row.findings = findings
        .into_iter()
        .filter(|f| {
            let k = &mut kept[Group::ALL.iter().position(|g| *g == f.group).unwrap_or(0)];
            *k += 1;
            *k <= FINDINGS_LISTED
        })
        .collect();
    // A tree over another mesh is not measured: its figures would say nothing of the student's work.
    Ok(match checked.tree {
        Some(tree) if row.verdict != Verdict::WrongMesh => CheckedDump::Traced(row, Box::new(tree)),
        _ => CheckedDump::Finished(row),
    })
}

/// The traced tree measured, timed and drawn into `row`.
fn measured(
    mut row: GradeRow,
    sub: &Submission,
    (tree, imported): &(AnyBvh, Imported),
    setup: &Setup,
    refs: &References,
    out: &ReportDir,
    control: &WorkControl,
) -> Result<GradeRow, Cancelled> {
    let layout = tree.params().layout;
    // The EPO is of a binary tree: the dump's own, or a wide dump binarised as the tree view shows it.
    let binary: Option<&Bvh> = match tree {
        AnyBvh::Binary(b) => Some(b),
        AnyBvh::Wide(_) | AnyBvh::Wide8(_) => imported.binary.as_ref().map(|(b, _)| b.as_ref()),
    };
    let (q, frame) = measure(tree, binary, setup.mesh, &setup.camera, setup.trace, setup.secondary, control)?;
    control.check()?;
    // Timed in the same rounds as bvhscope's SAH tree: the ratio survives a busy machine.
    let (ns, versus_time, sah_speedup) = refs.time_against_sah(tree, layout, setup, control)?;
    let q = timed(q, ns, versus_time, sah_speedup);
    let sah = &refs.sah(layout).expect("ensured above").quality;
    let ratio = |a: f64, b: f64| if b > 0.0 { a / b } else { f64::NAN };
    let versus = VersusSah {
        sah_cost: ratio(q.sah_cost, sah.sah_cost),
        nodes_per_ray: ratio(q.nodes_per_ray, sah.nodes_per_ray),
        tri_tests_per_ray: ratio(q.tri_tests_per_ray, sah.tri_tests_per_ray),
        trace_time: versus_time,
    };
    if row.verdict == Verdict::Correct && setup.rubric.good.any() {
        row.misses = setup.rubric.good.misses(&q, &versus);
        row.good = Some(row.misses.is_empty());
    }
    // The images: nodes visited on the class's scale for this layout (so they compare from student
    // to student), and the difference from the SAH tree (B, the student, minus A, bvhscope) on
    // ± the 99th percentile of its own differences, as `render --against` draws it: most
    // differences are a few nodes, and a class-wide scale left them white.
    let cost = tree.params().cost;
    let top = refs.visits_max(layout);
    let (img, legend) =
        view_image(&frame, View::Visits, ColorMap::Viridis, HeatRange::Fixed { min: 0.0, max: top }, cost);
    let visits = legend.map(|mut l| {
        l.subject = format!("{}: {}", sub.name, imported.label());
        draw_legend(&img, &l)
    });
    let sah_frame = refs.sah_frame(layout).expect("ensured above");
    let diff = difference(sah_frame, &frame, View::Visits, cost).map(|d| {
        let (img, mut l) = difference_image(frame.width(), &d, View::Visits, None);
        l.subject = format!("A: bvhscope SAH ({}), B: {}", layout.name(), sub.name);
        draw_legend(&img, &l)
    });
    if let (Some(v), Some(d)) = (visits, diff) {
        let names = Images {
            visits: ReportDir::image_name(&sub.slug, "visits"),
            difference: ReportDir::image_name(&sub.slug, "difference"),
        };
        match out.write_png(&names.visits, &v).and_then(|_| out.write_png(&names.difference, &d)) {
            Ok(()) => row.images = Some(names),
            Err(e) => row.notes.push(format!("images not written: {e}")),
        }
    }
    row.quality = Some(q);
    row.versus_sah = Some(versus);
    Ok(row)
}
