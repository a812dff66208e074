//! Passes that keep a body well-behaved where plain Gauss–Seidel is not enough:
//!
//! * [`angular_momentum`] — removing the rigid rotation the projections' corrections carry,
//!   so a free body's internal constraints conserve its angular momentum
//!   ([`crate::SafetySettings::conserve_angular_momentum`], on by default);
//! * [`correction_energy`] — keeping the families' corrections from adding more kinetic
//!   energy than their compliant constraints release
//!   ([`crate::SafetySettings::limit_correction_energy`], on by default), counting what a
//!   hook's position corrections hand them as external work ([`hook_work`]), and giving a
//!   free body back the momentum it held back within the same budget ([`give_back`]);
//! * [`momentum_restoration`] — giving back, as a rigid velocity change, the momentum the
//!   correction-speed safety net ([`crate::SafetySettings::max_correction_speed`]) clamped;
//! * [`ground_up`] — one more sweep ordered from a body's supports outwards, for heavy loads
//!   on light bodies (its level order in [`ground_up_levels`]), offered as one call by
//!   [`ground_up_sweep`] ([`crate::GroundUpSweep`]) to a hook such as a coupling's;
//! * [`deformation_damping`] — damping a body's velocities towards their rigid fit
//!   ([`crate::DeformationDamping`], a component; run after every velocity update);
//! * [`rigid_fit`] — the rigid fit of a field on a body's particles, the one every pass here
//!   and the couplings use ([`crate::Particles::rigid_fit`]);
//! * [`sliver_orientation`] — projecting the orientation constraints (volume, vertex–face)
//!   of a body's slivers once more after its edges, which cannot tell an inverted sliver
//!   from an upright one;
//! * [`untangle`] — pulling a body that came to rest tangled (inverted tetrahedra, or elastic
//!   energy no load explains) back to its best-fit rest shape ([`crate::Untangle`], a
//!   component spawned with every body, on by default).

pub(crate) mod angular_momentum;
pub(crate) mod correction_energy;
pub(crate) mod deformation_damping;
pub(crate) mod give_back;
pub(crate) mod ground_up;
pub(crate) mod ground_up_levels;
pub(crate) mod ground_up_sweep;
pub(crate) mod hook_work;
pub(crate) mod momentum_restoration;
pub(crate) mod rigid_fit;
pub(crate) mod sliver_orientation;
pub(crate) mod untangle;
