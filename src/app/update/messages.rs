//! What the app says in its messages on the status bar (`panels::status` draws
//! them): one per topic, the old scene's cleared when a new one opens (`events.rs`).

use crate::app::state::{BvhscopeApp, Message, MessageKind};
use std::time::Instant;

/// Messages kept; the status bar shows the newest, the others behind its "N earlier" button.
const MESSAGES_KEPT: usize = 8;

impl BvhscopeApp {
    /// Show a message. One per topic: a message whose text is already shown, or of the same kind
    /// about the same file or thing (the words before its first ": "), replaces that one, so the
    /// same warning never piles up.
    pub fn message(&mut self, kind: MessageKind, text: impl Into<String>) {
        let text = text.into();
        let topic = |t: &str| t.split_once(": ").map_or(t.to_string(), |(head, _)| head.to_string());
        let this = topic(&text);
        self.messages.retain(|m| !(m.text == text || (m.kind == kind && topic(&m.text) == this)));
        self.messages.push(Message { kind, text, at: Instant::now() });
        if self.messages.len() > MESSAGES_KEPT {
            self.messages.remove(0);
        }
    }
}
