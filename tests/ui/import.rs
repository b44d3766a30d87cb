//! Bring your own BVH in the app: a dump dropped or opened is checked as `bvhscope check` checks it,
//! listed as "imported: FILE" among the strategies, and traced by every view; the app's figures
//! are the command line's (`check`, `render --bvh`, `inspect --bvh`).

mod support;

use bvhscope::app::{Action, BvhscopeApp, MessageKind, Pick, SceneSource};
use bvhscope::cli::Command;
use bvhscope::explain::check::Group;
use egui_kittest::kittest::Queryable;
use egui_kittest::Harness;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use support::*;

fn torus() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/torus.obj")
}

/// Export `strategy`'s tree of the torus in `layout` to `name` (through the command line).
fn export(name: &str, strategy: &str, layout: &str) -> PathBuf {
    let out = temp_file(name, "");
    let args = [s("export-bvh"), s(torus().display()), s("--strategy"), s(strategy), s("--layout"), s(layout), s("-o")];
    let mut args = args.to_vec();
    args.push(s(out.display()));
    bvhscope::cli::run(words(&args)).unwrap();
    out
}

/// The app on the torus, idle.
fn on_the_torus() -> Harness<'static, BvhscopeApp> {
    let mut h = harness();
    run_until(&mut h, "the first frame", idle);
    h.state_mut().act(Action::Picked(Pick::Open, torus()));
    run_until(&mut h, "the torus", |a| a.scene.source == SceneSource::File(torus()) && idle(a));
    h
}

fn shows_imported(a: &BvhscopeApp) -> bool {
    idle(a) && a.shown.as_ref().is_some_and(|s| s.bvh.import().is_some()) && a.jobs.wrong.is_none()
}

