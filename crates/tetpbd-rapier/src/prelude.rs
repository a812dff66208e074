//! The names a coupled scene needs, usable next to `rapier3d::prelude::*`.
//!
//! Everything of [`tetpbd::prelude`] (where tetpbd's soft body types are [`TetBody`] and
//! [`TetBodyBuilder`], since rapier's prelude has its own `SoftBody` and `SoftBodyBuilder`)
//! and the coupling's own types (the scene queries among them: [`SoftQueries`]), plus
//! [`RapierPlacement`] to place a body with rapier's glam types.
//!
//! ```
//! use rapier3d::prelude::*;
//! use tetpbd_rapier::prelude::*;
//!
//! let mut scene = CoupledWorld::new(Default::default(), Default::default())?;
//! scene.physics.insert(RigidBodyBuilder::fixed(), ColliderBuilder::cuboid(2.0, 0.1, 2.0));
//! let mesh = generators::box_grid(nalgebra::Vector3::repeat(0.2), [2, 2, 2], generators::CellSplit::Six)?;
//! let pose = Pose::from_parts(Vector::new(0.0, 0.5, 0.0), Rotation::from_rotation_z(0.5));
//! TetBodyBuilder::new(mesh).edges(0.0).volume(0.0).rapier_pose(pose).build()?.spawn(&mut scene.soft);
//! scene.step()?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub use crate::attachments::{AttachTarget, Attachment, Attachments};
pub use crate::context::RapierContext;
pub use crate::coupling::Coupling;
pub use crate::error::CouplingError;
pub use crate::placement::RapierPlacement;
pub use crate::queries::{
    QueryError, ScenePointProjection, SceneRayHit, SoftLocation, SoftPointProjection, SoftQueries,
    SoftQueryFilter, SoftRayHit, SoftVolumePoint,
};
pub use crate::report::{ContactReport, CouplingStats, SoftFeature};
pub use crate::scene::CoupledWorld;
pub use crate::settings::{CouplingSettings, StackingSettings};
pub use crate::soft_collider::{SoftCollider, SoftColliderBuilder};
pub use tetpbd::prelude::*;
