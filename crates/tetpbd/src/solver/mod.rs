//! The solver: [`Solver`](step::Solver) runs a frame as `substeps × iterations` of the
//! [`systems`], configured by [`SolverSettings`](settings::SolverSettings), with a
//! [`SubstepHook`](hook::SubstepHook) for work of other crates (contacts, attachments) and
//! [`StepStats`](stats::StepStats) as its report. A substep starts in `step.rs`
//! (`Solver::substep`).

pub(crate) mod hook;
pub(crate) mod material_systems;
pub(crate) mod non_finite;
pub(crate) mod plastic_flow;
pub(crate) mod settings;
pub(crate) mod sleeping;
pub(crate) mod stats;
pub(crate) mod step;
pub mod systems;
pub(crate) mod tearing_pass;