/// A midpoint tree with its leaves' boxes halved in x, dropped on the window: checked (the
/// same findings and wrong pixels as `bvhscope check`), chosen in the strategy list, its image's
/// counts those of `render --bvh`, its findings linked to the tree view, its rays named by the
/// dump's ids, side by side against SAH; and back to the built strategy.
#[test]
fn a_dropped_dump_is_checked_and_traced_by_every_view() {
    let good = export("good.json", "midpoint", "binary");
    let mut v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&good).unwrap()).unwrap();
    let leaf = v["nodes"].as_array().unwrap().iter().position(|n| n.get("first").is_some()).unwrap();
    for n in v["nodes"].as_array_mut().unwrap().iter_mut().filter(|n| n.get("first").is_some()) {
        let (lo, hi) = (n["min"][0].as_f64().unwrap(), n["max"][0].as_f64().unwrap());
        n["max"][0] = serde_json::json!((lo + hi) / 2.0);
    }
    let broken = temp_file("broken.json", &v.to_string());

    let mut h = on_the_torus();
    h.input_mut().dropped_files.push(Arc::new(Dropped(broken.clone())));
    run_until(&mut h, "the imported tree's image and wrong pixels", |a| shows_imported(a) && a.import.wrong.is_some());
    assert_eq!(h.state().scene.source, SceneSource::File(torus()), "a dump is imported, not opened");
    // The strategy list holds it, chosen; a built-in strategy in the list goes back to a build.
    h.get_by_role_and_label(egui::accesskit::Role::ComboBox, "Split strategy").click();
    h.run_steps(2);
    h.get_by_label("imported: broken.json");
    assert!(h.state().import.on);
    h.get_by_role_and_label(egui::accesskit::Role::ComboBox, "Split strategy").click();
    h.run_steps(2);
    h.get_by_label("Imported BVH");
    assert!(h.state().messages.iter().any(|m| m.kind == MessageKind::Warning && m.text.contains("broken.json")));

    // The checker's findings and the red mask: as `bvhscope check` finds them for the same camera.
    let (shown_camera, findings, wrong) = {
        let app = h.state();
        let t = app.import.tree.as_ref().unwrap();
        let w = app.import.wrong.as_ref().unwrap();
        (app.shown.as_ref().unwrap().camera, t.findings.clone(), w.pixels.clone())
    };
    let mut args = vec![s("check"), s(torus().display()), s("--bvh"), s(broken.display())];
    args.extend(camera_words(&shown_camera));
    args.extend([s("--rays"), s(0), s("--no-compare"), s("--format"), s("json")]);
    let Command::Check(check_args) = words(&args) else { panic!("check") };
    let (json, defects) = bvhscope::cli::check::output(&check_args).unwrap();
    let cli: serde_json::Value = serde_json::from_str(&json).unwrap();
    let tree_findings = |f: &[bvhscope::explain::check::Finding]| {
        f.iter().filter(|f| f.group != Group::Rays).map(|f| serde_json::to_value(f).unwrap()).collect::<Vec<_>>()
    };
    let cli_tree: Vec<serde_json::Value> =
        cli["findings"].as_array().unwrap().iter().filter(|f| f["group"] != "Rays").cloned().collect();
    assert_eq!(tree_findings(&findings), cli_tree, "structure, coverage and bounds findings");
    // (The finding names the leaf whose box misses by most; every halved leaf is among its cases.)
    let names_leaf = |f: &bvhscope::explain::check::Finding| {
        f.node == Some(leaf as u32) || f.examples.iter().any(|e| e.starts_with(&format!("leaf node {leaf} (")))
    };
    assert!(defects > 0 && findings.iter().any(|f| f.group == Group::Bounds && names_leaf(f)));
    let cli_wrong: Vec<(u32, u32)> = serde_json::from_value(cli["wrong_pixels"].clone()).unwrap();
    assert!(!wrong.is_empty(), "a halved leaf box misses rays");
    let mut sorted = wrong.clone();
    sorted.sort();
    let mut cli_sorted = cli_wrong;
    cli_sorted.sort();
    assert_eq!(sorted, cli_sorted, "the red mask's pixels are check's wrong pixels");
    h.get_by_label_contains(&format!("{} of", wrong.len()));
    assert!(h.state().wrong_mask(&h.ctx.clone()).is_some_and(|(_, n)| n == wrong.len()));

    // The heatmap's counts: `render --bvh` on the same camera gives them pixel for pixel.
    h.state_mut().act(Action::View(2));
    run_until(&mut h, "the visits heatmap", |a| shows_imported(a) && a.shown.as_ref().unwrap().legend.is_some());
    let csv = temp_file("imported-counts.csv", "");
    let mut args = vec![s("render"), s(torus().display()), s("--bvh"), s(broken.display()), s("--view"), s("visits")];
    // The heatmap's camera: its legend took its part of the image's tile, so the image is smaller.
    args.extend(camera_words(&h.state().shown.as_ref().unwrap().camera));
    args.extend([s("--counts"), s(csv.display()), s("-o"), s(temp_file("imported.png", "").display())]);
    bvhscope::cli::run(words(&args)).unwrap();
    let app_counts = h.state().shown.as_ref().unwrap().frame.counts_csv().unwrap();
    assert_eq!(app_counts, std::fs::read_to_string(&csv).unwrap(), "the app's counts are render --bvh's");

    // A finding that names a node selects it in the tree view (by the dump's id).
    h.get_by_role_and_label(
        egui::accesskit::Role::Link,
        &format!(
            "defect: {}",
            findings.iter().find(|f| f.group == Group::Bounds).unwrap().line(bvhscope::explain::check::LISTED)
        ),
    )
    .click();
    run_until(&mut h, "the node selected", |a| {
        a.nodes.selected.is_some() && a.nodes.current(a.current_bvh().map(|b| &b.bvh)).is_some()
    });
    {
        let app = h.state();
        let bvh = &app.current_bvh().unwrap().bvh;
        let selected = app.nodes.selected.unwrap();
        let named = findings.iter().find(|f| f.group == Group::Bounds).unwrap().node;
        assert_eq!(bvh.import().unwrap().dump_of_binary_node(selected), named, "the finding's node");
        assert!(app.nodes.window);
    }

    // A pinned ray names the dump's nodes and gives the trace command with --bvh.
    h.state_mut().act(Action::PinPixel(shown_camera.width / 2, shown_camera.height / 2));
    h.run_steps(2);
    {
        let r = h.state().pins.current().unwrap();
        assert!(r.label.contains("imported: broken.json"), "{}", r.label);
        assert!(r.command.as_ref().unwrap().contains(&format!("--bvh {}", broken.display())));
        assert_eq!(r.named.len(), r.trace.steps.len());
    }

    // Side by side: B, SAH's build, against the imported tree.
    h.state_mut().act(Action::Compare(true));
    run_until(&mut h, "B", |a| pair_shown(a) && a.jobs.compare.is_none());
    assert!(h.state().compare_images(&h.ctx.clone()).is_some());
    assert!(h.query_all_by_label_contains("imported: broken.json").count() >= 1);
    h.state_mut().act(Action::Compare(false));

    // Its node boxes are drawn, and File ▸ Export BVH writes it back: the same nodes.
    let mut settings = h.state().settings.clone();
    (settings.show_boxes, settings.box_depth) = (true, 3);
    h.state_mut().act(Action::Edit(Box::new(settings)));
    h.run_steps(2);
    assert_eq!(h.state().boxes_drawn(), 8, "a binary tree has 8 nodes at depth 3 here");
    let written = temp_file("written.json", "");
    h.state_mut().act(Action::Picked(Pick::SaveBvh, written.clone()));
    let back = bvhscope::dump::BvhDump::read(&written, 1 << 30).unwrap();
    assert_eq!(back.nodes.len(), v["nodes"].as_array().unwrap().len());

    // Back to the built strategy: chosen in the list (the one built before, SAH).
    h.get_by_role_and_label(egui::accesskit::Role::ComboBox, "Split strategy").click();
    h.run_steps(2);
    h.get_by_role_and_label(egui::accesskit::Role::Button, "SAH binned").click();
    run_until(&mut h, "the built tree again", |a| idle(a) && a.shown.as_ref().unwrap().bvh.import().is_none());
}

