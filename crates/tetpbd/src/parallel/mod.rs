//! Parallel sweeps (feature `parallel`), bit-identical to the serial ones for any number of
//! threads.
//!
//! * [`context`] — where a step's passes run: the solver's pool, the caller's rayon context,
//!   or serially;
//! * [`sweeps`] — the parallel family sweeps and particle passes;
//! * [`schedule`] — one parallel region per sweep, its phases split into chunks;
//! * [`shared`] — memory the threads of a region share, each writing its own part: the
//!   particle passes take their runs through it without `unsafe`; the class sweeps and the
//!   blocked sums of [`sweeps`] cut their runs themselves, each with its `SAFETY` argument;
//! * [`team`] — the pool's threads kept awake for one step, when the integrator opts in
//!   ([`crate::ParallelSettings::keep_helpers_awake`]);
//! * [`backoff`] — how a waiting thread spins, yields and sleeps;
//! * [`affinity`] — moving a team helper off the stepping thread's core (Linux, only when
//!   the integrator opts in: [`crate::ParallelSettings::move_helpers_off_step_core`]).
//!
//! By default a pass enters the pool through `rayon::join` and the pool's threads sleep
//! between passes; no thread's CPU mask is touched.

pub(crate) mod affinity;
pub(crate) mod backoff;
pub(crate) mod context;
pub(crate) mod schedule;
pub(crate) mod shared;
pub(crate) mod sweeps;
#[cfg(feature = "sync-stats")]
pub mod sync_stats;
pub(crate) mod team;
