//! Where contacts against rigid bodies are made: the constraints between soft bodies and
//! rapier colliders, projected every iteration of every substep.
//!
//! * [`particle`]: a soft surface particle against a collider (parry point projection).
//! * [`approach`]: a fast body touching something immovable stopped as a whole, down to
//!   what its constraints carry within a substep.
//! * [`corner`]: a rigid corner or support point against a soft surface triangle
//!   ([`corner_friction`] its friction).
//! * [`support`]: the rigid contacts of a body anchored by an attachment.
//!
//! The candidates come from [`crate::gather`] once per frame; friction is
//! [`crate::response::friction`], restitution and rolling resistance act on whole bodies in
//! [`crate::response`].

pub(crate) mod approach;
pub(crate) mod corner;
pub(crate) mod corner_friction;
pub(crate) mod particle;
pub(crate) mod support;
