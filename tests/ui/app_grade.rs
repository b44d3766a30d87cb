//! A class's grade report in the app: a grade.json written by `bvhscope grade` and opened (dropped
//! on the window, or its folder's path typed) lists the students; choosing a correct one imports
//! their dump over the report's mesh, on its camera and traversal, side by side against SAH
//! binned; choosing one whose file is no dump shows the report's reason and imports nothing.

use super::support::*;
use bvhscope::app::{Action, BvhscopeApp, MessageKind, SceneSource};
use bvhscope::bvh::{Layout, Strategy};
use egui_kittest::kittest::Queryable;
use egui_kittest::Harness;
use std::path::{Path, PathBuf};
use std::sync::Arc;

fn torus() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/torus.obj")
}

/// A class of three on the torus, graded by `bvhscope grade`: ada's midpoint tree (correct),
/// cy's file that is no dump, dee's empty folder. Returns the report folder.
pub(super) fn graded_class(tag: &str) -> PathBuf {
    let dir = crate::support::scratch::dir(&format!("ui-grade-{tag}"));
    let class = dir.join("class");
    std::fs::create_dir_all(class.join("dee")).unwrap();
    let ada = class.join("ada.txt");
    let export = [s("export-bvh"), s(torus().display()), s("--strategy"), s("midpoint"), s("--layout"), s("binary")];
    let mut args = export.to_vec();
    args.extend([s("-o"), s(ada.display())]);
    bvhscope::cli::run(words(&args)).unwrap();
    std::fs::write(class.join("cy.txt"), "not a dump\n").unwrap();
    let report = dir.join("report");
    let mut args = vec![s("grade"), s(torus().display())];
    args.extend(["ada.txt", "cy.txt", "dee"].map(|n| s(class.join(n).display())));
    args.extend([
        s("--out"),
        s(report.display()),
        s("--rays"),
        s(1000),
        s("--time-rays"),
        s(64),
        s("--size"),
        s("64x48"),
    ]);
    bvhscope::cli::run(words(&args)).unwrap();
    report
}

/// The chosen student's tree on screen, against B, with nothing left running.
pub(super) fn student_shown(a: &BvhscopeApp) -> bool {
    a.grade.pending.is_none()
        && pair_shown(a)
        && a.jobs.compare.is_none()
        && a.jobs.wrong.is_none()
        && a.shown.as_ref().is_some_and(|s| s.bvh.import().is_some())
}

/// Dropped on the window over the built-in scene: the report's mesh is opened, ada's tree imported
/// (checked again: no defect) and compared against SAH binned in its layout on the report's
/// camera and traversal; then cy, whose file is no dump: the reason, and nothing imported.
#[test]
fn a_grade_report_shows_a_student_against_sah_or_why_not() {
    let report = graded_class("show");
    let mut h = harness();
    run_until(&mut h, "the first frame", idle);
    h.input_mut().dropped_files.push(Arc::new(Dropped(report.join("grade.json"))));
    run_until(&mut h, "the report", |a| a.grade.report.is_some() && a.grade.window);
    assert_eq!(h.state().scene.source, SceneSource::Builtin, "a report opens no scene by itself");
    for label in ["ada", "cy", "dee", "correct", "unreadable", "no dump"] {
        h.get_by_label(label);
    }

    click_label(&mut h, "ada");
    run_until(&mut h, "ada's tree against SAH binned", student_shown);
    {
        let app = h.state();
        let r = app.grade.report.clone().unwrap();
        assert_eq!(app.scene.source, SceneSource::File(torus()), "the report's mesh is opened");
        let t = app.import.tree.as_ref().unwrap();
        assert_eq!(t.path, report.parent().unwrap().join("class/ada.txt"));
        assert_eq!(t.defects(), 0, "checked again: correct");
        assert!(app.import.on && app.compare.on);
        let b = app.compare.b.as_ref().unwrap();
        assert_eq!((b.build.bvh.strategy, b.build.bvh.layout), (Strategy::SahBinned, Layout::Binary));
        assert_eq!(app.settings.trace, r.trace);
        let c = app.shown.as_ref().unwrap().camera;
        assert_eq!(
            (c.position, c.look_at, c.up, c.vfov_deg),
            (r.camera.position, r.camera.look_at, r.camera.up, r.camera.vfov_deg)
        );
        assert!(app.compare_images(&h.ctx.clone()).is_some(), "the two frames side by side");
    }
    h.get_by_label_contains("A = imported: ada.txt (0 defects as checked here), B = SAH binned");

    click_label(&mut h, "cy");
    run_until(&mut h, "cy's reason", |a| a.grade.why_not.is_some() && idle(a));
    let app = h.state();
    assert!(app.import.tree.is_none() && !app.import.on && !app.compare.on, "nothing imported");
    assert!(app.shown.as_ref().unwrap().bvh.import().is_none(), "the built strategy is shown again");
    let why = app.grade.why_not.clone().unwrap();
    assert!(why.contains("cy.txt: not a bvhscope-bvh file"), "{why}");
    h.get_by_label(&format!("Not shown: {why}"));
}

/// File ▸ Open grade report path…: the folder's path typed, the report read from its grade.json;
/// a report of another version refused in one message naming the file.
#[test]
fn a_grade_report_typed_by_its_folder_is_read_and_another_version_refused() {
    let report = graded_class("typed");
    let mut h: Harness<'static, BvhscopeApp> = harness();
    run_until(&mut h, "the first frame", idle);
    h.get_by_role_and_label(egui::accesskit::Role::Button, "File").click();
    h.run_steps(2);
    h.get_by_label("Open grade report path…").click();
    h.run_steps(3);
    type_keys(&mut h, &report.display().to_string());
    h.key_press(egui::Key::Enter);
    run_until(&mut h, "the typed report", |a| a.grade.report.is_some());
    assert_eq!(h.state().grade.report.as_ref().unwrap().students.len(), 3);
    assert!(h.state().path_window.is_none());

    let text = std::fs::read_to_string(report.join("grade.json")).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    v["version"] = 2.into();
    let future = report.join("future.json");
    std::fs::write(&future, v.to_string()).unwrap();
    h.state_mut().act(Action::OpenGradeReportFile(future.clone()));
    run_until(&mut h, "the refusal", |a| a.messages.iter().any(|m| m.kind == MessageKind::Error));
    let want = format!("{}: version 2 of the bvhscope-grade format; this bvhscope reads version 1", future.display());
    h.get_by_label_contains(&want);
    assert_eq!(h.state().grade.report.as_ref().unwrap().file, report.join("grade.json"), "the open report stays");
}
