//! The orders fixed when a body is built: which particle sits where in memory and in which
//! order the constraints are projected.
//!
//! * [`spatial`] — particles renumbered in rows so a constraint's particles lie close;
//! * [`colouring`] — constraints sorted into colour classes whose items share no particle;
//! * [`partition`] — a large body cut into slabs, so a parallel sweep has few phases.

pub(crate) mod colouring;
pub(crate) mod partition;
pub(crate) mod spatial;

pub use colouring::ColourClasses;
