//! Where the parallel passes of a step run (feature `parallel`): on the pool the integrator
//! gave the solver ([`crate::Solver::set_thread_pool`]), or else in the caller's rayon
//! context; or nowhere but the stepping thread ([`crate::ParallelSettings::serial`]).
//!
//! [`enter`] sets this thread's context for one step; the passes read it through
//! [`threads`] and [`in_pool`]. Outside a step (an integrator calling [`crate::systems`]
//! directly) the context is the caller's rayon context.

use std::cell::{Cell, RefCell};
use std::sync::Arc;

use rayon::ThreadPool;

thread_local! {
    /// The pool of the step running on this thread, if the solver was given one.
    static POOL: RefCell<Option<Arc<ThreadPool>>> = const { RefCell::new(None) };
    /// Whether the step running on this thread is serial.
    static SERIAL: Cell<bool> = const { Cell::new(false) };
}

/// This thread's step context while alive; the previous one comes back on drop.
pub(crate) struct Entered {
    pool: Option<Arc<ThreadPool>>,
    serial: bool,
}

/// Makes `pool` (or the caller's rayon context, for `None`) and `serial` this thread's
/// context until the returned guard drops.
pub(crate) fn enter(pool: Option<Arc<ThreadPool>>, serial: bool) -> Entered {
    Entered {
        pool: POOL.with(|p| p.replace(pool)),
        serial: SERIAL.with(|s| s.replace(serial)),
    }
}

impl Drop for Entered {
    fn drop(&mut self) {
        POOL.with(|p| *p.borrow_mut() = self.pool.take());
        SERIAL.with(|s| s.set(self.serial));
    }
}

/// The step's pool, if the solver was given one.
fn pool() -> Option<Arc<ThreadPool>> {
    POOL.with(|p| p.borrow().clone())
}

/// Threads a parallel pass may use: 1 when serial, else the size of the step's pool or of
/// the caller's rayon context.
pub(crate) fn threads() -> usize {
    if SERIAL.with(Cell::get) {
        return 1;
    }
    match pool() {
        Some(pool) => pool.current_num_threads(),
        None => rayon::current_num_threads(),
    }
}

/// Runs `f` in the step's pool: on this thread if it is one of the pool's threads (or the
/// solver has no pool), else on one of them while this thread waits.
pub(crate) fn in_pool<R: Send>(f: impl FnOnce() -> R + Send) -> R {
    match pool() {
        Some(pool) => pool.install(f),
        None => f(),
    }
}

/// Whether this thread is one of the step pool's threads (with no pool given: of any
/// rayon pool).
pub(crate) fn on_pool_thread() -> bool {
    match pool() {
        Some(pool) => pool.current_thread_index().is_some(),
        None => rayon::current_thread_index().is_some(),
    }
}
