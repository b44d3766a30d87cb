//! Parallel building blocks whose results do not depend on the thread count (the builders must
//! make the same tree on 1 and on 16 threads), and the clock of the time spent outside them.
//!
//! - `partition`: in place, in fixed-size blocks, as Embree's builders partition the top of the
//!   tree (Wald, "On fast Construction of SAH-based Bounding Volume Hierarchies", RT 2007).
//! - `exclusive_scan`: prefix sums in two passes over fixed chunks, as PLOC's compaction uses them
//!   (Meister & Bittner, "Parallel Locally-Ordered Clustering", TVCG 2018); `concat`: vectors
//!   joined by parallel copies.
//! - `region` / `measure_serial`: the serial fraction behind an Amdahl projection, measured on a
//!   machine with few cores (issue 37): the time outside the stretches marked parallel.

use rayon::prelude::*;
use std::cell::Cell;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// Slices shorter than this are partitioned on the calling thread: the block pass and the
/// swaps cost more than they save on a node that is itself one task among many.
pub const PARTITION_MIN: usize = 1 << 16;

/// Items per block of the parallel partition. Fixed, not derived from the thread count, so the
/// order the partition leaves does not depend on it.
const BLOCK: usize = 1 << 13;

/// Move the items satisfying `left` to the front; returns how many there are. Unstable, and the
/// order it leaves depends only on the items and `left` (not on the thread count).
///
/// Short slices: one branch-free Lomuto pass. Long ones: each block of `BLOCK` items is
/// partitioned on its own (in parallel), then the right-goers that lie before the boundary are
/// swapped, in order, with the left-goers that lie after it (in parallel over those swaps).
pub fn partition<T: Copy + Send + Sync>(items: &mut [T], left: impl Fn(&T) -> bool + Sync) -> usize {
    if items.len() < PARTITION_MIN {
        return lomuto(items, &left);
    }
    let counts: Vec<usize> = region(|| items.par_chunks_mut(BLOCK).map(|b| lomuto(b, &left)).collect());
    // The misplaced ranges are found on this thread (a few per block).
    let runs = swap_runs(&counts, items.len());
    let boundary: usize = counts.iter().sum();
    let base = SendPtr(items.as_mut_ptr());
    region(|| {
        runs.into_par_iter().for_each(|(x, y, len)| {
            let base = &base;
            // SAFETY: early ranges lie before `boundary`, late ones after it, and the runs cut
            // each list into disjoint pieces, so no two runs (nor the two sides of one) overlap,
            // and all lie inside `items`, which this function borrows mutably.
            unsafe { std::ptr::swap_nonoverlapping(base.0.add(x), base.0.add(y), len) };
        })
    });
    boundary
}

/// The swaps that finish a block partition whose blocks sent `counts` items left, as runs of at
/// most `BLOCK` swaps: (first early index, first late index, length).
fn swap_runs(counts: &[usize], len: usize) -> Vec<(usize, usize, usize)> {
    let boundary: usize = counts.iter().sum();
    // Misplaced ranges, in order: right-goers before the boundary, left-goers after it.
    let (mut early, mut late) = (Vec::new(), Vec::new());
    for (b, &c) in counts.iter().enumerate() {
        let (start, end) = (b * BLOCK, (b * BLOCK + BLOCK).min(len));
        let (rights, lefts) = (start + c..end.min(boundary), start.max(boundary)..(start + c));
        if rights.start < rights.end {
            early.push(rights);
        }
        if lefts.start < lefts.end {
            late.push(lefts);
        }
    }
    // Pair them up, in order.
    let mut runs = Vec::new();
    let (mut e, mut l) = (early.into_iter(), late.into_iter());
    let (mut a, mut b) = (e.next(), l.next());
    while let (Some(ea), Some(lb)) = (a.as_mut(), b.as_mut()) {
        let run = (ea.end - ea.start).min(lb.end - lb.start).min(BLOCK);
        runs.push((ea.start, lb.start, run));
        ea.start += run;
        lb.start += run;
        if ea.start == ea.end {
            a = e.next();
        }
        if lb.start == lb.end {
            b = l.next();
        }
    }
    debug_assert!(a.is_none() && b.is_none(), "as many right-goers before the boundary as left-goers after");
    runs
}

/// A pointer the swap runs share (each touches only its own disjoint ranges).
struct SendPtr<T>(*mut T);
// SAFETY: the runs that share it write disjoint ranges (see `partition`).
unsafe impl<T: Send> Sync for SendPtr<T> {}