/// A 4-wide dump is traced as 4-wide and binarised for the tree view; the node inspector's figures
/// for a dump node are `bvhscope inspect --bvh DUMP --node ID`'s.
#[test]
fn a_four_wide_dump_is_explained_like_a_built_tree() {
    let wide = export("wide.json", "sah", "wide4");
    let mut h = on_the_torus();
    h.state_mut().act(Action::ImportFile(wide.clone()));
    run_until(&mut h, "the imported 4-wide tree", shows_imported);
    assert_eq!(h.state().import.tree.as_ref().unwrap().defects(), 0);
    assert!(h.state().import.wrong.as_ref().unwrap().pixels.is_empty(), "a correct tree hits as the linear scan");
    assert_eq!(h.state().current_bvh().unwrap().bvh.build_params().bvh.layout, bvhscope::bvh::Layout::Wide4);
    let dump_node = 5;
    h.state_mut().act(Action::SelectDumpNode(dump_node));
    run_until(&mut h, "its inspection", |a| a.nodes.inspection.is_some() && a.nodes.visits.is_some() && idle(a));
    let ins = h.state().nodes.inspection.clone().unwrap();
    let mut args = vec![s("inspect"), s(torus().display()), s("--bvh"), s(wide.display()), s("--node"), s(dump_node)];
    args.extend(camera_words(&h.state().shown.as_ref().unwrap().camera));
    args.extend([s("--format"), s("json")]);
    let Command::Inspect(a) = words(&args) else { panic!("inspect") };
    let v: serde_json::Value = serde_json::from_str(&bvhscope::cli::inspect::output(&a).unwrap()).unwrap();
    assert_eq!(v["dump_node"], dump_node);
    assert_eq!(v["node"], ins.node);
    assert_eq!(v["triangles"], ins.triangles);
    assert_eq!(v["own_cost"].as_f64().map(|c| c as f32), ins.own_cost);
    let visits = h.state().nodes.visits.as_ref().unwrap().counts[ins.node as usize];
    assert_eq!(v["visits"], visits);
    h.get_by_label_contains(&format!("dump node {dump_node}."));
}

/// A file that is no dump is refused in one message naming it, and the scene and tree stay; a dump
/// whose structure is broken is listed with its findings but cannot be chosen.
#[test]
fn unreadable_and_broken_dumps_say_why() {
    let mut h = on_the_torus();
    let nodes = h.state().current_bvh().unwrap().stats.nodes;
    let junk = temp_file("junk.json", "{\"format\": \"bvhscope-bvh\", \"version\": 7}");
    h.state_mut().act(Action::ImportFile(junk));
    run_until(&mut h, "the refusal", |a| a.messages.iter().any(|m| m.kind == MessageKind::Error));
    h.get_by_label_contains("junk.json: version 7 of the bvhscope-bvh format");
    assert!(!h.state().import.on && h.state().import.tree.is_none());
    assert_eq!(h.state().current_bvh().unwrap().stats.nodes, nodes, "the built tree stays");

    let good = export("cycle.json", "midpoint", "binary");
    let mut v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&good).unwrap()).unwrap();
    v["nodes"][1]["children"] = serde_json::json!([0, 2]);
    v["nodes"][1].as_object_mut().unwrap().remove("first");
    v["nodes"][1].as_object_mut().unwrap().remove("count");
    std::fs::write(&good, v.to_string()).unwrap();
    h.state_mut().act(Action::ImportFile(good));
    run_until(&mut h, "the broken dump's findings", |a| {
        a.import.tree.as_ref().is_some_and(|t| t.path.ends_with("cycle.json")) && a.jobs.import.is_none()
    });
    let t = h.state().import.tree.as_ref().unwrap();
    assert!(t.bvh.is_err() && !h.state().import.on);
    assert!(t.findings.iter().any(|f| f.line(usize::MAX).contains("a cycle")));
    h.get_by_label_contains("Not traced");
}

