//! Progress display for work that takes over a second: nothing is drawn for quick work, and
//! nothing at all when stderr is not a terminal (indicatif's own rule).

use indicatif::{ProgressBar, ProgressStyle};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::{Duration, Instant};

const SHOW_AFTER: Duration = Duration::from_secs(1);
const TICK: Duration = Duration::from_millis(100);

/// Run `work`, showing a bar fed by `done` (out of `total`) once it has run for a second.
pub fn with_bar<T: Send>(
    label: &str,
    total: u64,
    done: &AtomicU64,
    work: impl FnOnce() -> T + Send,
) -> T {
    watch(label, Some((total, done)), work)
}

/// Run `work`, showing a spinner once it has run for a second.
pub fn with_spinner<T: Send>(label: &str, work: impl FnOnce() -> T + Send) -> T {
    watch(label, None, work)
}

fn watch<T: Send>(
    label: &str,
    bar: Option<(u64, &AtomicU64)>,
    work: impl FnOnce() -> T + Send,
) -> T {
    let finished = AtomicBool::new(false);
    std::thread::scope(|s| {
        s.spawn(|| {
            let start = Instant::now();
            let mut pb: Option<ProgressBar> = None;
            while !finished.load(Ordering::Acquire) {
                std::thread::sleep(TICK);
                if pb.is_none() && start.elapsed() >= SHOW_AFTER {
                    let p = match bar {
                        Some((total, _)) => ProgressBar::new(total).with_style(
                            ProgressStyle::with_template(
                                "{msg} [{bar:30}] {percent}% ({eta} left)",
                            )
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
                        Some((_, done)) => p.set_position(done.load(Ordering::Relaxed)),
                        None => p.tick(),
                    }
                }
            }
            if let Some(p) = pb {
                p.finish_and_clear();
            }
        });
        let out = work();
        finished.store(true, Ordering::Release);
        out
    })
}
