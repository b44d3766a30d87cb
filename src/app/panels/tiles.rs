//! The docked layout's contents: every explain view registered once in `VIEWS` (whether it is
//! open, its contents, what closing it asks for), and the egui_tiles behaviour that draws each
//! tile: the image, the Build and View panels, the statistics, the views.

use super::layout::fixed_width;
use super::{build, compare, grade, imported, node, ray, replay, stats, tree, view, viewport};
use crate::app::state::dock::{self, Pane};
use crate::app::state::{Action, Actions, BvhscopeApp};

/// An explain view as the layout knows it.
pub struct View {
    pub pane: Pane,
    pub is_open: fn(&BvhscopeApp) -> bool,
    pub ui: fn(&BvhscopeApp, &mut egui::Ui, &mut Actions),
    pub close: fn() -> Action,
}

/// Every explain view, once: the layout shows a view's tile while it is open.
pub const VIEWS: [View; 7] = [
    View { pane: Pane::Ray, is_open: ray::is_open, ui: ray::ui, close: ray::close },
    View { pane: Pane::Node, is_open: node::is_open, ui: node::ui, close: node::close },
    View { pane: Pane::Tree, is_open: tree::is_open, ui: tree::ui, close: tree::close },
    View { pane: Pane::Replay, is_open: replay::is_open, ui: replay::ui, close: replay::close },
    View { pane: Pane::Compare, is_open: compare::is_open, ui: compare::ui, close: compare::close },
    View { pane: Pane::Imported, is_open: imported::is_open, ui: imported::ui, close: imported::close },
    View { pane: Pane::Grade, is_open: grade::is_open, ui: grade::ui, close: grade::close },
];

fn view_of(pane: Pane) -> Option<&'static View> {
    VIEWS.iter().find(|v| v.pane == pane)
}

/// Lay out the tiles in `ui` (all of it): the open views shown, the closed ones hidden.
pub fn show(app: &mut BvhscopeApp, ui: &mut egui::Ui, out: &mut Actions) {
    let mut layout = app.dock.take().unwrap_or_else(dock::default_layout);
    let open: Vec<Pane> = VIEWS.iter().filter(|v| (v.is_open)(app)).map(|v| v.pane).collect();
    app.dock_presenting = dock::present(&mut layout, app.dock_presenting.take(), app.settings.present, &open);
    let slides = app.settings.present && app.lesson.is_some();
    dock::show_open(&mut layout, slides, |pane| view_of(pane).is_some_and(|v| (v.is_open)(app)));
    let mut tiles = Tiles { app, out };
    layout.ui(&mut tiles, ui);
    app.dock = Some(layout);
}

/// A panel's or view's tile: the panels' background (the tiles sit on a frameless central
/// panel), a margin round its contents.
fn margin(ui: &mut egui::Ui, add: impl FnOnce(&mut egui::Ui)) {
    ui.painter().rect_filled(ui.max_rect(), 0.0, ui.visuals().panel_fill);
    egui::Frame::new().inner_margin(egui::Margin::symmetric(6, 4)).show(ui, add);
}

struct Tiles<'a> {
    app: &'a BvhscopeApp,
    out: &'a mut Actions,
}

impl egui_tiles::Behavior<Pane> for Tiles<'_> {
    fn pane_ui(&mut self, ui: &mut egui::Ui, _tile: egui_tiles::TileId, pane: &mut Pane) -> egui_tiles::UiResponse {
        let (app, out) = (self.app, &mut *self.out);
        match *pane {
            Pane::Image => {
                ui.painter().rect_filled(ui.max_rect(), 0.0, egui::Color32::from_gray(12));
                viewport::show(app, ui, out);
            }
            // The panels keep the width of their tile: their contents wrap, scroll or clip
            // inside it and never widen it, so the image, and with it the camera's aspect,
            // stays as it is when the figures change.
            Pane::Controls => margin(ui, |ui| {
                fixed_width(ui, |ui| {
                    build::show(app, ui, out);
                    ui.separator();
                    view::show(app, ui, out);
                })
            }),
            Pane::Statistics => margin(ui, |ui| fixed_width(ui, |ui| stats::show(app, ui, out))),
            // A view scrolls inside its tile (a long list of steps or a wide table stays in it).
            pane => {
                if let Some(v) = view_of(pane) {
                    margin(ui, |ui| {
                        // Compare's bars take room of their own: floating, one covered its mode
                        // buttons on hover when presenting (issue 59).
                        if pane == Pane::Compare {
                            ui.spacing_mut().scroll = egui::style::ScrollStyle::solid();
                        }
                        egui::ScrollArea::both()
                            .id_salt(pane.title())
                            .auto_shrink([false, false])
                            .show(ui, |ui| (v.ui)(app, ui, out));
                    });
                }
            }
        }
        egui_tiles::UiResponse::None
    }

    fn tab_title_for_pane(&mut self, pane: &Pane) -> egui::WidgetText {
        pane.title().into()
    }

    fn is_tab_closable(&self, tiles: &egui_tiles::Tiles<Pane>, tile: egui_tiles::TileId) -> bool {
        tiles.get_pane(&tile).is_some_and(|p| !p.always_open())
    }

    /// Closing a view's tab closes the view (its tile stays in the layout, hidden, for the next
    /// time it opens).
    fn on_tab_close(&mut self, tiles: &mut egui_tiles::Tiles<Pane>, tile: egui_tiles::TileId) -> bool {
        if let Some(v) = tiles.get_pane(&tile).and_then(|p| view_of(*p)) {
            self.out.push((v.close)());
        }
        false
    }

    fn simplification_options(&self) -> egui_tiles::SimplificationOptions {
        // Every tile has a tab: its title, its close button, and the handle to drag it by.
        egui_tiles::SimplificationOptions { all_panes_must_have_tabs: true, ..Default::default() }
    }
}
