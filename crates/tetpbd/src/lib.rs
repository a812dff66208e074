//! Tetrahedral soft bodies solved with (extended) position-based dynamics, stored as
//! [`hecs`] components.
//!
//! The crate, folder by folder:
//!
//! * [`constraints`] — the math of the three constraints Müller et al. (2006) use for
//!   tetrahedra (edge distance, vertex–face, signed volume) as pure functions, with the XPBD
//!   update written once in its module docs;
//! * components — [`Particles`] (flat arrays per quantity), [`Tetrahedra`], [`Surface`] and
//!   one optional component per constraint family ([`EdgeConstraints`],
//!   [`VertexFaceConstraints`], [`VolumeConstraints`]): a body pays only for the families it has;
//! * [`systems`] — plain functions over `&mut hecs::World`, run in order by [`Solver`]
//!   (the `solver` folder: [`Solver`], [`SolverSettings`], [`SubstepHook`], [`StepStats`]).
//!
//! Inside the crate, `body/` builds bodies and holds their components, `stabilisation/` the
//! optional passes that keep a body well-behaved (the correction-speed safety net's momentum
//! restoration, the angular-momentum conservation, the ground-up sweep), `kernels/` the
//! scalar and SIMD projections over the working copy of the particles, `parallel/` the
//! parallel sweeps (feature `parallel`) and `ordering/` the build-time orders (colour
//! classes, spatial renumbering, domain decomposition).
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

mod body;
pub mod constraints;
mod error;
mod kernels;
mod ordering;
#[cfg(feature = "parallel")]
mod parallel;
mod solver;
mod stabilisation;

pub use body::builder::{unique_edges, SoftBody, SoftBodyBuilder, TetMesh};
pub use body::families::{EdgeConstraints, Family, VertexFaceConstraints, VolumeConstraints};
pub use body::generators;
pub use body::mesh::{Surface, Tetrahedra};
pub use body::particles::{ExternalAcceleration, Particles};
pub use error::{BuildError, SettingsError, StateError};
pub use ordering::ColourClasses;
pub use solver::hook::SubstepHook;
pub use solver::settings::SolverSettings;
pub use solver::stats::{ErrorAccumulator, ErrorStats, FamilyStats, StepStats};
pub use solver::step::Solver;
pub use solver::systems;
pub use stabilisation::ground_up::{project_stacked, BodyConstraints, StackingLayers};

/// The constraint math under its former name; the same module as [`constraints`].
#[doc(hidden)]
pub use constraints as constraint;
#[cfg(feature = "sync-stats")]
pub use parallel::sync_stats;

pub use hecs;
pub use nalgebra;
