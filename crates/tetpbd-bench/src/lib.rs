//! Code shared by the tetpbd-bench binaries: command-line pieces (`projections`, `scaling`)
//! and, for `error_vs_time` and `vs_rapier`, how rapier's built-in soft bodies are set up next
//! to tetpbd's, the contact scenes (a soft cube dropped on rigid ground, a pile of nine cubes)
//! in both engines, the observables measured the same way from either engine's particle
//! positions, the tearing scene ([`SlabPull`]: a slab pulled apart by two boxes, in either
//! engine), and [`Xpbd64`], tetpbd's XPBD model stepped in `f64` for converged references.
#![warn(missing_docs)]

mod args;
mod clock;
mod contact_metrics;
mod contact_scene;
mod contact_sim;
mod on_off;
mod perturb;
mod rapier_setup;
mod tear_scene;
mod xpbd64;

pub use args::{orders, FamilySet, SpatialOrder};
pub use clock::thread_cpu_ms;
pub use contact_metrics::{
    interpenetration, observe_contact, run_contact, ContactObservables, ContactResult,
    SETTLED_SPEED,
};
pub use contact_scene::{ContactKind, ContactScene, GROUND_HALF_EXTENTS};
pub use contact_sim::{build_contact, tetpbd_contact_world, ContactEngine, ContactSim};
pub use on_off::{free_body, step_alternately, zero_gravity_solver, Run};
pub use perturb::perturb;
pub use rapier_setup::{
    lumped_masses, rapier_label, rapier_material, to_rapier, RAPIER_HARD_HZ, RAPIER_POISSON,
    RAPIER_YOUNG,
};
pub use tear_scene::{
    Fragment, SlabPull, TearEngine, TearSummary, PULL_DISTANCE, TEAR_GROUND_HALF_EXTENTS,
    TEAR_SMOOTHING, TEAR_STRAIN, TEAR_SUBSTEPS,
};
pub use xpbd64::{Xpbd64, Xpbd64Error};

/// Frame time step of every benchmark run, s.
pub const DT: f32 = 1.0 / 60.0;

/// The median of `samples` (the upper one of an even count; NaN when there are none).
pub fn median(mut samples: Vec<f64>) -> f64 {
    samples.sort_by(f64::total_cmp);
    samples.get(samples.len() / 2).copied().unwrap_or(f64::NAN)
}
