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
//! * Rigid points against soft surface triangles: rigid corners and small shapes do not slip
//!   between the particles of a coarse soft body.
//! * Triangle-mesh colliders of either winding, open or closed, with or without
//!   pseudo-normals: an open mesh (or one wound inwards) is a two-sided sheet, a particle
//!   kept on the side it came from; only a closed mesh wound outwards has an inside that
//!   pushes a particle created in it out. A heightfield is solid below its surface (see
//!   [`SoftCollider`]).
//! * Per-body collision properties (friction, restitution, rolling resistance, thickness)
//!   and groups: the [`SoftCollider`] component; deformation damping: the
//!   [`DeformationDamping`] component.
//! * Attachments: the [`Attachments`] component.
//! * Contact reports: [`Coupling::contacts`]; statistics: [`CouplingStats`].
//! * Soft–soft and self contacts: on by default ([`CouplingSettings::soft_contacts`]), with
//!   each body's [`SoftCollider`]; [`SoftContacts`] runs them on a bare `tetpbd` solver.
//! * Hooks of the integrator's own run in the same substeps through [`Coupling::step_with`].
//! * Scene queries against soft bodies (ray casts, point projection and containment, AABB and
//!   shape overlap), alone or together with rapier's colliders: [`SoftQueries`].
//!
//! ```
//! use nalgebra::Vector3;
//! use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder};
//! use tetpbd::{generators, SoftBodyBuilder};
//! use tetpbd_rapier::{CoupledWorld, SoftColliderBuilder};
//!
//! let mut scene = CoupledWorld::new(Default::default(), Default::default())?;
//! scene.physics.insert(RigidBodyBuilder::fixed(), ColliderBuilder::cuboid(2.0, 0.1, 2.0));
//! let mesh = generators::box_grid(Vector3::repeat(0.2), [2, 2, 2], generators::CellSplit::Six)?;
//! let cube = SoftBodyBuilder::new(mesh)
//!     .edges(0.0)
//!     .volume(0.0)
//!     .translation(Vector3::new(0.0, 0.3, 0.0))
//!     .build()?
//!     .spawn(&mut scene.soft);
//! scene.soft.insert_one(cube, SoftColliderBuilder::new().friction(0.8).build()?)?;
//! for _ in 0..30 {
//!     scene.step()?;
//! }
//! assert!(!scene.coupling.contacts().is_empty());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! Where things are in the source: `gather` collects once per frame the colliders near each
//! soft body and the contact candidates; `contacts` makes and projects the contacts against
//! rigid bodies (`particle`: soft particles vs colliders, `corner`: rigid corners vs soft
//! triangles, `support`: the rigid contacts of anchored bodies); `response` holds friction
//! (one rule for every contact kind), restitution and rolling resistance (the deformation
//! damping is the core's, run by its solver); `rigid` the proxies of rapier bodies and colliders inside the substeps; `ccd`
//! the swept tests for fast bodies; `heavy_loads` the pass that carries heavy rigid bodies
//! on soft ones; `attachments`; `soft_soft` the contacts between soft bodies; `substep` the
//! order of the work in one substep; `coupling` the frame ([`Coupling::step`]).
//!
//! Bad input is rejected with a [`CouplingError`] naming what is wrong; conditions that can
//! only be seen during a step (an attachment whose body was removed, a point parry gives no
//! normal for) are skipped and counted in [`CouplingStats`].
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod attachments;
mod ccd;
mod contacts;
mod context;
mod convert;
mod coupling;
mod depenetration;
mod error;
mod gather;
mod heavy_loads;
mod joints;
mod mesh_side;
mod pieces;
mod placement;
pub mod prelude;
mod queries;
mod report;
mod response;
mod rigid;
mod scene;
mod settings;
mod sleeping;
mod soft_collider;
mod soft_soft;
mod substep;
mod validate;

pub use attachments::{AttachTarget, Attachment, Attachments};
pub use context::RapierContext;
pub use coupling::Coupling;
pub use error::CouplingError;
pub use pieces::follow_pieces;
pub use placement::RapierPlacement;
pub use queries::{
    QueryError, ScenePointProjection, SceneRayHit, SoftLocation, SoftPointProjection, SoftQueries,
    SoftQueryFilter, SoftRayHit, SoftVolumePoint,
};
pub use report::{ContactReport, CouplingStats, SoftFeature};
pub use scene::CoupledWorld;
pub use settings::{CouplingSettings, StackingSettings};
pub use soft_collider::{SoftCollider, SoftColliderBuilder};
pub use soft_soft::settings::{SelfCollision, SoftContactSettings, SoftContactStats};
pub use soft_soft::SoftContacts;
/// The deformation damping is a core component, run by the solver after every velocity
/// update; re-exported here for code written against the coupling.
pub use tetpbd::DeformationDamping;

pub use rapier3d;
pub use tetpbd;

/// The scene-query guide (`docs/guide/queries.md`), compiled as doctests.
#[cfg(doctest)]
#[doc = include_str!("../../../docs/guide/queries.md")]
pub struct QueriesGuide;
