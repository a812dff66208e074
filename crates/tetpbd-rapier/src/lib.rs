//! Two-way coupling of [`tetpbd`] soft bodies with [`rapier3d`] rigid-body scenes.
//!
//! Soft bodies (hecs entities with `tetpbd` components) collide with every rapier collider
//! through parry, push dynamic rigid bodies back with the right momentum, feel Coulomb
//! friction and restitution, can be attached to rigid bodies or kinematic targets, and
//! report their contacts — all under one call, [`Coupling::step`], which borrows the
//! integrator's rapier state ([`RapierContext`]). [`CoupledWorld`] owns everything for quick
//! scenes.
//!
//! * Order of a frame, and who integrates which reaction: see [`Coupling`].
//! * Collision detection: candidates from rapier's broad-phase BVH once per frame (never
//!   all pairs), contacts re-evaluated as XPBD inequality constraints every iteration of
//!   every substep (particle vs collider by parry point projection; rigid corners vs soft
//!   surface triangles).
//! * Per-body collision properties and groups: the [`SoftCollider`] component.
//! * Attachments: the [`Attachments`] component.
//! * Contact reports: [`Coupling::contacts`]; statistics: [`CouplingStats`].
//!
//! Bad input is rejected with a [`CouplingError`] naming what is wrong; conditions that can
//! only be seen during a step (an attachment whose body was removed, a point parry gives no
//! normal for) are skipped and counted in [`CouplingStats`].
#![warn(missing_docs)]

mod attachment;
mod bodies;
mod contact;
pub mod convert;
mod corner;
mod coupling;
mod damping;
mod error;
mod frame;
mod hook;
mod material;
mod report;
mod restitution;
mod scene;
mod shape_query;
mod soft_bvh;
mod soft_contact;
mod soft_gather;
mod soft_project;
mod soft_separation;

pub use attachment::{AttachTarget, Attachment, Attachments};
pub use coupling::{Coupling, CouplingSettings, RapierContext};
pub use damping::DeformationDamping;
pub use error::CouplingError;
pub use material::{SoftCollider, SoftColliderBuilder};
pub use report::{ContactReport, CouplingStats, SoftFeature};
pub use scene::CoupledWorld;
pub use soft_contact::{SelfCollision, SoftContactSettings, SoftContactStats, SoftContacts};

pub use rapier3d;
pub use tetpbd;