/// File ▸ Open BVH path…: the field takes the keyboard (the keys of a typed path fire no
/// shortcut), and Enter imports the dump.
#[test]
fn a_dump_opened_by_typing_its_path_is_imported() {
    let dump = export("typed-sbc-12345].json", "midpoint", "binary");
    let mut h = on_the_torus();
    let (settings, orbit) = (h.state().settings.clone(), h.state().orbit);
    h.get_by_role_and_label(egui::accesskit::Role::Button, "File").click();
    h.run_steps(2);
    h.get_by_label("Open BVH path…").click();
    h.run_steps(2);
    assert!(h.state().path_window.is_some(), "the path window opens");
    h.run_steps(3);
    assert!(h.get_by_label("Path").is_focused(), "the field takes the keyboard when it opens");
    let typed = dump.display().to_string();
    type_keys(&mut h, &typed);
    assert_eq!(h.state().path_window.as_ref().map(|w| w.text.as_str()), Some(typed.as_str()));
    assert_eq!(h.state().settings, settings, "no setting changed while typing");
    assert_eq!(h.state().orbit, orbit, "the camera did not move");
    h.key_press(egui::Key::Enter);
    run_until(&mut h, "the typed dump, imported and shown", shows_imported);
    assert!(h.state().path_window.is_none());
    assert!(h.state().import.tree.as_ref().is_some_and(|t| t.path == dump && t.defects() == 0));
}

/// `bvhscope MESH --bvh DUMP` with a correct dump whose every box is the root's (its check makes
/// every ray visit every node: minutes): the mesh's own build and first full frame come first,
/// while the check is still running, and a strategy changed meanwhile builds at once (no build
/// waits for the check).
#[test]
fn a_slow_import_check_never_holds_the_meshs_own_build_and_image_back() {
    let mesh = generate_knot_file("slow-knot.obj");
    let out = temp_file("slow-sah.json", "");
    let args = [s("export-bvh"), s(mesh.display()), s("--strategy"), s("sah"), s("-o"), s(out.display())];
    bvhscope::cli::run(words(&args)).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    let (min, max) = (v["nodes"][0]["min"].clone(), v["nodes"][0]["max"].clone());
    for n in v["nodes"].as_array_mut().unwrap() {
        n["min"] = min.clone();
        n["max"] = max.clone();
    }
    let fat = temp_file("slow-fat.json", &v.to_string());
    let options = bvhscope::app::AppOptions { file: Some(mesh.clone()), bvh: Some(fat) };
    let mut h = egui_kittest::Harness::builder()
        .with_size(egui::vec2(1400.0, 860.0))
        .build_eframe(move |cc| BvhscopeApp::new(cc, options.clone()));
    run_until(&mut h, "the mesh's own first full frame", |a| {
        a.scene.source == SceneSource::File(mesh.clone()) && idle(a)
    });
    assert!(h.state().jobs.import.is_some() && h.state().import.tree.is_none(), "the check is still running");
    // A strategy changed now builds and shows without waiting for the check.
    let mut s = h.state().settings.clone();
    s.build.strategy = bvhscope::bvh::Strategy::Midpoint;
    h.state_mut().act(Action::Edit(Box::new(s)));
    run_until(&mut h, "the midpoint tree's frame", |a| {
        idle(a)
            && a.current_bvh().is_some_and(|b| b.bvh.build_params().bvh.strategy == bvhscope::bvh::Strategy::Midpoint)
    });
    assert!(h.state().import.tree.is_none(), "the check is still running");
}

/// A 20,000-triangle knot written as an OBJ (its fat tree's check takes minutes).
fn generate_knot_file(name: &str) -> PathBuf {
    let m = bvhscope::mesh::generate::torus_knot(2, 3, 0.3, 500, 20);
    let mut text = Vec::new();
    bvhscope::mesh::write_obj(&m, &mut text).unwrap();
    temp_file(name, std::str::from_utf8(&text).unwrap())
}