/// Branch-free Lomuto: every element is swapped with the first non-left one (a no-op while there
/// is none) and the boundary advances by the predicate's 0 or 1. In the top levels `left` is a
/// coin toss the branch predictor loses half the time; two extra moves per element cost less.
#[inline]
fn lomuto<T: Copy>(items: &mut [T], left: &impl Fn(&T) -> bool) -> usize {
    let mut boundary = 0;
    for i in 0..items.len() {
        let x = items[i];
        let goes_left = left(&x);
        items[i] = items[boundary];
        items[boundary] = x;
        boundary += goes_left as usize;
    }
    boundary
}

/// Items per chunk of `exclusive_scan`.
const SCAN_CHUNK: usize = 1 << 14;

/// Replace each count by the sum of those before it; returns the total. Two parallel passes over
/// fixed chunks (their sums, then each chunk from its offset), the chunks' offsets summed on this
/// thread: the same sums in the same order on any thread count (floats included).
pub fn exclusive_scan<T>(counts: &mut [T]) -> T
where
    T: Copy + Default + Send + Sync + std::ops::Add<Output = T>,
{
    let scan = |c: &mut [T], mut sum: T| {
        for x in c {
            (*x, sum) = (sum, sum + *x);
        }
        sum
    };
    if counts.len() < 2 * SCAN_CHUNK {
        return scan(counts, T::default());
    }
    let mut offsets: Vec<T> =
        region(|| counts.par_chunks(SCAN_CHUNK).map(|c| c.iter().fold(T::default(), |a, &b| a + b)).collect());
    let total = scan(&mut offsets, T::default());
    region(|| {
        counts.par_chunks_mut(SCAN_CHUNK).zip(offsets).for_each(|(c, o)| {
            scan(c, o);
        })
    });
    total
}

/// Items per chunk of `sum`.
const SUM_CHUNK: usize = 1 << 14;

/// The sum of `values`, in fixed chunks (each's sum, then theirs in order): the same on any thread
/// count, which rayon's `sum` (split by the threads' stealing) is not for floats.
pub fn sum(values: &[f64]) -> f64 {
    let sums: Vec<f64> = values.par_chunks(SUM_CHUNK).map(|c| c.iter().sum::<f64>()).collect();
    sums.iter().sum()
}

/// The parts one after the other, copied in parallel (a serial `concat` of a build's top-level
/// pieces is a pass over all of its references on one thread), with room for `spare` more. Each
/// part is freed by the thread that copied it: freeing big buffers one after the other on the
/// calling thread was a third of a 4M-triangle load's serial time.
pub fn concat<T: Copy + Send + Sync>(parts: Vec<Vec<T>>, spare: usize) -> Vec<T> {
    let total = parts.iter().map(Vec::len).sum();
    let Some(fill) = parts.iter().find_map(|p| p.first().copied()) else {
        return Vec::with_capacity(spare);
    };
    let mut out = Vec::with_capacity(total + spare);
    region(|| out.par_extend(rayon::iter::repeat_n(fill, total)));
    let mut slices = Vec::with_capacity(parts.len());
    let mut rest = &mut out[..];
    for p in &parts {
        let (a, b) = rest.split_at_mut(p.len());
        slices.push(a);
        rest = b;
    }
    region(|| slices.into_par_iter().zip(parts).for_each(|(to, from)| to.copy_from_slice(&from)));
    out
}

/// A slice that many tasks write at once, each slot by one task (a tree's nodes, each reached
/// once from the root): the caller promises that no two tasks touch the same slot.
pub struct Disjoint<'a, T> {
    base: *mut T,
    len: usize,
    _slice: std::marker::PhantomData<&'a mut [T]>,
}

// SAFETY: shared between tasks only through `set` and `get`, whose callers promise that each slot
// is touched by one task.
unsafe impl<T: Send> Sync for Disjoint<'_, T> {}
unsafe impl<T: Send> Send for Disjoint<'_, T> {}

impl<'a, T: Copy> Disjoint<'a, T> {
    pub fn new(slice: &'a mut [T]) -> Self {
        Disjoint { base: slice.as_mut_ptr(), len: slice.len(), _slice: std::marker::PhantomData }
    }

    /// Write slot `i` (checked against the length).
    ///
    /// # Safety
    /// No other task reads or writes slot `i` while the slice is shared.
    #[inline]
    pub unsafe fn set(&self, i: usize, v: T) {
        assert!(i < self.len);
        // SAFETY: in bounds; the caller promises no other task touches the slot.
        unsafe { self.base.add(i).write(v) }
    }

