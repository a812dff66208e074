//! One parallel region for a whole sweep (feature `parallel`): a sequence of phases (the
//! colour classes of a family, or the particles of a copy) that must run one after another,
//! each phase's items split among the threads of rayon's pool.
//!
//! Why not one rayon parallel iterator per phase: a sweep of a 100k-tetrahedron body in the
//! plain layout has 30 classes of tetrahedra (14 of edges), each a few hundred microseconds
//! of work or less (a partitioned body has 3 phases per family, see [`crate::ordering::partition`]).
//! Between two parallel iterators rayon's idle thread goes to sleep and has to be woken, which
//! can cost tens of microseconds each time. Here every thread of the pool enters once per sweep and
//! waits at a phase boundary on a counter (spinning, then yielding, then sleeping:
//! [`crate::parallel::backoff`]); between sweeps the threads sleep as rayon's do, unless the
//! integrator keeps them awake for the step ([`crate::parallel::team`]).
//!
//! **Layout.** Each phase is cut into `R` contiguous *regions*, one per thread (`R` = the
//! pool's threads, at most [`MAX_REGIONS`]), at multiples of [`LANES`] items, and each region
//! into chunks of a given number of items (a multiple of [`LANES`]). A thread works through its own region first (thread `i`
//! owns region `i`: consecutive classes of a family cover the mesh in the same order, so the
//! particles a thread touches stay in its cache from one phase to the next), then takes the
//! chunks left in other regions. A phase that is not independent (the overflow class) is one
//! chunk. A phase of *units* (the tasks of a partitioned sweep, [`crate::ordering::partition`]) is cut
//! the same way with one unit per chunk and no lane alignment: a task is never split.
//!
//! **Claiming and waiting.** Each region has a claim counter and a done counter, both
//! counting its chunks over all phases so far. A thread claims a chunk of phase `k` with a
//! compare-and-swap that never passes the region's last chunk of phase `k`, and moves on to
//! phase `k + 1` only once every region is fully claimed for phase `k`. Before running its
//! first chunk of phase `k` it waits until every region's done counter has reached the
//! region's chunks of the phases before `k`. So a thread only ever waits for chunks that other
//! threads have claimed and are running (a chunk never waits inside): a thread that enters
//! late, or never (its pool is busy elsewhere), holds nobody up, and one thread alone runs
//! the sweep serially. No deadlock, whatever the pool does.
//!
//! **Determinism.** The chunks cut a phase at multiples of [`LANES`] from the phase's start,
//! so the SIMD kernels group the same four items as the serial sweep does; a unit runs whole
//! on one thread, in the serial order; and the items (units) of a phase are independent: the result is bit-identical to the serial sweep for any number of
//! threads and any assignment of chunks to threads.

use std::ops::{AddAssign, Range};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
#[cfg(feature = "sync-stats")]
use std::time::Instant;

use crate::kernels::lanes::LANES;
use crate::parallel::backoff::Backoff;

/// Constraints per chunk of a colour class: small enough to balance the threads at a class
/// boundary (a 100k-tetrahedron body has 7–9 chunks per thread in most classes), large
/// enough that a claim costs little beside it (256 volume projections take a few µs; 64
/// are a few per cent slower per frame on 2 threads).
pub(crate) const CLASS_CHUNK: usize = 256;

/// Particles per chunk of a pass over the particles (a copy, the prediction, the velocity
/// update: a few nanoseconds per particle).
pub(crate) const PARTICLE_CHUNK: usize = 1024;

/// Regions per phase at most (threads beyond this share regions).
const MAX_REGIONS: usize = 16;

/// One region's counters, on a cache line of its own (its owner updates them).
#[derive(Default)]
#[repr(align(128))]
struct Region {
    claimed: AtomicUsize,
    done: AtomicUsize,
}

/// How the items of a phase may be split among the threads.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Split {
    /// Pairwise independent items (a colour class, particles): chunks of the given size
    /// cut at multiples of [`LANES`] from the phase's start.
    Lanes,
    /// Independent units of work (the tasks of a partitioned sweep): one unit per chunk.
    Units,
    /// Not independent (the overflow class): one chunk of every item.
    Whole,
}

