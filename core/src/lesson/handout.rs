//! A lesson's handout: one HTML page a student keeps, self-contained (the pictures inline), each
//! step's picture with its caption, question and answer (folded until clicked), the command that
//! draws the picture and the command-line twin of the view the app opens at that step.

use super::{spans, Lesson, Show, Span};
use crate::explain::grade::html::{base64, esc};

/// What the handout shows of one step besides its caption.
pub struct HandoutStep {
    /// The picture, as `render` wrote it.
    pub png: Vec<u8>,
    /// The `bvhscope render` command that wrote it.
    pub command: String,
    /// The explain view's command-line twin, if the step opens one.
    pub explain: Option<String>,
}

/// The page, step by step (`steps` in the lesson's order).
pub fn handout_html(lesson: &Lesson, steps: &[HandoutStep]) -> String {
    let title = if lesson.title.is_empty() { "A bvhscope lesson" } else { &lesson.title };
    let mut o = format!(
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>{t}</title>\n<style>\n{STYLE}</style></head>\n<body>\n<h1>{t}</h1>\n<p class=\"how\">{n} steps. Each picture is drawn by the command under it; open the lesson in bvhscope to step through it (PageDown, PageUp) with every view live.</p>\n",
        t = esc(title),
        n = steps.len()
    );
    for (i, (step, h)) in lesson.steps.iter().zip(steps).enumerate() {
        o += &format!("<section id=\"step-{}\">\n<h2>Step {} of {}</h2>\n", i + 1, i + 1, steps.len());
        o += &format!("<img alt=\"Step {}\" src=\"data:image/png;base64,{}\">\n", i + 1, base64(&h.png));
        o += &format!("<p class=\"caption\">{}</p>\n", caption_html(&step.caption));
        if let Some(q) = &step.question {
            o += &format!("<p class=\"question\"><b>Question.</b> {}</p>\n", caption_html(q));
        }
        if let Some(a) = &step.answer {
            o += &format!("<details><summary>Answer</summary><p>{}</p></details>\n", caption_html(a));
        }
        o += &format!("<pre><code>{}</code></pre>\n", esc(&h.command));
        if let Some(e) = &h.explain {
            let view = match &step.show {
                Some(Show::Ray { .. }) => "the ray's walk, step by step",
                Some(Show::Node(_)) | Some(Show::Tree(_)) => "the node, and where each strategy would split it",
                Some(Show::Replay { .. }) => "the build played back split by split",
                _ => "the view",
            };
            o += &format!("<p class=\"twin\">In a terminal, {view}:</p>\n<pre><code>{}</code></pre>\n", esc(e));
        }
        o += "</section>\n";
    }
    o += "</body></html>\n";
    o
}

/// A caption's text as HTML: escaped, its emphasis and code marked up (`lesson::spans`), its
/// line breaks kept.
pub fn caption_html(text: &str) -> String {
    let mut o = String::new();
    for s in spans(text) {
        match s {
            Span::Plain(t) => o += &esc(&t),
            Span::Emphasis(t) => o += &format!("<em>{}</em>", esc(&t)),
            Span::Code(t) => o += &format!("<code>{}</code>", esc(&t)),
        }
    }
    o.replace('\n', "<br>")
}

const STYLE: &str = "body { font-family: system-ui, sans-serif; max-width: 60rem; margin: 2rem auto; padding: 0 1rem; line-height: 1.45; color: #222; }
section { margin: 2.5rem 0; page-break-inside: avoid; }
img { max-width: 100%; border: 1px solid #ccc; }
.caption { font-size: 1.15rem; }
.how, .twin { color: #555; }
pre { background: #f4f4f4; padding: 0.5rem; overflow-x: auto; white-space: pre-wrap; word-break: break-all; }
code { font-family: ui-monospace, monospace; }
";