    /// Read slot `i`, which this task wrote.
    ///
    /// # Safety
    /// As `set`.
    #[inline]
    pub unsafe fn get(&self, i: usize) -> T {
        assert!(i < self.len);
        // SAFETY: as `set`.
        unsafe { self.base.add(i).read() }
    }
}

static MEASURING: AtomicBool = AtomicBool::new(false);
static PARALLEL_NANOS: AtomicU64 = AtomicU64::new(0);

thread_local! {
    /// How many `region`s the calling thread is inside (only the outermost is timed).
    static DEPTH: Cell<u32> = const { Cell::new(0) };
}

/// Run `f`, a stretch that gives 16 threads work each (a parallel pass over many chunks, or one
/// of many independent subtrees), timing it when `measure_serial` asks. Off, it costs one relaxed
/// load.
#[inline]
pub fn region<R>(f: impl FnOnce() -> R) -> R {
    if !MEASURING.load(Ordering::Relaxed) {
        return f();
    }
    let outermost = DEPTH.with(|d| {
        d.set(d.get() + 1);
        d.get() == 1
    });
    let t0 = Instant::now();
    let r = f();
    DEPTH.with(|d| d.set(d.get() - 1));
    if outermost {
        PARALLEL_NANOS.fetch_add(t0.elapsed().as_nanos() as u64, Ordering::Relaxed);
    }
    r
}

/// `region(f)` where `wide` (the stretch has work for 16 threads), else `f()`: a pass over a
/// few chunks stays serial in the count, as it would be on 16 threads.
#[inline]
pub fn region_if<R>(wide: bool, f: impl FnOnce() -> R) -> R {
    if wide {
        region(f)
    } else {
        f()
    }
}

/// Whether `measure_serial` is timing: code that chooses its path by the thread count takes the
/// one it would take on many threads.
pub fn measuring() -> bool {
    MEASURING.load(Ordering::Relaxed)
}

/// Run `f` on a pool of one thread and return, with its result, the time it spent outside every
/// `region`: the serial part of Amdahl's law, for projecting a speed-up on more cores than this
/// machine has. What is not marked as a region counts as serial, so a stretch overlooked makes the
/// projection lower, never higher. One thread, because the nesting of regions is followed per
/// thread; one measurement at a time (the count is global).
pub fn measure_serial<R: Send>(f: impl FnOnce() -> R + Send) -> (R, Duration, Duration) {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("a pool of one thread");
    pool.install(|| {
        PARALLEL_NANOS.store(0, Ordering::Relaxed);
        MEASURING.store(true, Ordering::Relaxed);
        let t0 = Instant::now();
        let r = f();
        let total = t0.elapsed();
        MEASURING.store(false, Ordering::Relaxed);
        let parallel = Duration::from_nanos(PARALLEL_NANOS.swap(0, Ordering::Relaxed));
        (r, total, total.saturating_sub(parallel))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_parallel_partition_is_a_partition_and_the_same_on_any_thread_count() {
        let mut rng = crate::random::Rng::new(37);
        for n in [PARTITION_MIN, PARTITION_MIN + 1, 3 * PARTITION_MIN + 777] {
            let original: Vec<u32> = (0..n).map(|_| rng.below(1000) as u32).collect();
            for cut in [0, 1, 300, 999, 1000] {
                let run = |threads| {
                    let mut v = original.clone();
                    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
                    let k = pool.install(|| partition(&mut v, |&x| x < cut));
                    (k, v)
                };
                let (k, v) = run(1);
                assert_eq!(k, original.iter().filter(|&&x| x < cut).count());
                assert!(v[..k].iter().all(|&x| x < cut) && v[k..].iter().all(|&x| x >= cut));
                let (mut sorted, mut expected) = (v.clone(), original.clone());
                sorted.sort();
                expected.sort();
                assert_eq!(sorted, expected, "a permutation");
                assert!(run(4) == (k, v), "n {n}, cut {cut}: the same order on 4 threads");
            }
        }
    }

    #[test]
    fn exclusive_scan_sums_what_comes_before() {
        for n in [0, 5, 2 * SCAN_CHUNK + 3] {
            let counts: Vec<u32> = (0..n as u32).map(|i| i % 7).collect();
            let mut scanned = counts.clone();
            let total = exclusive_scan(&mut scanned);
            let mut sum = 0;
            for (s, c) in scanned.iter().zip(&counts) {
                assert_eq!(*s, sum);
                sum += c;
            }
            assert_eq!(total, sum);
        }
    }
}
