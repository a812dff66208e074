//! How a soft body responds at its contacts besides being pushed out: Coulomb friction
//! (one rule for every contact kind), restitution, rolling resistance, and the deformation
//! damping of a body.

pub(crate) mod deformation_damping;
pub(crate) mod friction;
pub(crate) mod restitution;
pub(crate) mod rolling;
