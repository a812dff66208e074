//! Tetrahedral soft bodies solved with (extended) position-based dynamics, stored as
//! [`hecs`] components.
//!
//! Three layers:
//!
//! * [`constraint`] — the math of the three constraints Müller et al. (2006) use for
//!   tetrahedra (edge distance, vertex–face, signed volume) as pure functions, with the XPBD
//!   update written once in its module docs;
//! * components — [`Particles`] (flat arrays per quantity), [`Tetrahedra`], [`Surface`] and
//!   one optional component per constraint family ([`EdgeConstraints`],
//!   [`VertexFaceConstraints`], [`VolumeConstraints`]): a body pays only for the families it has;
//! * [`systems`] — plain functions over `&mut hecs::World`, run in order by [`Solver`].
//!
//! ```
//! use nalgebra::Vector3;
//! use tetpbd::{generators, Solver, SolverSettings, SoftBodyBuilder};
//!
//! let mut world = hecs::World::new();
//! let mesh = generators::box_grid(Vector3::new(1.0, 1.0, 1.0), [3, 3, 3], generators::CellSplit::Six)?;
//! SoftBodyBuilder::new(mesh).density(1000.0).edges(0.0).volume(0.0).build()?.spawn(&mut world);
//! let mut solver = Solver::new(SolverSettings { measure_error: true, ..Default::default() })?;
//! let stats = solver.step(&mut world)?;
//! assert_eq!(stats.inverted, Some(0));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![warn(missing_docs)]

#[cfg(feature = "parallel")]
mod affinity;
mod builder;
pub mod constraint;
mod error;
mod families;
pub mod generators;
mod lanes;
mod level_order;
pub mod locality;
mod mesh;
mod momentum;
pub mod ordering;
#[cfg(feature = "parallel")]
mod parallel;
mod particles;
pub mod partition;
mod projection;
mod runs;
#[cfg(feature = "parallel")]
mod schedule;
mod simd;
mod solver;
mod spin;
mod stacking;
mod stats;
#[cfg(feature = "sync-stats")]
pub mod sync_stats;
pub mod systems;
#[cfg(feature = "parallel")]
mod team;
mod work;

pub use builder::{unique_edges, SoftBody, SoftBodyBuilder, TetMesh};
pub use error::{BuildError, SettingsError, StateError};
pub use families::{EdgeConstraints, VertexFaceConstraints, VolumeConstraints};
pub use mesh::{Surface, Tetrahedra};
pub use particles::{ExternalAcceleration, Particles};
pub use solver::{Solver, SolverSettings, SubstepHook};
pub use stacking::{project_stacked, BodyConstraints, StackingLayers};
pub use stats::{ErrorAccumulator, ErrorStats, Family, FamilyStats, StepStats};

pub use hecs;
pub use nalgebra;
