//! Keyboard shortcuts: one table, used both to handle keys and to list them in the Help window.

use super::action::Action;
use crate::app::views::NodeStep;
use egui::{Key, KeyboardShortcut, Modifiers};

pub const SHORTCUTS: &[(KeyboardShortcut, Action, &str)] = &[
    (KeyboardShortcut::new(Modifiers::COMMAND, Key::O), Action::Open, "Open a mesh (file dialog)"),
    (KeyboardShortcut::new(Modifiers::COMMAND, Key::L), Action::OpenPath, "Open a mesh by typing its path"),
    (KeyboardShortcut::new(Modifiers::COMMAND, Key::S), Action::SavePng, "Save the view as PNG"),
    (KeyboardShortcut::new(Modifiers::COMMAND, Key::E), Action::ExportStats, "Export the statistics (CSV / JSON)"),
    (KeyboardShortcut::new(Modifiers::NONE, Key::F), Action::FrameMesh, "Frame the mesh"),
    (KeyboardShortcut::new(Modifiers::NONE, Key::R), Action::ResetView, "Reset the camera"),
    (KeyboardShortcut::new(Modifiers::NONE, Key::Num1), Action::View(0), "Normals view"),
    (KeyboardShortcut::new(Modifiers::NONE, Key::Num2), Action::View(1), "Depth view"),
    (KeyboardShortcut::new(Modifiers::NONE, Key::Num3), Action::View(2), "Heatmap: nodes visited"),
    (KeyboardShortcut::new(Modifiers::NONE, Key::Num4), Action::View(3), "Heatmap: triangle tests"),
    (KeyboardShortcut::new(Modifiers::NONE, Key::Num5), Action::View(4), "Heatmap: combined cost"),
    (KeyboardShortcut::new(Modifiers::NONE, Key::B), Action::ToggleBoxes, "Show / hide node boxes"),
    (KeyboardShortcut::new(Modifiers::NONE, Key::CloseBracket), Action::DepthUp, "Boxes one level deeper"),
    (KeyboardShortcut::new(Modifiers::NONE, Key::OpenBracket), Action::DepthDown, "Boxes one level shallower"),
    (KeyboardShortcut::new(Modifiers::NONE, Key::S), Action::NextStrategy, "Next split strategy"),
    (KeyboardShortcut::new(Modifiers::NONE, Key::C), Action::NextColormap, "Next colour map"),
    (
        KeyboardShortcut::new(Modifiers::ALT, Key::ArrowUp),
        Action::NodeStep(NodeStep::Parent),
        "Node: select the parent",
    ),
    (
        KeyboardShortcut::new(Modifiers::ALT, Key::ArrowLeft),
        Action::NodeStep(NodeStep::Left),
        "Node: select the left child",
    ),
    (
        KeyboardShortcut::new(Modifiers::ALT, Key::ArrowRight),
        Action::NodeStep(NodeStep::Right),
        "Node: select the right child",
    ),
    (
        KeyboardShortcut::new(Modifiers::ALT, Key::ArrowDown),
        Action::NodeStep(NodeStep::Sibling),
        "Node: select the sibling",
    ),
    (
        KeyboardShortcut::new(Modifiers::COMMAND.plus(Modifiers::SHIFT), Key::C),
        Action::CopyTraceCommand,
        "Copy the pinned ray's trace command",
    ),
    (
        KeyboardShortcut::new(Modifiers::NONE, Key::F5),
        Action::TogglePresent,
        "Present: large text and plots (again: off)",
    ),
    (KeyboardShortcut::new(Modifiers::COMMAND, Key::Plus), Action::UiScaleBy(1), "Larger (10 % a step)"),
    (KeyboardShortcut::new(Modifiers::COMMAND, Key::Equals), Action::UiScaleBy(1), "Larger (as Ctrl++)"),
    (KeyboardShortcut::new(Modifiers::COMMAND, Key::Minus), Action::UiScaleBy(-1), "Smaller"),
    (KeyboardShortcut::new(Modifiers::COMMAND, Key::Num0), Action::UiScale(1.0), "Normal size"),
    (KeyboardShortcut::new(Modifiers::NONE, Key::F1), Action::Help, "This help"),
];

