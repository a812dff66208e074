//! Tetrahedral soft bodies solved with (extended) position-based dynamics, stored as
//! [`hecs`] components.
//!
//! What a user touches: [`SoftBodyBuilder`] turns a [`TetMesh`] (from a file or a
//! [`generators`] function) into components — [`Particles`] (flat arrays per quantity),
//! [`Tetrahedra`], [`Surface`] and one optional component per constraint family
//! ([`EdgeConstraints`], [`VertexFaceConstraints`], [`VolumeConstraints`]) and optionally a
//! physical [`Material`] (Young's modulus, Poisson's ratio) as the [`NeoHookeanMaterial`]
//! component: a body pays only for the families it has. A [`Solver`] steps every body of a `hecs::World` with
//! [`SolverSettings`], runs a [`SubstepHook`] (contacts, attachments of a coupling crate)
//! inside its substep loop and returns [`StepStats`]. Interaction: impulses on
//! [`Particles`] (`apply_impulse`, `apply_impulse_at_point`, `apply_radial_impulse`), forces
//! in the [`UserForces`] component (integrated like gravity, kept until reset), and the
//! [`Grab`] component holding a [`MaterialPoint`] to a moving target (mouse picking). The
//! optional [`Plasticity`] component lets a body's rest shape flow past a yield (bodies that
//! stay bent), every family's rest values following; the optional [`Tearing`] component
//! lets it tear past a strain, and [`cut`] cuts it with a [`Blade`], both splitting it into
//! pieces ([`TearEvent`]). [`constraints`] holds the constraint
//! math as pure functions and [`systems`] the solver's steps as plain functions over
//! `&mut hecs::World`, for an integrator who builds a different schedule.
//!
//! The source, folder by folder:
//!
//! | folder | holds |
//! |---|---|
//! | `body/` | the builder, the mesh generators and the components |
//! | `constraints/` | one file per constraint (`edge.rs`, `vertex_face.rs`, `vertex_face_bounded.rs`, `volume.rs`, `neo_hookean.rs`) and the XPBD update (`xpbd.rs`) |
//! | `solver/` | settings, the hook, the statistics, the systems, and `step.rs`, where a frame and each substep start |
//! | `stabilisation/` | the rigid fit of a body, the angular-momentum conservation, the safety net's momentum restoration, the deformation damping, the ground-up sweep for heavy loads |
//! | `kernels/` | the scalar and SIMD projections and the working copy of the particles they run on |
//! | `parallel/` | the parallel sweeps (feature `parallel`), bit-identical to the serial ones |
//! | `ordering/` | orders fixed at build time: colour classes, spatial renumbering, domain decomposition |
//!
//! `unsafe` is confined to `kernels/` (bounds checked once per run of a colour class, AVX2
//! chosen at run time) and `parallel/` (disjoint writes of one region's threads, the step's
//! helper threads and the helper's CPU mask, both only when the integrator opts in), each use with its `SAFETY` argument.
//!
//! ```
//! use nalgebra::Vector3;
//! use tetpbd::{generators, DiagnosticSettings, Solver, SolverSettings, SoftBodyBuilder};
//!
//! let mut world = hecs::World::new();
//! let mesh = generators::box_grid(Vector3::new(1.0, 1.0, 1.0), [3, 3, 3], generators::CellSplit::Six)?;
//! SoftBodyBuilder::new(mesh).density(1000.0).edges(0.0).volume(0.0).build()?.spawn(&mut world);
//! let diagnostics = DiagnosticSettings { measure_error: true, ..Default::default() };
//! let mut solver = Solver::new(SolverSettings { diagnostics, ..Default::default() })?;
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
pub mod prelude;
mod solver;
mod stabilisation;

pub use body::activation::{Activation, Asleep};
pub use body::builder::{SoftBody, SoftBodyBuilder, TetMesh};
pub use body::cutting::{cut, Blade};
pub use body::elastic_energy::ElasticFamilies;
pub use body::families::{EdgeConstraints, Family, VertexFaceConstraints, VolumeConstraints};
pub use body::forces::{applied_acceleration, UserForces};
pub use body::generators;
pub use body::grab::Grab;
pub use body::impact_reach::{local_reach, ImpactReach, LOCAL_REACH};
pub use body::impact_speed;
pub use body::impulses::PointImpulse;
pub use body::material::{Material, MaterialError};
pub use body::material_point::MaterialPoint;
pub use body::mesh::{Surface, Tetrahedra};
pub use body::neo_hookean::NeoHookeanMaterial;
pub use body::particles::{ExternalAcceleration, Particles};
pub use body::pieces::{Piece, TearEvent};
pub use body::placement::Placement;
pub use body::plasticity::{Plasticity, PlasticitySettings, VOLUME_PRESERVING_TOLERANCE};
pub use body::rest_families::unique_edges;
pub use body::tear_relaxation::{TearRelaxation, RELAXATION_TIME};
pub use body::tearing::{Pieces, Tearing, TearingSettings};
pub use error::{
    BuildError, CutError, PlasticityError, SettingsError, StateError, StepError, TearingError,
};
pub use ordering::ColourClasses;
pub use solver::hook::{FrameContext, SubstepContext, SubstepHook};
pub use solver::non_finite::Restored;
pub use solver::settings::{DiagnosticSettings, ParallelSettings, SafetySettings, SolverSettings};
pub use solver::sleeping::{is_sleeping, wake, Touching};
pub use solver::stats::{ErrorAccumulator, ErrorStats, FamilyStats, StepStats};
pub use solver::step::Solver;
pub use solver::systems;
pub use stabilisation::deformation_damping::DeformationDamping;
pub use stabilisation::ground_up_sweep::GroundUpSweep;
pub use stabilisation::rigid_fit::RigidFit;
pub use stabilisation::untangle::Untangle;

/// The constraint math under its former name; the same module as [`constraints`].
#[doc(hidden)]
pub use constraints as constraint;
#[cfg(feature = "sync-stats")]
pub use parallel::sync_stats;

pub use hecs;
pub use nalgebra;
/// The rayon version the solver's pools are of ([`Solver::set_thread_pool`]).
#[cfg(feature = "parallel")]
pub use rayon;
