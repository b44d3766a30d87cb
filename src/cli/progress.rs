//! Progress display for work that takes over a second: nothing is drawn for quick work, and
//! nothing at all when stderr is not a terminal (indicatif's own rule).

use crate::work::WorkControl;
use indicatif::{ProgressBar, ProgressStyle};
use std::time::{Duration, Instant};

const SHOW_AFTER: Duration = Duration::from_secs(1);
const TICK: Duration = Duration::from_millis(100);

/// Run `work`, showing a bar fed by `control` once it has run for a second.
pub fn with_bar<T: Send>(label: &str, control: &WorkControl, work: impl FnOnce() -> T + Send) -> T {
    watch(label, Some(control), work)
}

/// Run `work`, showing a spinner once it has run for a second.
pub fn with_spinner<T: Send>(label: &str, work: impl FnOnce() -> T + Send) -> T {
    watch(label, None, work)
}

fn watch<T: Send>(label: &str, bar: Option<&WorkControl>, work: impl FnOnce() -> T + Send) -> T {
    crate::work::watched(
        |ended| {
            let start = Instant::now();
            let mut pb: Option<ProgressBar> = None;
            while !ended.after(TICK) {
                if pb.is_none() && start.elapsed() >= SHOW_AFTER {
                    let p = match bar {
                        Some(c) => ProgressBar::new(c.total()).with_style(
                            ProgressStyle::with_template("{msg} [{bar:30}] {percent}% ({eta} left)")
                                .expect("static template")
                                .progress_chars("=> "),
                        ),
                        None => ProgressBar::new_spinner(),
                    };
                    p.set_message(label.to_string());
                    pb = Some(p);
                }
                if let Some(p) = &pb {
                    match bar {
                        Some(c) => {
                            p.set_length(c.total());
                            p.set_position(c.done());
                        }
                        None => p.tick(),
                    }
                }
            }
            if let Some(p) = pb {
                p.finish_and_clear();
            }
        },
        work,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A panic in the work ends the wrapped call with that panic, and does not leave the display
    /// thread waiting forever (it used to: the scope waited for a spinner nobody stopped).
    #[test]
    fn a_panic_in_the_work_is_passed_on_not_waited_for() {
        let (done, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let r = std::panic::catch_unwind(|| with_spinner("failing", || -> u32 { panic!("the work failed") }));
            let _ = done.send(r.is_err());
        });
        let panicked = rx.recv_timeout(Duration::from_secs(20)).expect("with_spinner returned within 20 s");
        assert!(panicked);
        assert_eq!(with_spinner("fine", || 7), 7);
    }
}
