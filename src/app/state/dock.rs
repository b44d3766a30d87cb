//! The docked layout (egui_tiles): the image, the two panels and every explain view as tiles
//! beside and below one another, never over the image (floating windows covered most of it at
//! 1280×720). A view's tile shows while the view is open; the arrangement, which the user may
//! change by dragging a tile's tab, is saved with the settings.

use egui_tiles::{Container, Tile, TileId, Tiles, Tree};

/// Where the docked layout is saved (beside the settings, under `eframe::APP_KEY`).
pub const DOCK_KEY: &str = "bvhscope-dock";

/// What a tile holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub enum Pane {
    Image,
    /// The Build and View panels.
    Controls,
    Statistics,
    Ray,
    Node,
    Tree,
    Replay,
    Compare,
    Imported,
    Grade,
}

impl Pane {
    pub const ALL: [Pane; 10] = [
        Pane::Image,
        Pane::Controls,
        Pane::Statistics,
        Pane::Ray,
        Pane::Node,
        Pane::Tree,
        Pane::Replay,
        Pane::Compare,
        Pane::Imported,
        Pane::Grade,
    ];

    /// The tile's tab.
    pub fn title(self) -> &'static str {
        match self {
            Pane::Image => "Image",
            Pane::Controls => "Build and view",
            Pane::Statistics => "Statistics",
            Pane::Ray => "Ray",
            Pane::Node => "Node",
            Pane::Tree => "Tree",
            Pane::Replay => "Replay",
            Pane::Compare => "Compare",
            Pane::Imported => "Imported BVH",
            Pane::Grade => "Grade report",
        }
    }

    /// The image and the two panels are always there; the explain views while open.
    pub fn always_open(self) -> bool {
        matches!(self, Pane::Image | Pane::Controls | Pane::Statistics)
    }
}

pub type Layout = Tree<Pane>;

/// The layout of a fresh start: the controls on the left; the image in the middle, with the
/// Tree, Replay, Compare, Imported BVH and Grade report views side by side below it; the
/// statistics, Ray and Node views stacked on the right (each as tall as the others open there).
pub fn default_layout() -> Layout {
    let mut tiles = Tiles::default();
    let controls = tiles.insert_pane(Pane::Controls);
    let image = tiles.insert_pane(Pane::Image);
    let below: Vec<TileId> =
        [Pane::Tree, Pane::Replay, Pane::Compare, Pane::Imported, Pane::Grade].map(|p| tiles.insert_pane(p)).into();
    let below = tiles.insert_horizontal_tile(below);
    let center = tiles.insert_vertical_tile(vec![image, below]);
    share(&mut tiles, center, &[(image, 2.6), (below, 1.0)]);
    let right = [Pane::Statistics, Pane::Ray, Pane::Node].map(|p| tiles.insert_pane(p));
    let right_column = tiles.insert_vertical_tile(right.into());
    share(&mut tiles, right_column, &[(right[0], 1.0), (right[1], 1.3), (right[2], 1.6)]);
    let root = tiles.insert_horizontal_tile(vec![controls, center, right_column]);
    share(&mut tiles, root, &[(controls, 290.0), (center, 770.0), (right_column, 340.0)]);
    Tree::new(egui::Id::unique("bvhscope-dock"), root, tiles)
}

fn share(tiles: &mut Tiles<Pane>, container: TileId, shares: &[(TileId, f32)]) {
    if let Some(Tile::Container(Container::Linear(l))) = tiles.get_mut(container) {
        for &(id, s) in shares {
            l.shares.set_share(id, s);
        }
    }
}

/// A saved layout is used when it holds every pane exactly once (one saved by an older version
/// may lack a view added since); else the default.
pub fn valid(layout: &Layout) -> bool {
    let panes: Vec<Pane> =
        layout.tiles.tiles().filter_map(|t| if let Tile::Pane(p) = t { Some(*p) } else { None }).collect();
    layout.root.is_some() && panes.len() == Pane::ALL.len() && Pane::ALL.iter().all(|p| panes.contains(p))
}

/// Show the open views' tiles and hide the closed ones'. A view opened just now is brought to
/// the front of its tabs, unless the image shares those tabs (it would hide the image).
pub fn show_open(layout: &mut Layout, open: impl Fn(Pane) -> bool) {
    for pane in Pane::ALL {
        let Some(id) = layout.tiles.find_pane(&pane) else { continue };
        let now = pane.always_open() || open(pane);
        let was = layout.tiles.is_visible(id);
        layout.tiles.set_visible(id, now);
        if now && !was {
            let parent = layout.tiles.parent_of(id);
            let tabs_with_image = parent.is_some_and(|p| {
                matches!(layout.tiles.get(p), Some(Tile::Container(Container::Tabs(t)))
                    if t.children.iter().any(|c| layout.tiles.get_pane(c) == Some(&Pane::Image)))
            });
            if !tabs_with_image {
                layout.make_active(|tile, _| tile == id);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_layout_holds_every_pane_once_and_a_broken_one_is_refused() {
        let layout = default_layout();
        assert!(valid(&layout));
        let mut lacking = default_layout();
        let id = lacking.tiles.find_pane(&Pane::Grade).unwrap();
        lacking.tiles.remove(id);
        assert!(!valid(&lacking));
    }

    #[test]
    fn closed_views_are_hidden_and_the_image_never() {
        let mut layout = default_layout();
        show_open(&mut layout, |p| p == Pane::Ray);
        let visible = |l: &Layout, p: Pane| l.tiles.is_visible(l.tiles.find_pane(&p).unwrap());
        assert!(visible(&layout, Pane::Image) && visible(&layout, Pane::Ray) && visible(&layout, Pane::Statistics));
        assert!(!visible(&layout, Pane::Node) && !visible(&layout, Pane::Grade));
    }
}
