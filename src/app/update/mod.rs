//! What changes the app's state: `act` applies one `Action` (`act.rs`), `reconcile` decides from
//! the state alone what to rebuild and re-render (`reconcile.rs`), the jobs' results, picked and
//! dropped files and keys are taken in (`events.rs`), files are saved (`export.rs`), the
//! messages kept (`messages.rs`), a lesson opened and stepped through (`lesson.rs`) and recorded
//! (`record.rs`), and the steps of an imported tree and a grade report (`import.rs`, `grade.rs`).

mod act;
mod events;
mod export;
mod grade;
mod import;
mod lesson;
mod messages;
mod reconcile;
mod record;

pub use export::{default_name, StatsFormat};