/// Where a phase of `len` items is cut for `regions` regions.
#[derive(Clone, Copy)]
struct Cut {
    len: usize,
    split: Split,
    regions: usize,
    chunk: usize,
}

impl Cut {
    fn new(len: usize, split: Split, regions: usize, lanes_chunk: usize) -> Cut {
        let chunk = match split {
            Split::Lanes => lanes_chunk,
            Split::Units | Split::Whole => 1,
        };
        Cut {
            len,
            split,
            regions,
            chunk,
        }
    }

    /// First item of region `r` (`r ≤ regions`).
    fn bound(&self, r: usize) -> usize {
        let align = if self.split == Split::Lanes { LANES } else { 1 };
        if r >= self.regions {
            self.len
        } else {
            self.len * r / self.regions / align * align
        }
    }

    /// Chunks of region `r`.
    fn chunks(&self, r: usize) -> usize {
        if self.split == Split::Whole {
            return usize::from(r == 0 && self.len > 0);
        }
        (self.bound(r + 1) - self.bound(r)).div_ceil(self.chunk)
    }

    /// Items of chunk `j` of region `r`.
    fn items(&self, r: usize, j: usize) -> Range<usize> {
        if self.split == Split::Whole {
            return 0..self.len;
        }
        let (lo, hi) = (self.bound(r), self.bound(r + 1));
        let first = lo + j * self.chunk;
        first..(first + self.chunk).min(hi)
    }
}

/// The result of a pass that counts nothing.
#[derive(Default)]
pub(crate) struct Nothing;

impl AddAssign for Nothing {
    fn add_assign(&mut self, _: Nothing) {}
}

/// Claims the next chunk of `region` below `end` (its count over all phases), if any.
fn claim(region: &Region, end: usize) -> Option<usize> {
    let mut c = region.claimed.load(Ordering::Relaxed);
    while c < end {
        match region
            .claimed
            .compare_exchange_weak(c, c + 1, Ordering::Relaxed, Ordering::Relaxed)
        {
            Ok(_) => return Some(c),
            Err(now) => c = now,
        }
    }
    None
}

/// Spins until `counter` reaches `target` (acquiring the writes of the chunks it counts).
fn wait_for(counter: &AtomicUsize, target: usize) {
    if counter.load(Ordering::Acquire) >= target {
        return;
    }
    #[cfg(feature = "sync-stats")]
    let since = Instant::now();
    let mut backoff = Backoff::default();
    while counter.load(Ordering::Acquire) < target {
        backoff.wait();
    }
    #[cfg(feature = "sync-stats")]
    crate::parallel::sync_stats::phase(since);
}

