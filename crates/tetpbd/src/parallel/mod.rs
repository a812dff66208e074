//! Parallel sweeps (feature `parallel`), bit-identical to the serial ones for any number of
//! threads.
//!
//! * [`sweeps`] — the parallel family sweeps and particle passes;
//! * [`schedule`] — one parallel region per sweep, its phases split into chunks;
//! * [`shared`] — memory the threads of a region share, each writing its own part: the
//!   particle passes take their runs through it without `unsafe`; the class sweeps and the
//!   blocked sums of [`sweeps`] cut their runs themselves, each with its `SAFETY` argument;
//! * [`team`] — the pool's threads kept awake for one step;
//! * [`backoff`] — how a waiting thread spins, yields and sleeps;
//! * [`affinity`] — moving a team helper off the stepping thread's core (Linux).

pub(crate) mod affinity;
pub(crate) mod backoff;
pub(crate) mod schedule;
pub(crate) mod shared;
pub(crate) mod sweeps;
#[cfg(feature = "sync-stats")]
pub mod sync_stats;
pub(crate) mod team;
