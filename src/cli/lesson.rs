//! `bvhscope lesson LESSON -o DIR`: a lesson rendered to a handout — each step's picture drawn by
//! `render` with the step's own words (run here, in-process: the PNG is the one that command
//! writes, byte for byte), and one self-contained HTML page with each picture, its caption and
//! the commands. `--check` opens every scene, builds every step's tree and looks up every target
//! (`lesson::check`), naming the step and field of each problem.

use crate::cli::error::CliError;
use crate::cli::print::printable;
use crate::files::{FolderKind, ReportDir};
use crate::lesson::{self, HandoutStep, Lesson};
use clap::Args;
use std::path::{Path, PathBuf};

#[derive(Args, Debug)]
pub struct LessonArgs {
    /// The lesson file (.json): its steps, each a caption and what it shows.
    pub lesson: PathBuf,
    /// The folder to write the handout to: index.html (every picture inline) and steps/step-NN.png.
    /// It must be new, empty, or an earlier handout's folder (only what that handout wrote is
    /// replaced).
    #[arg(long, short, value_name = "DIR")]
    pub output: Option<PathBuf>,
    /// Check the lesson without writing anything: every scene opens, every step's tree builds,
    /// every target is in range (exit 0: no problems, 1: problems, each on a line naming the step
    /// and field, 2: unreadable).
    #[arg(long)]
    pub check: bool,
}

/// A handout's folder (`files::ReportDir`).
pub const HANDOUT: FolderKind = FolderKind {
    what: "lesson handout",
    list: "handout-files.txt",
    first_line: "bvhscope-handout-files 1",
    names: &["index.html", "steps"],
    folders: &["steps"],
    flag: "-o",
};

pub fn run(a: &LessonArgs) -> Result<(), CliError> {
    if a.output.is_none() && !a.check {
        return Err(CliError::Usage("name the handout's folder (-o DIR), or check the lesson (--check)".into()));
    }
    let l = lesson::read_lesson(&a.lesson).map_err(|e| CliError::Usage(e.to_string()))?;
    let name = printable(&a.lesson.display().to_string());
    let problems = check(&l)?;
    if !problems.is_empty() {
        let lines: Vec<String> = problems.iter().map(|p| format!("{name}: {}\n", printable(&p.to_string()))).collect();
        super::out(&lines.concat());
        return Err(CliError::Defects(problems.len()));
    }
    let Some(dir) = &a.output else {
        super::out(&format!("{name}: {} steps, no problems\n", l.steps.len()));
        return Ok(());
    };
    write_handout(&l, &a.lesson, dir)
}

/// The lesson's problems, found with a progress line.
fn check(l: &Lesson) -> Result<Vec<lesson::Problem>, CliError> {
    let control = crate::work::WorkControl::new();
    let n = l.steps.len();
    Ok(super::progress::with_spinner(&format!("checking {n} steps"), || lesson::check(l, &control, |_, _| {})))
}

/// The scene of a step as the handout's commands name it (relative to where bvhscope runs).
fn scene_of(state: &lesson::StepState) -> PathBuf {
    lesson::folded(&state.scene)
}

/// The picture file of step `i` (0-based), relative to the handout's folder.
fn picture(i: usize) -> String {
    format!("steps/step-{:02}.png", i + 1)
}

fn write_handout(l: &Lesson, path: &Path, dir: &Path) -> Result<(), CliError> {
    let states = l.states();
    let mut inputs = vec![(path.to_path_buf(), "the lesson".to_string())];
    for (i, s) in states.iter().enumerate() {
        if l.steps[i].scene.is_some() {
            inputs.push((s.scene.clone(), format!("step {}'s scene", i + 1)));
        }
    }
    let fail = |e: crate::files::FolderError| CliError::Usage(e.to_string());
    let mut out = ReportDir::prepare(dir, &HANDOUT, inputs).map_err(fail)?;
    let mut steps = Vec::with_capacity(states.len());
    for (i, state) in states.iter().enumerate() {
        let rel = picture(i);
        let file = Path::new(&rel).file_name().map(PathBuf::from).unwrap_or_default();
        let scene = scene_of(state);
        let run = lesson::render_words(state, &scene, &out.path_while_written(&rel));
        eprintln!("step {} of {}:", i + 1, states.len());
        render(&run)?;
        let png = out.read_image(&rel, 256 << 20).ok_or_else(|| {
            CliError::Usage(format!("{}: step {}'s picture cannot be read back", dir.display(), i + 1))
        })?;
        steps.push(HandoutStep {
            png,
            command: lesson::shown(&lesson::render_words(state, &scene, &file)),
            explain: lesson::explain_words(state, &scene).map(|w| lesson::shown(&w)),
        });
    }
    out.write("index.html", lesson::handout_html(l, &steps).as_bytes())?;
    out.publish().map_err(fail)?;
    eprintln!("wrote {} ({} steps: index.html and {} pictures)", dir.display(), steps.len(), steps.len());
    Ok(())
}

/// `bvhscope render` run on `words` (those after `bvhscope`), as the command line would: parsed by
/// `render`'s own arguments, so a step's command is read with the very flags `render` takes.
fn render(words: &[String]) -> Result<(), CliError> {
    /// The command line with `render` as its only subcommand.
    #[derive(clap::Parser)]
    #[command(name = "bvhscope")]
    enum OnlyRender {
        Render(super::render::RenderArgs),
    }
    if words.first().map(String::as_str) != Some("render") {
        return Err(CliError::Usage("the step's command is not a render".into()));
    }
    let OnlyRender::Render(r) = <OnlyRender as clap::Parser>::try_parse_from(
        std::iter::once("bvhscope".to_string()).chain(words.iter().cloned()),
    )
    .map_err(|e| CliError::Usage(format!("the step's render command does not parse: {e}")))?;
    super::render::run(&r)
}
