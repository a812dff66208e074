//! The numerical stability suite: stiff and extreme cases run against every constraint
//! configuration, measured the same way, for the tests and for `docs/stability.md`.
//!
//! Each [`Case`] builds a scene, runs it, and reports an [`Outcome`]: whether the state
//! stayed finite, the peak kinetic energy relative to the case's reference energy, the frames
//! until recovered (no inverted tetrahedron and total volume within 1 %), and the final
//! max |C| per family. [`Outcome::pass`] applies the case's criteria.
#![forbid(unsafe_code)]
#![warn(missing_docs)]

mod cases;
mod config;
mod coupled;
mod coupled_rapier;
mod coupled_robust;
mod draws;
pub mod energy;
mod ground;
pub mod random_scenes;
mod report;
mod run;
pub mod settle;
mod throws;

pub use cases::{all_cases, impact, Case, CaseKind, SWEEP_SUBSTEPS};
pub use config::{Config, ConstraintSet};
pub use coupled::{coupled_cases, CoupledCase, CoupledOutcome};
pub use coupled_rapier::rapier_comparison;
pub use coupled_robust::{
    pull_apart, pull_apart_in, PullFigures, BLOWN_UP_SPEED, FRAGMENT_SPEED_MARGIN, PULL_SPEEDS,
};
pub use draws::Draws;
pub use ground::Ground;
pub use report::{markdown, verdict, Verdict};
pub use run::{
    run_scene, run_scene_observed, stable_substeps, substeps_for, FrameView, Outcome, Scene, Start,
};
pub use throws::{Landing, Shape, Throw};
