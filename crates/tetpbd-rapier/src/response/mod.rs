//! How a soft body responds at its contacts besides being pushed out: Coulomb friction
//! (one rule for every contact kind), restitution, the passivity of immovable contacts and rolling
//! resistance. The deformation
//! damping of a body is the core's ([`tetpbd::DeformationDamping`]), run by its solver.

pub(crate) mod friction;
pub(crate) mod passivity;
pub(crate) mod restitution;
pub(crate) mod rolling;
