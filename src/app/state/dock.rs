//! The docked layout (egui_tiles): the image, the two panels and every explain view as tiles
//! beside and below one another, never over the image (floating windows covered most of it at
//! 1280×720). A view's tile shows while the view is open; the arrangement, which the user may
//! change by dragging a tile's tab, is saved with the settings.

use egui_tiles::{Container, LinearDir, Tile, TileId, Tiles, Tree};

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
    // The Ray view's step list shows eight rows under its controls at 1280×720 (issue 59).
    share(&mut tiles, right_column, &[(right[0], 1.0), (right[1], 2.0), (right[2], 1.6)]);
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
/// the front of its tabs, unless the image shares those tabs (it would hide the image). `slides`:
/// a lesson presented, where the Build and view panel's sliders are for the teacher, not the
/// room: its tile is hidden and the image takes its room (it comes back when presenting ends).
pub fn show_open(layout: &mut Layout, slides: bool, open: impl Fn(Pane) -> bool) {
    for pane in Pane::ALL {
        let Some(id) = layout.tiles.find_pane(&pane) else { continue };
        let now = (pane.always_open() && !(slides && pane == Pane::Controls)) || open(pane);
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

/// Presenting (F5): the layout as it was before, restored when presenting ends, and the open
/// views it was last fitted for.
pub struct Presenting {
    before: Layout,
    fitted_for: Vec<Pane>,
}

impl Presenting {
    /// The layout presenting started from.
    pub fn before(&self) -> &Layout {
        &self.before
    }
}

/// Of a row, the share of the width an open explain view gets presenting, and of a column the
/// share of the height: at 150 % a 1280-px screen is 853 points wide, and the Node view's table
/// and plots, the Ray view's steps, need about half of it to be read from the back row.
const PRESENT_WIDTH: f32 = 0.45;
const PRESENT_HEIGHT: f32 = 0.45;

/// Presenting or not, with the explain views `open`: on starting to present, and whenever
/// another view opens or closes while presenting, each open view's tile is given the side of the
/// screen it needs (its row and column widened, its share raised in each container holding it);
/// presenting ended, the layout before it comes back (what was dragged meanwhile is not kept).
pub fn present(layout: &mut Layout, was: Option<Presenting>, on: bool, open: &[Pane]) -> Option<Presenting> {
    match (was, on) {
        (None, false) => None,
        (Some(p), false) => {
            *layout = p.before;
            None
        }
        (None, true) => {
            let before = layout.clone();
            fit(layout, open);
            Some(Presenting { before, fitted_for: open.to_vec() })
        }
        (Some(p), true) if p.fitted_for != open => {
            fit(layout, open);
            Some(Presenting { fitted_for: open.to_vec(), ..p })
        }
        (p, true) => p,
    }
}

/// Raise each open view's share, and its ancestors', to `PRESENT_WIDTH` of its row and
/// `PRESENT_HEIGHT` of its column (never lowered), counting only the siblings on screen.
fn fit(layout: &mut Layout, open: &[Pane]) {
    let tiles = &mut layout.tiles;
    for &pane in open {
        let Some(mut child) = tiles.find_pane(&pane) else { continue };
        while let Some(parent) = tiles.parent_of(child) {
            let others = match tiles.get(parent) {
                Some(Tile::Container(Container::Linear(l))) => {
                    let want = if l.dir == LinearDir::Horizontal { PRESENT_WIDTH } else { PRESENT_HEIGHT };
                    let others: f32 = l
                        .children
                        .iter()
                        .filter(|&&c| c != child && on_screen(tiles, c, open))
                        .map(|&c| l.shares[c])
                        .sum();
                    Some(want * others / (1.0 - want))
                }
                _ => None,
            };
            if let (Some(share), Some(Tile::Container(Container::Linear(l)))) = (others, tiles.get_mut(parent)) {
                if l.shares[child] < share {
                    l.shares.set_share(child, share);
                }
            }
            child = parent;
        }
    }
}

/// Whether a tile will be on screen: a pane always there or open, a container holding one.
fn on_screen(tiles: &Tiles<Pane>, id: TileId, open: &[Pane]) -> bool {
    match tiles.get(id) {
        Some(Tile::Pane(p)) => p.always_open() || open.contains(p),
        Some(Tile::Container(c)) => c.children().any(|&c| on_screen(tiles, c, open)),
        None => false,
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
        show_open(&mut layout, false, |p| p == Pane::Ray);
        let visible = |l: &Layout, p: Pane| l.tiles.is_visible(l.tiles.find_pane(&p).unwrap());
        assert!(visible(&layout, Pane::Image) && visible(&layout, Pane::Ray) && visible(&layout, Pane::Statistics));
        assert!(!visible(&layout, Pane::Node) && !visible(&layout, Pane::Grade));
    }

    #[test]
    fn presenting_gives_an_open_view_its_side_and_gives_the_layout_back() {
        let mut layout = default_layout();
        let share_of = |l: &Layout, p: Pane| {
            let id = l.tiles.find_pane(&p).unwrap();
            let mut child = id;
            // The right column's share of the whole row.
            while let Some(parent) = l.tiles.parent_of(child) {
                if l.root == Some(parent) {
                    if let Some(Tile::Container(Container::Linear(row))) = l.tiles.get(parent) {
                        let total: f32 = row.children.iter().map(|&c| row.shares[c]).sum();
                        return row.shares[child] / total;
                    }
                }
                child = parent;
            }
            unreachable!()
        };
        let before = share_of(&layout, Pane::Ray);
        assert!(before < 0.3, "{before}");
        let p = present(&mut layout, None, true, &[Pane::Ray]);
        let presenting = share_of(&layout, Pane::Ray);
        assert!((presenting - PRESENT_WIDTH).abs() < 0.01, "{presenting}");
        let p = present(&mut layout, p, false, &[Pane::Ray]);
        assert!(p.is_none());
        assert_eq!(share_of(&layout, Pane::Ray), before, "the layout as it was");
    }
}