/// Runs `phases` phases in order on every thread of the step's pool
/// ([`crate::parallel::context`]; the step's team if it has one): phase `k` has
/// `phase(k) = (len, split)` items, and `work(k, items)` does the `items` of phase `k`
/// (indices within the phase): in chunks of `chunk` items (rounded up to a multiple of
/// [`LANES`]) for [`Split::Lanes`], one item at a time for [`Split::Units`], all at once for
/// [`Split::Whole`]. Returns the sum of what `work` returned (summed per thread, then over
/// the threads: use it for counts, whose sum does not depend on the order).
///
/// The items of a [`Split::Lanes`] or [`Split::Units`] phase must be pairwise independent
/// (touch disjoint data); `work` then runs concurrently on disjoint ranges of the phase. A
/// [`Split::Whole`] phase runs as one range on one thread.
pub(crate) fn run_phases<C: Default + AddAssign + Send>(
    phases: usize,
    chunk: usize,
    phase: impl Fn(usize) -> (usize, Split) + Sync,
    work: impl Fn(usize, Range<usize>) -> C + Sync,
) -> C {
    let threads = crate::parallel::context::threads();
    let regions_n = threads.clamp(1, MAX_REGIONS);
    let chunk = chunk.max(1).next_multiple_of(LANES);
    let regions: [Region; MAX_REGIONS] = Default::default();
    let total = Mutex::new(C::default());
    #[cfg(feature = "sync-stats")]
    let own = rayon::current_thread_index();
    let worker = || {
        let index = rayon::current_thread_index();
        let home = index.unwrap_or(0) % regions_n;
        let mut count = C::default();
        // Chunks of each region in the phases before the current one.
        let mut before = [0usize; MAX_REGIONS];
        for k in 0..phases {
            let (len, split) = phase(k);
            let cut = Cut::new(len, split, regions_n, chunk);
            let mut ready = false;
            loop {
                let got = (0..regions_n)
                    .map(|i| (home + i) % regions_n)
                    .find_map(|r| {
                        claim(&regions[r], before[r] + cut.chunks(r)).map(|c| (r, c - before[r]))
                    });
                let Some((r, j)) = got else { break };
                if !ready {
                    for (region, &b) in regions.iter().zip(&before).take(regions_n) {
                        wait_for(&region.done, b);
                    }
                    ready = true;
                }
                count += work(k, cut.items(r, j));
                regions[r].done.fetch_add(1, Ordering::Release);
                #[cfg(feature = "sync-stats")]
                crate::parallel::sync_stats::chunk(index != own);
            }
            for (r, b) in before.iter_mut().enumerate().take(regions_n) {
                *b += cut.chunks(r);
            }
        }
        // A poisoned lock means another worker panicked; the scope re-raises that panic.
        if let Ok(mut t) = total.lock() {
            *t += count;
        }
    };
    if !crate::parallel::team::post(&worker) {
        let worker = &worker;
        crate::parallel::context::in_pool(|| fan_out(threads, worker));
    }
    total.into_inner().unwrap_or_default()
}

/// Runs `worker` on up to `n` threads of the pool: this one and `n - 1` rayon jobs others may
/// steal (`rayon::join`, whose jobs live on the stack: no allocation, unlike a scope's
/// spawned jobs). A job nobody stole runs here afterwards and finds nothing left to do.
fn fan_out(n: usize, worker: &(impl Fn() + Sync)) {
    if n <= 1 {
        worker();
    } else {
        rayon::join(worker, || fan_out(n - 1, worker));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernels::count::ProjectionCount;

    /// Every item of every phase is worked exactly once, phases in order, on 1 to 3 threads,
    /// and the ranges of an independent phase start at multiples of the lanes.
    #[test]
    fn every_item_once_phases_in_order() {
        let lens = [0usize, 1, 5, 63, 64, 65, 1000, 7, 4097];
        for threads in 1..=3 {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let seen: Vec<Vec<AtomicUsize>> = lens
                .iter()
                .map(|&n| (0..n).map(|_| AtomicUsize::new(0)).collect())
                .collect();
            let count = pool.install(|| {
                run_phases(
                    lens.len(),
                    CLASS_CHUNK,
                    |k| match k {
                        7 => (lens[k], Split::Whole),
                        3 => (lens[k], Split::Units),
                        _ => (lens[k], Split::Lanes),
                    },
                    |k, items| {
                        let earlier_done = seen[..k]
                            .iter()
                            .flatten()
                            .all(|s| s.load(Ordering::SeqCst) == 1);
                        assert!(earlier_done, "phase {k} started before the ones before it");
                        match k {
                            7 => assert_eq!(items, 0..lens[k]),
                            3 => assert_eq!(items.len(), 1),
                            _ => assert_eq!(items.start % LANES, 0),
                        }
                        for i in items.clone() {
                            seen[k][i].fetch_add(1, Ordering::SeqCst);
                        }
                        ProjectionCount {
                            applied: items.len() as u64,
                            degenerate: 1,
                        }
                    },
                )
            });
            assert_eq!(count.applied, lens.iter().sum::<usize>() as u64);
            for (k, s) in seen.iter().enumerate() {
                assert!(s.iter().all(|x| x.load(Ordering::SeqCst) == 1), "phase {k}");
            }
        }
    }
}
