//! The legend beside or below the image, never over it, folding to its colour bar; messages on
//! the status bar, not over the image (issue 59, point 1). Every `run_until` also checks that the
//! legend and the image never overlap (`support::assert_legend_apart`), in every layout any test
//! opens. A module of the `app_ui` test binary (`app.rs`).

use super::*;

fn at_720() -> Harness<'static, BvhscopeApp> {
    Harness::builder()
        .with_size(egui::vec2(1280.0, 720.0))
        .build_eframe(|cc| BvhscopeApp::new(cc, AppOptions::default()))
}

fn heatmap(h: &mut Harness<'_, BvhscopeApp>) {
    h.state_mut().act(Action::View(2));
    run_until(h, "the heatmap", |a| idle(a) && a.shown.as_ref().is_some_and(|s| s.legend.is_some()));
    h.run_steps(3);
}

/// The legend's title and histogram lie in the image's tile, outside the image: beside it or
/// below it, in the image tile's own part.
fn legend_outside_the_image(h: &Harness<'_, BvhscopeApp>) -> egui::Rect {
    let image = h.state().image_rect;
    let title = h.get_by_label_contains("Legend: ").rect();
    let histogram = h.get_by_label("Histogram of the heatmap").rect();
    for r in [title, histogram] {
        let both = r.intersect(image);
        assert!(both.width() <= 0.5 || both.height() <= 0.5, "{r:?} over the image {image:?}");
        assert!(r.min.x >= image.max.x - 0.5 || r.min.y >= image.max.y - 0.5, "{r:?} beside or below {image:?}");
    }
    title.union(histogram)
}

#[test]
fn the_legend_is_beside_or_below_the_image_and_folds_to_a_bar() {
    let mut h = harness();
    run_until(&mut h, "the first frame", idle);
    let plain = h.state().image_rect;
    heatmap(&mut h);
    let legend = legend_outside_the_image(&h);
    let image = h.state().image_rect;
    assert!(image.area() < plain.area(), "the legend took its part of the tile: {image:?} in {plain:?}");
    // Its lowest line above the status bar.
    let status = h
        .get_all_by_label_contains("last full frame")
        .map(|n| n.rect())
        .max_by(|a, b| a.min.y.total_cmp(&b.min.y))
        .unwrap();
    assert!(legend.max.y < status.min.y, "the legend {legend:?} above the status bar {status:?}");
    // Folded: the colour bar and its ends only, and the image takes the room back.
    h.get_by_label("Fold").click();
    h.run_steps(3);
    assert!(h.state().settings.legend_folded);
    assert!(h.query_by_label("Histogram of the heatmap").is_none(), "folded");
    run_until(&mut h, "the image at its new size", idle);
    assert!(h.state().image_rect.area() > image.area(), "{:?} larger than {image:?}", h.state().image_rect);
    let unfold =
        h.query_by_label("Show").or_else(|| h.query_by_label("Show the legend")).expect("the unfold button").rect();
    let both = unfold.intersect(h.state().image_rect);
    assert!(both.width() <= 0.5 || both.height() <= 0.5, "the folded bar beside the image");
    h.query_by_label("Show").or_else(|| h.query_by_label("Show the legend")).unwrap().click();
    h.run_steps(3);
    assert!(!h.state().settings.legend_folded);
    run_until(&mut h, "the legend again", idle);
    legend_outside_the_image(&h);
}

/// Presenting at 1280×720, in a narrow window, with Compare and the Ray view open: the legend is
/// never over the image.
#[test]
fn presenting_and_beside_explain_views_the_legend_stays_off_the_image() {
    let mut h = at_720();
    h.state_mut().act(Action::Present(true));
    run_until(&mut h, "the first frame", idle);
    heatmap(&mut h);
    legend_outside_the_image(&h);
    h.state_mut().act(Action::ShowRayWindow);
    h.run_steps(4);
    run_until(&mut h, "the frame beside the Ray view", idle);
    legend_outside_the_image(&h);
    h.state_mut().act(Action::Present(false));
    h.state_mut().act(Action::Compare(true));
    run_until(&mut h, "B", pair_shown);
    let image = h.state().image_rect;
    let title = h.get_by_label_contains("Legend: ").rect();
    let both = title.intersect(image);
    assert!(both.width() <= 0.5 || both.height() <= 0.5, "the pair's legend {title:?} off the image {image:?}");
    // A tall narrow window: below the image.
    h.set_size(egui::vec2(720.0, 900.0));
    h.run_steps(4);
    run_until(&mut h, "the narrow frame", pair_shown);
    let image = h.state().image_rect;
    let title = h.get_by_label_contains("Legend: ").rect();
    assert!(title.min.y >= image.max.y - 0.5, "below the image in a tall tile: {title:?} under {image:?}");
}

/// A message is on the status bar, below the image and never over it, and the image keeps its
/// size while messages come and go.
#[test]
fn messages_are_on_the_status_bar_not_over_the_image() {
    let mut h = harness();
    run_until(&mut h, "the first frame", idle);
    let image = h.state().image_rect;
    h.state_mut().message(MessageKind::Error, "broken.obj: line 3: a face names vertex 9 of 4");
    h.state_mut().message(MessageKind::Info, "Saved a.png");
    h.run_steps(3);
    let m = h.get_by_label_contains("Note: Saved a.png").rect();
    assert!(m.min.y >= image.max.y, "the message {m:?} below the image {image:?}");
    assert_eq!(h.state().image_rect, image, "a message does not change the image's size");
    // The earlier one is behind its button, whole.
    h.get_by_label("1 earlier").click();
    h.run_steps(2);
    h.get_by_label_contains("Error: broken.obj: line 3: a face names vertex 9 of 4");
}

/// F5 gives the open explain view the side of the screen it needs (about half the width), and
/// ending presenting gives the layout back.
#[test]
fn presenting_gives_the_open_explain_view_its_side_of_the_screen() {
    use bvhscope::app::Pane;
    let tile = |h: &Harness<'_, BvhscopeApp>, p: Pane| {
        let layout = h.state().dock.as_ref().unwrap();
        layout.tiles.rect(layout.tiles.find_pane(&p).unwrap()).unwrap()
    };
    let mut h = at_720();
    run_until(&mut h, "the first frame", idle);
    h.state_mut().act(Action::ShowRayWindow);
    h.run_steps(4);
    let before = tile(&h, Pane::Ray);
    let screen = h.ctx.content_rect().width();
    assert!(before.width() < 0.3 * screen, "{before:?} of {screen}");
    h.state_mut().act(Action::Present(true));
    h.run_steps(4);
    let screen = h.ctx.content_rect().width();
    let presenting = tile(&h, Pane::Ray);
    assert!(presenting.width() > 0.4 * screen, "presenting, the Ray view {presenting:?} of {screen} points");
    h.state_mut().act(Action::Present(false));
    h.run_steps(4);
    let after = tile(&h, Pane::Ray);
    assert!((after.width() - before.width()).abs() < 2.0, "the layout back: {after:?}, was {before:?}");
}
