//! The app from the front of a room (issue 48, the parts done; the legend's place is in
//! `app_legend.rs`): messages come one per topic and go when the scene changes or on a click, and
//! a plain click on the image pins no ray until the Ray window is open. A module of the `app_ui`
//! test binary (`app.rs`).

use super::*;

/// One message per topic: a second note replaces the first, the same warning twice is shown
/// once; a click on a message dismisses it; a new scene clears the old scene's messages.
#[test]
fn messages_come_one_per_topic_and_go_with_their_scene() {
    let mut h = harness();
    run_until(&mut h, "the first frame", idle);
    let app = h.state_mut();
    app.messages.clear();
    app.message(MessageKind::Info, "Saved a.png");
    app.message(MessageKind::Info, "Saved a.png");
    app.message(MessageKind::Warning, "alice.json: her tree keeps a far triangle");
    app.message(MessageKind::Warning, "alice.json: her tree keeps a far triangle, again");
    app.message(MessageKind::Warning, "bob.json: another warning");
    let texts: Vec<&str> = h.state().messages.iter().map(|m| m.text.as_str()).collect();
    assert_eq!(texts, ["Saved a.png", "alice.json: her tree keeps a far triangle, again", "bob.json: another warning"]);
    h.run_steps(2);
    // A click on the message's text (not its button) dismisses it.
    let at = h.get_by_label_contains("another warning").rect().center();
    h.input_mut().events.push(egui::Event::PointerMoved(at));
    let button = |pressed| egui::Event::PointerButton {
        pos: at,
        button: egui::PointerButton::Primary,
        pressed,
        modifiers: egui::Modifiers::NONE,
    };
    h.input_mut().events.push(button(true));
    h.step();
    h.input_mut().events.push(button(false));
    h.run_steps(3);
    assert!(h.state().pins.pinned.is_empty(), "the click pinned no ray");
    assert_eq!(h.state().messages.len(), 2, "{:?}", h.state().messages.iter().map(|m| &m.text).collect::<Vec<_>>());
    // A scene opened: the old scene's messages are gone.
    let torus = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/torus.obj");
    h.state_mut().act(Action::Picked(bvhscope::app::Pick::Open, torus.clone()));
    run_until(&mut h, "the torus", |a| a.scene.source == SceneSource::File(torus.clone()) && idle(a));
    assert!(h.state().messages.iter().all(|m| !m.text.contains("alice") && !m.text.contains("a.png")));
    assert!(h.state().messages.iter().any(|m| m.text.starts_with("Opened torus.obj")), "the new scene's own");
}

/// Side by side, "Fix the current range" takes the pair's one scale (A's alone clipped B's hottest
/// pixels); in the difference mode the difference's ±range is fixed, and its legend follows.
#[test]
fn compare_ranges_are_fixed_on_the_shared_scale_and_the_difference_too() {
    let mut h = midpoint_against_sah();
    h.run_steps(2);
    let ctx = h.ctx.clone();
    let shared = h.state().compare_images(&ctx).unwrap().legend.as_ref().map(|l| (l.range_min, l.range_max)).unwrap();
    let own = h.state().shown.as_ref().unwrap().legend.as_ref().map(|l| l.range_max).unwrap();
    assert!(shared.1 > own, "B's hottest pixel is above A's here ({} > {own}): the case that clipped", shared.1);
    h.get_by_label("Fix the current range").click();
    h.run_steps(2);
    let view = h.state().settings.view;
    assert_eq!(h.state().settings.fixed_ranges.get(&view).copied(), Some((shared.0, shared.1.max(shared.0 + 1.0))));
    // The difference: its range fixed at ±3, and its legend says so.
    h.get_by_label("Difference B - A").click();
    h.run_steps(2);
    h.get_by_label("Fixed difference range (±)").click();
    h.run_steps(2);
    *h.state_mut().settings.diff_ranges.get_mut(&view).expect("fixed") = 3.0;
    let ctx2 = ctx.clone();
    run_until(&mut h, "the difference on ±3", move |a| {
        idle(a) && a.compare_images(&ctx2).is_some_and(|c| c.diff_range == Some(3.0))
    });
    let diff = h.state().compare_images(&ctx).unwrap().diff.as_ref().unwrap().2.clone();
    assert_eq!((diff.range_min, diff.range_max), (-3.0, 3.0));
}

