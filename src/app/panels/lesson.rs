//! The lesson's band: a strip of its own across the window above the status line (never over the
//! image), one height whatever the step says, so stepping never resizes the image. It shows
//! "Step k / N", the lesson's title, Previous and Next, the caption with its simple emphasis
//! (`*emphasis*` and `` `code` `` as Markdown writes them, read by `lesson::spans`), the question
//! and, once asked for, the answer. While editing, the title, caption, question and answer are
//! fields to type in.

use crate::app::state::{Action, Actions, BvhscopeApp, LessonState};
use crate::lesson::{spans, Span};
use egui::text::LayoutJob;
use egui::{Align, FontSelection, RichText};

/// The band's height: a row of buttons and the longest step's words (caption, question, answer)
/// laid out in the band's width, so that stepping never resizes the band and with it the image;
/// at most a third of the window (the words scroll past that). While editing: the four fields.
pub fn height(ui: &egui::Ui, l: &LessonState) -> f32 {
    let s = ui.spacing();
    let row = s.interact_size.y + s.item_spacing.y;
    let frame = 2.0 * FRAME_MARGIN + s.item_spacing.y;
    if l.editing {
        // Title, caption (two lines), question, answer.
        return row + 5.0 * row + frame;
    }
    let width = ui.available_width() - 2.0 * FRAME_MARGIN;
    let words = l.lesson.steps.iter().map(|step| words_height(ui, step, width)).fold(caption_size(ui) * 1.3, f32::max);
    (row + words + frame).min(ui.ctx().content_rect().height() / 3.0)
}

/// The band's margin round its contents (the bottom panel's frame's).
pub const FRAME_MARGIN: f32 = 8.0;

/// The height of a step's words in the band, `width` wide.
fn words_height(ui: &egui::Ui, step: &crate::lesson::Step, width: f32) -> f32 {
    let size = caption_size(ui);
    let gap = ui.spacing().item_spacing.y;
    let mut jobs = vec![caption_job(ui, &step.caption, size, width)];
    if let Some(q) = &step.question {
        jobs.push(headed_job(ui, "Question: ", q, size, width));
        // The answer, or the line saying it comes next, in its place.
        jobs.push(headed_job(ui, "Answer: ", step.answer.as_deref().unwrap_or(""), size, width));
    }
    jobs.into_iter().map(|j| ui.painter().layout_job(j).size().y + gap).sum()
}

/// The caption's letter size: a little larger than the panels' text (which presenting enlarges).
fn caption_size(ui: &egui::Ui) -> f32 {
    ui.style().text_styles.get(&egui::TextStyle::Body).map_or(12.5, |f| f.size) * 1.15
}

pub fn show(app: &BvhscopeApp, ui: &mut egui::Ui, out: &mut Actions) {
    let Some(l) = &app.lesson else { return };
    header(l, ui, out);
    let rest = ui.available_height();
    egui::ScrollArea::vertical().id_salt("lesson band").max_height(rest).auto_shrink([false, false]).show(ui, |ui| {
        if l.editing {
            fields(l, ui, out);
        } else {
            words(l, ui);
        }
    });
}

/// Previous, Next, where the lesson is, its title; editing's switch on the right.
fn header(l: &LessonState, ui: &mut egui::Ui, out: &mut Actions) {
    ui.horizontal(|ui| {
        let at_start = l.step == 0 && !l.revealed;
        let previous = ui.add_enabled(!l.is_empty() && !at_start, egui::Button::new("Previous"));
        if previous.on_hover_text("The previous step (PageUp or Left)").clicked() {
            out.push(Action::LessonPrevious);
        }
        let next_text = if l.answer_next() { "Answer" } else { "Next" };
        let more = l.answer_next() || l.step + 1 < l.len();
        let next = ui.add_enabled(more, egui::Button::new(next_text));
        if next.on_hover_text("The answer, then the next step (PageDown or Right)").clicked() {
            out.push(Action::LessonNext);
        }
        let at = if l.is_empty() { "No steps yet".to_string() } else { format!("Step {} / {}", l.step + 1, l.len()) };
        ui.label(RichText::new(at).strong());
        if !l.lesson.title.is_empty() {
            ui.label(RichText::new(format!("· {}", l.lesson.title)).strong());
        }
        if l.applying.is_some() {
            ui.spinner();
        }
        ui.with_layout(egui::Layout::right_to_left(Align::Center), |ui| {
            let mut editing = l.editing;
            if ui.checkbox(&mut editing, "Edit the text").changed() {
                out.push(Action::LessonEditing(editing));
            }
        });
    });
}

