//! The names a scene needs, under names that do not clash with `rapier3d::prelude::*`.
//!
//! rapier's prelude has its own `SoftBody` and `SoftBodyBuilder`; here they are
//! [`TetBody`] and [`TetBodyBuilder`]. Everything else keeps its name.
//!
//! ```
//! use tetpbd::prelude::*;
//! let mesh = generators::box_grid(nalgebra::Vector3::repeat(0.5), [2, 2, 2], generators::CellSplit::Six)?;
//! let mut world = hecs::World::new();
//! TetBodyBuilder::new(mesh).edges(0.0).volume(0.0).build()?.spawn(&mut world);
//! Solver::new(SolverSettings::default())?.step(&mut world)?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub use crate::body::activation::{Activation, Asleep};
pub use crate::body::builder::{SoftBody as TetBody, SoftBodyBuilder as TetBodyBuilder, TetMesh};
pub use crate::body::forces::UserForces;
pub use crate::body::generators;
pub use crate::body::grab::Grab;
pub use crate::body::material_point::MaterialPoint;
pub use crate::body::mesh::{Surface, Tetrahedra};
pub use crate::body::particles::{ExternalAcceleration, Particles};
pub use crate::body::placement::Placement;
pub use crate::body::plasticity::{Plasticity, PlasticitySettings};
pub use crate::error::{BuildError, PlasticityError, SettingsError, StateError, StepError};
pub use crate::solver::settings::{SafetySettings, SolverSettings};
pub use crate::solver::stats::StepStats;
pub use crate::solver::step::Solver;
