//! Passes that keep a body well-behaved where plain Gauss–Seidel is not enough:
//!
//! * [`angular_momentum`] — removing the rigid rotation the projections' corrections carry,
//!   so a free body's internal constraints conserve its angular momentum
//!   ([`crate::SolverSettings::conserve_angular_momentum`], on by default);
//! * [`correction_energy`] — keeping the families' corrections from adding more kinetic
//!   energy than their compliant constraints release
//!   ([`crate::SolverSettings::limit_correction_energy`], on by default);
//! * [`momentum_restoration`] — giving back, as a rigid velocity change, the momentum the
//!   correction-speed safety net ([`crate::SolverSettings::max_correction_speed`]) clamped;
//! * [`ground_up`] — one more sweep ordered from a body's supports outwards, for heavy loads
//!   on light bodies (its level order in [`ground_up_levels`]), called by a coupling;
//! * [`rigid_fit`] — the rigid fit of a field on a body's particles both momentum passes use.

pub(crate) mod angular_momentum;
pub(crate) mod correction_energy;
pub(crate) mod ground_up;
pub(crate) mod ground_up_levels;
pub(crate) mod momentum_restoration;
pub(crate) mod rigid_fit;