/// The step as the room sees it.
fn words(l: &LessonState, ui: &mut egui::Ui) {
    let Some(step) = l.current() else {
        ui.label("Set up the view, then Lesson › Add this view as a step. Type its caption here (Edit the text).");
        return;
    };
    let size = caption_size(ui);
    let width = ui.available_width();
    ui.label(caption_job(ui, &step.caption, size, width));
    if let Some(q) = &step.question {
        ui.label(headed_job(ui, "Question: ", q, size, width));
        match (&step.answer, l.revealed) {
            (Some(a), true) => {
                ui.label(headed_job(ui, "Answer: ", a, size, width));
            }
            (Some(_), false) => {
                ui.label(RichText::new("Next: the answer").size(size).weak());
            }
            (None, _) => {}
        }
    }
}

/// The band's fields: the lesson's title, the step's caption, question and answer.
fn fields(l: &LessonState, ui: &mut egui::Ui, out: &mut Actions) {
    let step = l.current();
    let mut title = l.lesson.title.clone();
    let mut caption = step.map_or(String::new(), |s| s.caption.clone());
    let mut question = step.and_then(|s| s.question.clone()).unwrap_or_default();
    let mut answer = step.and_then(|s| s.answer.clone()).unwrap_or_default();
    let mut changed = false;
    egui::Grid::new("lesson fields").num_columns(2).show(ui, |ui| {
        let label = ui.label("Lesson title");
        let edit = egui::TextEdit::singleline(&mut title).desired_width(f32::INFINITY);
        changed |= ui.add(edit).labelled_by(label.id).changed();
        ui.end_row();
        let label = ui.label("Caption");
        let edit = egui::TextEdit::multiline(&mut caption)
            .desired_rows(2)
            .desired_width(f32::INFINITY)
            .hint_text("What to look at: *emphasis*, `code`");
        changed |= ui.add_enabled(step.is_some(), edit).labelled_by(label.id).changed();
        ui.end_row();
        let label = ui.label("Question");
        let edit = egui::TextEdit::singleline(&mut question).desired_width(f32::INFINITY).hint_text("(none)");
        changed |= ui.add_enabled(step.is_some(), edit).labelled_by(label.id).changed();
        ui.end_row();
        let label = ui.label("Answer");
        let edit = egui::TextEdit::singleline(&mut answer).desired_width(f32::INFINITY).hint_text("(shown on Next)");
        let has_question = !question.trim().is_empty();
        changed |= ui.add_enabled(step.is_some() && has_question, edit).labelled_by(label.id).changed();
        ui.end_row();
    });
    if changed {
        out.push(Action::LessonText { title, caption, question, answer });
    }
}

/// A caption laid out with its emphasis, `width` wide.
fn caption_job(ui: &egui::Ui, text: &str, size: f32, width: f32) -> LayoutJob {
    let mut job = LayoutJob::default();
    append(&mut job, ui, text, size);
    job.wrap.max_width = width;
    job
}

/// `head` in bold, then `text` with its emphasis, `width` wide.
fn headed_job(ui: &egui::Ui, head: &str, text: &str, size: f32, width: f32) -> LayoutJob {
    let mut job = LayoutJob::default();
    // The question's head in the warning colour, the answer's in green: told apart at a glance.
    let color = if head.starts_with('Q') { ui.visuals().warn_fg_color } else { egui::Color32::from_rgb(120, 210, 120) };
    let head = RichText::new(head).size(size).strong().color(color);
    head.append_to(&mut job, ui.style(), FontSelection::Default, Align::Min);
    append(&mut job, ui, text, size);
    job.wrap.max_width = width;
    job
}

/// `text` with its emphasis, in the strong text colour (read from the back of a room).
fn append(job: &mut LayoutJob, ui: &egui::Ui, text: &str, size: f32) {
    let color = ui.visuals().strong_text_color();
    for span in spans(text) {
        let t = match span {
            Span::Plain(s) => RichText::new(s),
            Span::Emphasis(s) => RichText::new(s).italics().strong(),
            Span::Code(s) => RichText::new(s).code(),
        };
        let t = t.size(size).color(color);
        t.append_to(job, ui.style(), FontSelection::Default, Align::Min);
    }
}

/// A caption as the band shows its text (the markers gone).
pub fn plain(text: &str) -> String {
    spans(text)
        .into_iter()
        .map(|s| match s {
            Span::Plain(s) | Span::Emphasis(s) | Span::Code(s) => s,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_band_shows_a_caption_without_its_markers() {
        assert_eq!(super::plain("The *floor* is `hot`, 2 * 3 = 6"), "The floor is hot, 2 * 3 = 6");
    }
}