/// In Compare, File ▸ Save view writes what is on screen (halves, wipe, difference, each with its
/// legend) and Export counts the pair's numbers (x, y, a, b, b_minus_a), each byte for byte what
/// `render --against … --pair-view … --difference` writes for the same camera; the names say so.
#[test]
fn compare_exports_are_what_the_screen_shows_byte_for_byte_the_clis() {
    use bvhscope::app::{PairView, Pick};
    let mut h = harness();
    let torus = Path::new(env!("CARGO_MANIFEST_DIR")).join("../assets/torus.obj");
    open(&mut h, &torus);
    with_strategy(&mut h, Strategy::Midpoint);
    h.state_mut().act(Action::View(2));
    run_until(&mut h, "midpoint's heatmap", midpoint_heatmap_shown);
    h.state_mut().act(Action::Compare(true));
    run_until(&mut h, "B", pair_shown);
    assert_eq!(h.state().compare.strategy, Strategy::SahBinned);
    let camera = h.state().shown.as_ref().unwrap().camera;
    let cli = |pair: &str, wipe: f32, png: &Path, csv: &Path| {
        let mut args = vec![s("render"), s(torus.display()), s("--strategy"), s("midpoint"), s("--view"), s("visits")];
        args.extend(camera_words(&camera));
        args.extend([s("--against"), s("sah"), s("--pair-view"), s(pair), s("--wipe"), s(wipe)]);
        args.extend([s("--difference"), s(csv.display()), s("-o"), s(png.display())]);
        bvhscope::cli::run(words(&args)).unwrap();
    };
    let mut written = Vec::new();
    for (mode, pair, wipe) in
        [(PairView::Halves, "halves", 0.5), (PairView::Wipe, "wipe", 0.3), (PairView::Difference, "difference", 0.5)]
    {
        h.state_mut().act(Action::CompareMode(mode));
        h.state_mut().compare.wipe = wipe;
        h.run_steps(2);
        let name = bvhscope::app::default_name(h.state(), "png");
        assert!(name.contains("midpoint-vs-sah") && name.ends_with(&format!("visits-{pair}.png")), "{name}");
        let app_png = temp_file(&format!("app-{pair}.png"), "");
        h.state_mut().act(Action::Picked(Pick::SavePng, app_png.clone()));
        let (cli_png, cli_csv) = (temp_file(&format!("cli-{pair}.png"), ""), temp_file(&format!("cli-{pair}.csv"), ""));
        cli(pair, wipe, &cli_png, &cli_csv);
        let bytes = std::fs::read(&app_png).unwrap();
        assert!(bytes == std::fs::read(&cli_png).unwrap(), "{pair}: the app's PNG is the CLI's");
        written.push(bytes);
        if mode == PairView::Difference {
            let name = bvhscope::app::default_name(h.state(), "counts");
            assert!(name.ends_with("midpoint-vs-sah-visits-difference.csv"), "{name}");
            let app_csv = temp_file("app-pair.csv", "");
            h.state_mut().act(Action::Picked(Pick::SaveCounts, app_csv.clone()));
            let text = std::fs::read_to_string(&app_csv).unwrap();
            assert!(text.starts_with("x,y,a,b,b_minus_a\n"), "{}", &text[..40.min(text.len())]);
            assert_eq!(text, std::fs::read_to_string(&cli_csv).unwrap(), "the app's pair counts are the CLI's");
        }
    }
    // The halves and the difference are different pictures (the export follows the screen).
    assert!(written[0] != written[1] && written[0] != written[2] && written[1] != written[2]);
}

/// The docked layout: with the Ray, Tree, Node and Compare views all open, each is a tile
/// beside or below the image, none over it; a view closed hides its tile and the image takes
/// the room back.
#[test]
fn every_view_is_a_tile_beside_the_image_never_over_it() {
    use bvhscope::app::Pane;
    let mut h = midpoint_against_sah();
    let act = |h: &mut egui_kittest::Harness<'_, BvhscopeApp>, a: Action| h.state_mut().act(a);
    act(&mut h, Action::ShowTree(true));
    act(&mut h, Action::SelectNode(0));
    act(&mut h, Action::ShowRayWindow);
    h.run_steps(4);
    let rect = |h: &egui_kittest::Harness<'_, BvhscopeApp>, p: Pane| {
        let layout = h.state().dock.as_ref().unwrap();
        let id = layout.tiles.find_pane(&p).unwrap();
        layout.is_visible_in_layout(id).then(|| layout.tiles.rect(id)).flatten()
    };
    let image = rect(&h, Pane::Image).expect("the image's tile");
    for p in [Pane::Controls, Pane::Statistics, Pane::Ray, Pane::Node, Pane::Tree, Pane::Compare] {
        let r = rect(&h, p).unwrap_or_else(|| panic!("{p:?} is open: its tile is shown"));
        let shared = r.intersect(image);
        assert!(shared.width() <= 1.0 || shared.height() <= 1.0, "{p:?} {r:?} over the image {image:?}");
    }
    assert!(image.expand(1.0).contains_rect(h.state().viewport_rect), "the viewport is the image's tile");
    // Closed: the tile goes, the image grows.
    act(&mut h, Action::ShowTree(false));
    act(&mut h, Action::Compare(false));
    h.run_steps(4);
    assert!(rect(&h, Pane::Tree).is_none() && rect(&h, Pane::Compare).is_none());
    assert!(rect(&h, Pane::Image).unwrap().height() > image.height() + 50.0, "the image takes the room back");
}

