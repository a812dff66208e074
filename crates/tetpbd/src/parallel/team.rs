//! The pool's other threads kept awake for one solver step (feature `parallel`), when the
//! integrator opts in ([`crate::ParallelSettings::keep_helpers_awake`]; off by default).
//!
//! Why: a parallel region entered through rayon (`join`, a parallel iterator) has to wake
//! the other threads, which go to sleep a few microseconds after they run out of work. A
//! wake-up can cost tens of microseconds, while a substep of a 100k-tetrahedron
//! body has six parallel passes (prediction, the copies in and out, two families, the
//! velocity update) of 30–700 µs each. The price: while a step runs, the helpers hold the
//! pool's cores even between passes, which a host running other work on them would feel.
//!
//! [`with_team`] runs the step on this thread while the pool's other threads wait in a loop
//! for work ([`post`]): each parallel pass is posted as a job that every helper runs beside
//! this thread, then closed. A helper spins, and yields the core now and then, between jobs;
//! after [`LINGER`] without a job (a long hook, e.g. a rigid-body step) it leaves, and the
//! following passes enter through rayon as by default. So a helper never waits on anything
//! but a job to come or its own job's chunks, and no cycle of waits can form (two steps run
//! on the same pool each leave the other's helper loop within [`LINGER`]).
//!
//! With [`crate::ParallelSettings::move_helpers_off_step_core`] also on, a helper that
//! finds itself on the core of the step's thread (the kernel often wakes it there) moves to
//! another core for as long as it stays in the team ([`crate::parallel::affinity`]): two
//! threads spinning on one core run no faster than one.
//!
//! Posting: the job (a closure on this thread's stack) is published with an odd epoch, and
//! a helper registers in `active` before re-checking the epoch; closing makes the epoch even
//! and waits for `active` to drain. With sequentially consistent orderings a helper either
//! sees the closed epoch and does not touch the job, or is counted and waited for, so the job
//! outlives every use.

use std::cell::{Cell, UnsafeCell};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use crate::parallel::affinity::{current_cpu, Moved};
use crate::parallel::backoff::Backoff;

/// How long a helper waits for the next job before it leaves the team.
const LINGER: Duration = Duration::from_micros(500);

/// A job: the worker of one parallel pass, with its lifetime erased (see [`post`]).
type Job = *const (dyn Fn() + Sync);

/// The shared state of one step's team.
struct Team {
    /// Odd while a job is open; each post adds 2 over two steps (open, close).
    epoch: AtomicUsize,
    /// The open job (written only while the epoch is even and no helper is active).
    job: UnsafeCell<Option<Job>>,
    /// Helpers inside the open job.
    active: AtomicUsize,
    /// Helpers in the loop.
    helpers: AtomicUsize,
    /// Set when the step is over.
    quit: AtomicBool,
    /// The core the step's thread ran on at its last post (`usize::MAX`: not known).
    step_cpu: AtomicUsize,
    /// Whether helpers move off the step thread's core (the integrator's choice).
    move_off: bool,
}

// SAFETY: `job` is written by the team's own thread only between jobs (epoch even, `active`
// drained), and read by helpers only after they registered in `active` and saw the job's
// odd epoch (see the module docs); everything else is atomic.
unsafe impl Sync for Team {}

thread_local! {
    /// The team this thread is running a step with, if any.
    static CURRENT: Cell<*const Team> = const { Cell::new(std::ptr::null()) };
}

/// Runs `f` on this thread with the step pool's other threads waiting for jobs from
/// [`post`] (moving off this thread's core if `move_off`). On a pool of one thread, or from
/// a thread that is not one of the pool's, just runs `f`.
pub(crate) fn with_team<T>(move_off: bool, f: impl FnOnce() -> T) -> T {
    let helpers = crate::parallel::context::threads().saturating_sub(1);
    if helpers == 0 || !crate::parallel::context::on_pool_thread() {
        return f();
    }
    let team = Team {
        epoch: AtomicUsize::new(0),
        job: UnsafeCell::new(None),
        active: AtomicUsize::new(0),
        helpers: AtomicUsize::new(0),
        quit: AtomicBool::new(false),
        step_cpu: AtomicUsize::new(if move_off {
            current_cpu().unwrap_or(usize::MAX)
        } else {
            usize::MAX
        }),
        move_off,
    };
    let mut step = OnThisThread(Some(f), None);
    let step_ref = &mut step;
    rayon::join(|| step_ref.run(&team), || fan_helpers(&team, helpers));
    match step.1 {
        Some(out) => out,
        // The first closure of `join` always runs (on this thread).
        None => unreachable!("with_team's step did not run"),
    }
}

/// The step and its result, moved into the first closure of `rayon::join`.
struct OnThisThread<F, T>(Option<F>, Option<T>);

// SAFETY: `with_team` moves it into `rayon::join` only from a worker thread of the step's
// pool (`on_pool_thread`), and there `rayon::join` runs its first closure on the calling
// thread ("It will begin by executing closure A (on the current thread)", rayon's docs), so
// neither the step nor its result changes thread.
unsafe impl<F, T> Send for OnThisThread<F, T> {}

impl<F: FnOnce() -> T, T> OnThisThread<F, T> {
    /// Runs the step as the team's thread; the team quits when it returns (or panics).
    fn run(&mut self, team: &Team) {
        let _guard = Registered::new(team);
        if let Some(f) = self.0.take() {
            self.1 = Some(f());
        }
    }
}

