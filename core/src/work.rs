//! Control of long work (loading, building, rendering): a cancel flag the worker polls and a
//! progress counter it advances, shared with whoever started it (the app's UI thread, the CLI's
//! progress bar). Plain atomics, read a few times per second: no cost to the work itself.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

#[derive(Debug, Default)]
pub struct WorkControl {
    cancel: AtomicBool,
    done: AtomicU64,
    total: AtomicU64,
}

/// The work was cancelled before it finished.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("cancelled")]
pub struct Cancelled;

impl WorkControl {
    pub fn new() -> Self {
        Self::default()
    }

    pub fn cancel(&self) {
        self.cancel.store(true, Ordering::Relaxed);
    }

    #[inline]
    pub fn is_cancelled(&self) -> bool {
        self.cancel.load(Ordering::Relaxed)
    }

    /// `Err(Cancelled)` once cancelled, for `?` at check points.
    #[inline]
    pub fn check(&self) -> Result<(), Cancelled> {
        if self.is_cancelled() {
            Err(Cancelled)
        } else {
            Ok(())
        }
    }

    /// Progress back to none done, for a second stretch of work under the same control (the
    /// counted pass after an image, `render::render_passes_counts_after`).
    pub fn restart(&self) {
        self.done.store(0, Ordering::Relaxed);
    }

    pub fn set_total(&self, total: u64) {
        self.total.store(total, Ordering::Relaxed);
    }

    pub fn total(&self) -> u64 {
        self.total.load(Ordering::Relaxed)
    }

    #[inline]
    pub fn add_done(&self, n: u64) {
        self.done.fetch_add(n, Ordering::Relaxed);
    }

    pub fn done(&self) -> u64 {
        self.done.load(Ordering::Relaxed)
    }

    /// Progress in [0, 1] (0 while the total is unknown).
    pub fn fraction(&self) -> f32 {
        let t = self.total();
        if t == 0 {
            0.0
        } else {
            (self.done() as f64 / t as f64).min(1.0) as f32
        }
    }
}

/// Whether the work a watcher watches has ended (`watched`).
pub struct Ended<'a>(&'a AtomicBool);

impl Ended<'_> {
    /// Sleep `tick`, then whether the work has ended (returned or panicked).
    pub fn after(&self, tick: std::time::Duration) -> bool {
        std::thread::sleep(tick);
        self.0.load(Ordering::Acquire)
    }
}

/// Sets the flag when dropped: when the work returns, and when it panics (the scope then waits
/// for the watcher, which must stop, before the panic goes on).
struct EndOnDrop<'a>(&'a AtomicBool);

impl Drop for EndOnDrop<'_> {
    fn drop(&mut self) {
        self.0.store(true, Ordering::Release);
    }
}

/// Run `work` on this thread while `watcher` runs on a thread of its own, told through `Ended`
/// when the work has ended, so it never outlives the work, not even one that panics (the panic
/// is passed on once the watcher has stopped). The CLI's progress bars and the grader's
/// deadline are such watchers.
pub fn watched<T>(watcher: impl FnOnce(&Ended) + Send, work: impl FnOnce() -> T) -> T {
    let ended = AtomicBool::new(false);
    std::thread::scope(|s| {
        s.spawn(|| watcher(&Ended(&ended)));
        let _end = EndOnDrop(&ended);
        work()
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    /// The watcher sees the work end, and a panic in the work is passed on once the watcher has
    /// stopped, never waited for.
    #[test]
    fn the_watcher_stops_when_the_work_ends_even_by_a_panic() {
        let ticks = AtomicU64::new(0);
        let watch = |ended: &Ended| {
            while !ended.after(Duration::from_millis(1)) {
                ticks.fetch_add(1, Ordering::Relaxed);
            }
        };
        assert_eq!(watched(watch, || 7), 7);
        let r = std::panic::catch_unwind(|| watched(watch, || -> u32 { panic!("the work failed") }));
        assert!(r.is_err());
        // A watcher that stops first leaves the work to run on.
        assert_eq!(watched(|_| {}, || 8), 8);
    }
}