/// Mouse controls, listed in the Help window.
pub const MOUSE: &[(&str, &str)] = &[
    ("Left drag", "Orbit"),
    ("Right or middle drag", "Pan"),
    ("Wheel", "Zoom"),
    ("Hover", "Exact counts of the pixel's ray"),
    (
        "Ctrl+click",
        "Pin the pixel's ray: its traversal step by step (Ray window); with the Ray window open, a plain click too",
    ),
    (
        "Shift+click",
        "Select the node of a drawn box's edge, else the leaf the pixel's ray hits (Tree and Node windows)",
    ),
    ("Drop a mesh or scene", "Open it (.obj, .ply, .off, .stl, .gltf, .glb, a scene's .json)"),
];

/// A shortcut as the Help window and the menus show it: modifiers by name, keys by their symbol
/// (`]`, not egui's `CloseBracket`).
pub fn shortcut_text(ctx: &egui::Context, s: &KeyboardShortcut) -> String {
    let is_mac = ctx.os().is_mac();
    let names = if is_mac { egui::ModifierNames::SYMBOLS } else { egui::ModifierNames::NAMES };
    let mut text = names.format(&s.modifiers, is_mac);
    if !text.is_empty() {
        text += names.concat;
    }
    // The arrows' symbols (⏶ …) are not in egui's default fonts: name them.
    let key = s.logical_key.symbol_or_name();
    text + if key.is_ascii() { key } else { s.logical_key.name() }
}

/// The actions whose keys were pressed this frame. Single-key shortcuts are ignored while a text
/// field has the keyboard.
pub fn pressed(ctx: &egui::Context) -> Vec<Action> {
    let typing = ctx.egui_wants_keyboard_input();
    ctx.input_mut(|i| {
        SHORTCUTS
            .iter()
            .filter(|(s, _, _)| !(typing && s.modifiers == Modifiers::NONE))
            .filter(|(s, _, _)| i.consume_shortcut(s))
            .map(|(_, a, _)| a.clone())
            .collect()
    })
}

/// A lesson's keys: what a presentation clicker sends (PageDown / PageUp; some send the arrows).
/// With a lesson open and no text field taking the keyboard they step the lesson before anything
/// else sees them: plain arrows and the page keys are bound to nothing else (the Node view's
/// steps are Alt+arrows, which stay its own), and a slider or scroll area with the keyboard does
/// not take them from the lesson. Only the key with no modifier counts.
pub const LESSON_KEYS: &[(Key, bool)] =
    &[(Key::PageDown, true), (Key::ArrowRight, true), (Key::PageUp, false), (Key::ArrowLeft, false)];

/// The lesson's keys as the Help window lists them.
pub const LESSON_HELP: &[(&str, &str)] = &[
    ("PageDown, Right", "Lesson: the step's answer, then the next step"),
    ("PageUp, Left", "Lesson: the previous step (or hide the answer)"),
];

/// The lesson's steps asked for this frame (`LESSON_KEYS`); the keys are taken from the input so
/// that nothing else acts on them. Call only while a lesson is open.
pub fn lesson_keys(ctx: &egui::Context) -> Vec<Action> {
    if ctx.egui_wants_keyboard_input() {
        return Vec::new();
    }
    let mut out = Vec::new();
    ctx.input_mut(|i| {
        i.events.retain(|e| {
            let egui::Event::Key { key, pressed: true, repeat: false, modifiers, .. } = e else { return true };
            let Some((_, next)) = LESSON_KEYS.iter().find(|(k, _)| k == key).filter(|_| modifiers.is_none()) else {
                return true;
            };
            out.push(if *next { Action::LessonNext } else { Action::LessonPrevious });
            false
        });
    });
    out
}