/// This thread's team while alive; on drop, restores the previous one and lets the helpers
/// go.
struct Registered<'a> {
    team: &'a Team,
    outer: *const Team,
}

impl<'a> Registered<'a> {
    fn new(team: &'a Team) -> Registered<'a> {
        let outer = CURRENT.with(|c| c.replace(team));
        Registered { team, outer }
    }
}

impl Drop for Registered<'_> {
    fn drop(&mut self) {
        CURRENT.with(|c| c.set(self.outer));
        self.team.quit.store(true, Ordering::SeqCst);
    }
}

/// Starts `n` helper loops (rayon jobs the other threads may steal; a job nobody stole runs
/// after the step and leaves at once).
fn fan_helpers(team: &Team, n: usize) {
    if n <= 1 {
        help(team);
    } else {
        rayon::join(|| help(team), || fan_helpers(team, n - 1));
    }
}

/// A helper's loop: run every job posted until the step is over or no job came for
/// [`LINGER`].
fn help(team: &Team) {
    if team.quit.load(Ordering::SeqCst) {
        return;
    }
    team.helpers.fetch_add(1, Ordering::SeqCst);
    let mut seen = 0;
    let mut idle = Instant::now();
    let mut spins = 0u32;
    let mut moved = Moved::default();
    if team.move_off {
        move_off_step(team, &mut moved);
    }
    loop {
        let e = team.epoch.load(Ordering::SeqCst);
        if e % 2 == 1 && e != seen {
            team.active.fetch_add(1, Ordering::SeqCst);
            if team.epoch.load(Ordering::SeqCst) == e {
                // SAFETY: the job of epoch `e` is open and this helper is counted in
                // `active`, so the poster waits for it before the job goes away.
                let job = unsafe { *team.job.get() };
                if let Some(job) = job {
                    // SAFETY: as above, the closure is alive until `active` drains.
                    unsafe { (*job)() };
                }
            }
            team.active.fetch_sub(1, Ordering::SeqCst);
            seen = e;
            idle = Instant::now();
            if team.move_off {
                move_off_step(team, &mut moved);
            }
            continue;
        }
        if team.quit.load(Ordering::SeqCst) {
            break;
        }
        spins = spins.wrapping_add(1);
        if spins.is_multiple_of(64) {
            if idle.elapsed() > LINGER {
                break;
            }
            if team.move_off {
                move_off_step(team, &mut moved);
            }
            std::thread::yield_now();
        } else {
            std::hint::spin_loop();
        }
    }
    team.helpers.fetch_sub(1, Ordering::SeqCst);
}

/// Moves this helper off the step thread's core if it is on it (see [`crate::parallel::affinity`]).
fn move_off_step(team: &Team, moved: &mut Moved) {
    let Some(cpu) = current_cpu() else { return };
    if team.step_cpu.load(Ordering::Relaxed) == cpu && moved.off(cpu) {
        #[cfg(feature = "sync-stats")]
        crate::parallel::sync_stats::moved();
    }
}

/// Runs `worker` on this thread and on every helper of this thread's team; `false` (nothing
/// run) when this thread has no team or the team has no helper left.
///
/// `worker` must be safe to run any number of times concurrently and must return once the
/// pass is done, whoever did its work (the workers of [`crate::parallel::schedule::run_phases`] are).
pub(crate) fn post(worker: &(dyn Fn() + Sync)) -> bool {
    let team = CURRENT.with(|c| c.get());
    if team.is_null() {
        return false;
    }
    // SAFETY: `CURRENT` points to the team of the `with_team` running on this thread (reset
    // before that returns).
    let team = unsafe { &*team };
    if team.helpers.load(Ordering::SeqCst) == 0 {
        return false;
    }
    if team.move_off {
        if let Some(cpu) = current_cpu() {
            team.step_cpu.store(cpu, Ordering::Relaxed);
        }
    }
    // SAFETY: only the lifetime is erased; the job is closed and every helper that may use
    // it has left it (`active` drained) before this function returns or unwinds (`Close`).
    let job: Job = unsafe {
        std::mem::transmute::<&(dyn Fn() + Sync + '_), &'static (dyn Fn() + Sync)>(worker)
    };
    // SAFETY: the epoch is even (between jobs) and no helper is active, so nobody reads it.
    unsafe { *team.job.get() = Some(job) };
    team.epoch.fetch_add(1, Ordering::SeqCst);
    // Closes the job when this function is left, also by a panic of `worker`: no helper may
    // still run the closure once its frame is gone.
    let _close = Close(team);
    worker();
    true
}

/// Closes the open job of a team on drop: the epoch made even, then every helper inside the
/// job waited for.
struct Close<'a>(&'a Team);

impl Drop for Close<'_> {
    fn drop(&mut self) {
        let team = self.0;
        team.epoch.fetch_add(1, Ordering::SeqCst);
        #[cfg(feature = "sync-stats")]
        let since = (team.active.load(Ordering::SeqCst) > 0).then(Instant::now);
        let mut backoff = Backoff::default();
        while team.active.load(Ordering::SeqCst) > 0 {
            backoff.wait();
        }
        #[cfg(feature = "sync-stats")]
        if let Some(since) = since {
            crate::parallel::sync_stats::close(since);
        }
        // SAFETY: the epoch is even again and `active` drained: no helper reads the job.
        unsafe { *team.job.get() = None };
    }
}