/// One yardstick in the app too: a dump that keeps the mesh's far zero-area triangle (its root box
/// forty times the knot's height) is measured on the mesh's box, as `check`'s table measures it,
/// so its SAH cost is above the tight tree's, not flattered by its larger root.
#[test]
fn an_imported_tree_is_measured_on_the_meshs_box() {
    // The knot and one zero-area triangle far above it.
    let knot = bvhscope::mesh::generate::torus_knot(2, 3, 0.3, 96, 8);
    let mut text = Vec::new();
    bvhscope::mesh::write_obj(&knot, &mut text).unwrap();
    let v = knot.positions.len();
    text.extend(format!("v 0 40 0\nv 1 40 0\nv 2 40 0\nf {} {} {}\n", v + 1, v + 2, v + 3).bytes());
    let mesh = temp_file("far-degenerate.obj", std::str::from_utf8(&text).unwrap());
    let tight = temp_file("far-tight.json", "");
    let args = [s("export-bvh"), s(mesh.display()), s("--strategy"), s("midpoint"), s("-o"), s(tight.display())];
    bvhscope::cli::run(words(&args)).unwrap();
    // The far triangle (the file's last) put in the highest leaf, its box and its ancestors' grown.
    let mut d: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&tight).unwrap()).unwrap();
    let far = knot.triangle_count() as u64;
    let nodes = d["nodes"].as_array().unwrap().clone();
    let leaf = (0..nodes.len())
        .filter(|&i| nodes[i].get("first").is_some())
        .max_by(|&a, &b| nodes[a]["max"][1].as_f64().unwrap().total_cmp(&nodes[b]["max"][1].as_f64().unwrap()))
        .unwrap();
    let at = nodes[leaf]["first"].as_u64().unwrap() + nodes[leaf]["count"].as_u64().unwrap();
    d["primitives"].as_array_mut().unwrap().insert(at as usize, far.into());
    let mut parent = vec![usize::MAX; nodes.len()];
    for (i, n) in nodes.iter().enumerate() {
        for k in n["children"].as_array().into_iter().flatten() {
            parent[k.as_u64().unwrap() as usize] = i;
        }
    }
    for n in d["nodes"].as_array_mut().unwrap() {
        if n["first"].as_u64().is_some_and(|f| f >= at) {
            n["first"] = (n["first"].as_u64().unwrap() + 1).into();
        }
    }
    d["nodes"][leaf]["count"] = (nodes[leaf]["count"].as_u64().unwrap() + 1).into();
    let mut i = leaf;
    loop {
        let hi = d["nodes"][i]["max"][1].as_f64().unwrap().max(40.0);
        d["nodes"][i]["max"][1] = hi.into();
        let hx = d["nodes"][i]["max"][0].as_f64().unwrap().max(2.0);
        d["nodes"][i]["max"][0] = hx.into();
        if i == 0 {
            break;
        }
        i = parent[i];
    }
    let kept = temp_file("far-kept.json", &d.to_string());

    let mut h = harness();
    run_until(&mut h, "the first frame", idle);
    h.state_mut().act(Action::Picked(Pick::Open, mesh.clone()));
    run_until(&mut h, "the mesh", |a| a.scene.source == SceneSource::File(mesh.clone()) && idle(a));
    h.input_mut().dropped_files.push(Arc::new(Dropped(kept.clone())));
    run_until(&mut h, "the imported tree", shows_imported);
    let app_sah = h.state().current_bvh().unwrap().stats.sah_cost;
    // `check`'s table: the imported tree's row, and bvhscope's midpoint tree in its layout.
    let args =
        [s("check"), s(mesh.display()), s("--bvh"), s(kept.display()), s("--rays"), s(0), s("--format"), s("json")];
    let Command::Check(check_args) = words(&args) else { panic!("check") };
    let (json, _) = bvhscope::cli::check::output(&check_args).unwrap();
    let cli: serde_json::Value = serde_json::from_str(&json).unwrap();
    let row = |name: &str| {
        cli["quality"].as_array().unwrap().iter().find(|r| r["name"].as_str().unwrap().starts_with(name)).unwrap()
            ["sah_cost"]
            .as_f64()
            .unwrap()
    };
    let (cli_sah, midpoint) = (row("imported"), row("Midpoint"));
    assert!((app_sah - cli_sah).abs() <= 1e-9 * cli_sah, "the app's {app_sah} is check's {cli_sah}");
    assert!(cli_sah > midpoint, "the kept triangle costs its box: {cli_sah} against the tight tree's {midpoint}");
    assert!(cli["findings"]
        .as_array()
        .unwrap()
        .iter()
        .any(|f| f["text"].as_str().unwrap().starts_with("the root box is larger")));
}