/// Presenting: View › Present (F5) draws everything at 150 % (egui's body text, 12.5 points,
/// 18.75 pixels on screen); Ctrl +/− step the scale by 10 %, Ctrl+0 sets it back; the Node view
/// writes every strategy's plane and cost in a table, as `inspect` prints them.
#[test]
fn presenting_draws_everything_larger_and_the_node_view_writes_its_planes_out() {
    let mut h = harness();
    run_until(&mut h, "the first frame", idle);
    h.key_press(egui::Key::F5);
    h.run_steps(3);
    assert!(h.state().settings.present);
    assert_eq!(h.ctx.zoom_factor(), 1.5);
    let body = h.ctx.global_style().text_styles[&egui::TextStyle::Body].size * h.ctx.zoom_factor();
    assert!(body >= 18.0, "body text {body} px");
    h.key_press(egui::Key::F5);
    h.run_steps(2);
    assert_eq!(h.ctx.zoom_factor(), 1.0);
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Plus);
    h.run_steps(2);
    assert!((h.ctx.zoom_factor() - 1.1).abs() < 1e-4, "{}", h.ctx.zoom_factor());
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Num0);
    h.run_steps(2);
    assert_eq!(h.ctx.zoom_factor(), 1.0);
    // The Node view's planes, each strategy's on a row of its own, nothing only on hover.
    h.state_mut().act(Action::Present(true));
    h.state_mut().act(Action::ShowTree(true));
    h.state_mut().act(Action::SelectNode(0));
    run_until(&mut h, "the root's inspection", |a| a.nodes.inspection.as_ref().is_some_and(|i| i.node == 0));
    h.run_steps(3);
    for head in ["n_L", "n_R", "A_L/A", "A_R/A", "Cost"] {
        h.get_by_label(head);
    }
    let ins = h.state().nodes.inspection.clone().unwrap();
    for (_, m) in &ins.markers {
        if let Some(m) = m {
            assert!(h.query_all_by_label(&format!("{:.3}", m.area_left)).count() >= 1);
            assert!(h.query_all_by_label(&format!("{:.3}", m.cost)).count() >= 1, "{}", m.cost);
        }
    }
}

/// Presenting at 1280×720 (480 points tall at 150 %) the View menu is taller than the window:
/// it scrolls, so its last commands (Compare side by side, Present, Size, Reset the layout) can
/// be brought inside the window and clicked with the pointer (issue 59).
#[test]
fn presenting_at_720_px_the_view_menu_reaches_every_command() {
    let mut h = Harness::builder()
        .with_size(egui::vec2(1280.0, 720.0))
        .build_eframe(|cc| BvhscopeApp::new(cc, AppOptions::default()));
    h.state_mut().act(Action::Present(true));
    run_until(&mut h, "the first frame", idle);
    let open_view = |h: &mut Harness<'_, BvhscopeApp>| {
        h.get_by_role_and_label(Role::Button, "View").click();
        h.run_steps(3);
    };
    // The menu's items hang below its button in the accessibility tree (other panels have a
    // "Size" or a "100 %" of their own).
    fn item<'t>(h: &'t Harness<'_, BvhscopeApp>, part: &'t str) -> egui_kittest::Node<'t> {
        h.get_by_role_and_label(Role::Button, "View").get_by_label_contains(part)
    }
    // Scroll `part`'s item into view as a screen reader does; its rectangle, inside the window.
    let shown = |h: &mut Harness<'_, BvhscopeApp>, part: &str| {
        item(h, part).scroll_to_me();
        h.run_steps(3);
        let screen = h.ctx.content_rect();
        let r = item(h, part).rect();
        assert!(screen.contains_rect(r), "{part:?} at {r:?}, outside the window {screen:?}");
        r
    };
    open_view(&mut h);
    let bar = h.get_by_role_and_label(Role::Button, "View").rect();
    let first = bvhscope::render::View::ALL[0].label();
    for part in ["Reset the layout", "Size ", "100 %", "Present (", "Compare side by side", first] {
        let r = shown(&mut h, part);
        assert!(r.min.y >= bar.max.y, "{part:?} at {r:?} over the menu bar's {bar:?}");
    }
    // The pointer reaches them: a click on Compare side by side opens B ...
    shown(&mut h, "Compare side by side");
    item(&h, "Compare side by side").click();
    h.run_steps(3);
    assert!(h.state().compare.on, "Compare side by side clicked");
    // ... and one on Present, near the bottom, ends presenting. Opened again, the menu starts at
    // its top, not where it was scrolled to.
    open_view(&mut h);
    let top = item(&h, first).rect();
    assert!(top.min.y >= bar.max.y && top.max.y <= h.ctx.content_rect().max.y, "{first:?} at {top:?} on opening");
    shown(&mut h, "Present (");
    item(&h, "Present (").click();
    h.run_steps(3);
    assert!(!h.state().settings.present, "Present clicked");
    // At scale 1 the window holds the whole menu: nothing to scroll, its first and last items in
    // view as it opens.
    h.run_steps(3);
    open_view(&mut h);
    let screen = h.ctx.content_rect();
    for part in [first, "Reset the layout"] {
        let r = item(&h, part).rect();
        assert!(screen.contains_rect(r) && r.min.y >= bar.max.y, "{part:?} at {r:?} with nothing scrolled");
    }
}
