//! Diagnostic (feature `sync-stats`): time the threads of parallel sweeps spend waiting at
//! phase boundaries (the `schedule` module) and for a pass's last chunks when the pass closes
//! (the `team` module), and how many of a sweep's chunks threads other than the sweep's own
//! ran (how much of the work the helpers actually took), and how often a helper moved off
//! the core of the thread it helps (the `affinity` module). Counted over all threads,
//! process-wide; read and reset with [`take`]. The counting adds a clock read per wait that
//! had to spin, so leave the feature off for timings.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

static PHASE_WAITS: AtomicU64 = AtomicU64::new(0);
static PHASE_NS: AtomicU64 = AtomicU64::new(0);
static CLOSE_WAITS: AtomicU64 = AtomicU64::new(0);
static CLOSE_NS: AtomicU64 = AtomicU64::new(0);
static CHUNKS: AtomicU64 = AtomicU64::new(0);
static CHUNKS_ELSEWHERE: AtomicU64 = AtomicU64::new(0);
static MOVES: AtomicU64 = AtomicU64::new(0);

/// Waits counted since the last [`take`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SyncStats {
    /// Waits at a phase boundary that had to spin (a thread ready for phase `k + 1` while
    /// chunks of phase `k` still ran elsewhere).
    pub phase_waits: u64,
    /// Their total time, summed over threads.
    pub phase_wait: Duration,
    /// Waits of a pass's own thread for the helpers to leave the pass.
    pub close_waits: u64,
    /// Their total time.
    pub close_wait: Duration,
    /// Chunks of parallel sweeps run (phases of colour classes, tasks, particle passes).
    pub chunks: u64,
    /// Those of them run by a thread other than the one that started the sweep: about
    /// `chunks / 2` when two threads share the work evenly, 0 when the helper never ran.
    pub chunks_elsewhere: u64,
    /// Times a helper found itself on the core of the thread it helps and moved to another.
    pub moves: u64,
}

/// The counts so far, reset to zero.
pub fn take() -> SyncStats {
    SyncStats {
        phase_waits: PHASE_WAITS.swap(0, Ordering::Relaxed),
        phase_wait: Duration::from_nanos(PHASE_NS.swap(0, Ordering::Relaxed)),
        close_waits: CLOSE_WAITS.swap(0, Ordering::Relaxed),
        close_wait: Duration::from_nanos(CLOSE_NS.swap(0, Ordering::Relaxed)),
        chunks: CHUNKS.swap(0, Ordering::Relaxed),
        chunks_elsewhere: CHUNKS_ELSEWHERE.swap(0, Ordering::Relaxed),
        moves: MOVES.swap(0, Ordering::Relaxed),
    }
}

/// Counts a phase wait that started at `since`.
pub(crate) fn phase(since: Instant) {
    PHASE_WAITS.fetch_add(1, Ordering::Relaxed);
    PHASE_NS.fetch_add(since.elapsed().as_nanos() as u64, Ordering::Relaxed);
}

/// Counts a close wait that started at `since`.
pub(crate) fn close(since: Instant) {
    CLOSE_WAITS.fetch_add(1, Ordering::Relaxed);
    CLOSE_NS.fetch_add(since.elapsed().as_nanos() as u64, Ordering::Relaxed);
}

/// Counts a chunk of a sweep, run by the sweep's own thread or `elsewhere`.
pub(crate) fn chunk(elsewhere: bool) {
    CHUNKS.fetch_add(1, Ordering::Relaxed);
    if elsewhere {
        CHUNKS_ELSEWHERE.fetch_add(1, Ordering::Relaxed);
    }
}

/// Counts a helper's move off the core of the thread it helps.
pub(crate) fn moved() {
    MOVES.fetch_add(1, Ordering::Relaxed);
}
