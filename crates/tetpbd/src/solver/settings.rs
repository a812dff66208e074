//! Settings of the solver: time step, substeps, iterations, gravity, damping, family order,
//! and the groups of safety mechanisms, diagnostics and threads, with their units and
//! defaults.

use nalgebra::Vector3;

use crate::body::families::Family;
use crate::error::SettingsError;
use crate::solver::systems;

/// Settings of a [`Solver`](crate::Solver). Fields are public; [`SolverSettings::validate`] (called by every
/// step) rejects bad values with a typed error before they reach the state.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct SolverSettings {
    /// Frame time step, s (> 0). The length of a frame of [`Solver::step`](crate::Solver::step)
    /// and [`Solver::step_with`](crate::Solver::step_with); not used by
    /// [`Solver::step_frame`](crate::Solver::step_frame), whose caller gives the frame's length
    /// (in a scene coupled to rapier, rapier's `IntegrationParameters::dt` is the frame's, and
    /// `tetpbd-rapier` rejects a value here other than the default or rapier's).
    pub dt: f32,
    /// Substeps per frame (≥ 1); each has length `h = dt / substeps`.
    pub substeps: u32,
    /// Constraint iterations per substep (≥ 1). Macklin et al. 2019 ("Small Steps in
    /// Physics Simulation") show that spending a budget on substeps beats iterations, so the
    /// default is many substeps of one iteration.
    pub iterations: u32,
    /// Gravity, m/s². Used by [`Solver::step`](crate::Solver::step) and
    /// [`Solver::step_with`](crate::Solver::step_with); not by
    /// [`Solver::step_frame`](crate::Solver::step_frame), whose caller gives the frame's
    /// gravity (in a scene coupled to rapier, rapier's gravity is the frame's, and
    /// `tetpbd-rapier` rejects a value here other than the default or rapier's).
    pub gravity: Vector3<f32>,
    /// Linear velocity damping, 1/s (0 = none).
    pub damping: f32,
    /// The order in which the families are projected in an iteration. Default: volume,
    /// vertex–face, edge — edges last, so lengths are closest to rest at the end.
    pub order: [Family; 3],
    /// The safety mechanisms that keep a body calm when its constraints cannot all be met
    /// (tangled or crushed states, impacts). The defaults are what the README's claims and
    /// the stability matrix measure; change them only to reproduce a measurement.
    #[cfg_attr(feature = "serde", serde(default))]
    pub safety: SafetySettings,
    /// Scalar or SIMD projection kernels (default SIMD; they agree to rounding).
    pub kernel: systems::Kernel,
    /// What a step measures beyond what it needs (off by default: each costs about a
    /// sweep).
    #[cfg_attr(feature = "serde", serde(default))]
    pub diagnostics: DiagnosticSettings,
    /// How the parallel passes use threads (feature `parallel`; ignored without it). The
    /// pool they run on is not a setting but a handle: [`Solver::set_thread_pool`](crate::Solver).
    #[cfg_attr(feature = "serde", serde(default))]
    pub parallel: ParallelSettings,
}

/// The solver's safety mechanisms (a group of [`SolverSettings`]): what keeps a body calm and
/// its energy bounded when its constraints cannot all be met. Theory in the
/// `stabilisation` module docs; the decisions and their measurements in
/// `docs/decisions/correction-energy.md`, `angular-momentum-removal.md` and
/// `correction-speed-net-opt-in.md`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
pub struct SafetySettings {
    /// Safety net: the velocity a substep's projections add to a particle is clamped to this
    /// length, m/s (positions keep their full correction). `None` = no clamp. On a body
    /// without pinned particles, the linear and angular momentum the clamps removed are
    /// given back as a rigid velocity change of the whole body, so the net never changes the
    /// body's momentum; a body with pinned particles gets the per-particle clamp alone.
    /// Cost: a compare per particle per substep, plus two serial passes over a body's
    /// particles in substeps where it clamped one of them. See
    /// [`systems::update_velocities`]; clamps are counted in
    /// [`crate::StepStats::velocity_clamps`].
    pub max_correction_speed: Option<f32>,
    /// Remove the rigid rotation the families' corrections carry, once per iteration, so
    /// that a free body's internal constraints conserve its angular momentum (default on).
    /// Gauss–Seidel projections conserve it only to second order, which in a body that
    /// cannot meet all its constraints (a tangled, self-intersecting state) is a steady
    /// torque: undamped, such a body spins itself up from rest. Bodies with pinned
    /// particles are left alone, as are a hook's contacts. Cost: the copy back from the
    /// working copy also measures the corrections, plus one more pass over a free body's
    /// particles per iteration (a few per cent of a frame); both counted in
    /// [`crate::StepStats::spin_time`] instead of [`crate::StepStats::copy_time`].
    pub conserve_angular_momentum: bool,
    /// Keep the families' corrections from adding more kinetic energy to a body than the
    /// elastic energy their compliant constraints release (default **on**): a violation that
    /// was there before the substep (a tangled or collapsed start, a body crushed by an
    /// impact) is corrected in position without becoming velocity, so hard constraints never
    /// add energy. One scale per body and iteration keeps linear and angular momentum. A
    /// hook's impulses (contacts, attachments: what it moves in `begin_substep`/`project`
    /// and changes in `end_substep`) are external work added to the budget, so bodies resting
    /// and sliding on contacts move as without the limit; corrections at the rounding of the
    /// positions are left alone. Cost: a few multiply–adds per particle in the copy back from
    /// the working copy, a pass in iterations where it acts (counted in
    /// [`crate::StepStats::energy_limited`]), and one copy and pass over the particles per
    /// hook call that moves them ([`crate::SubstepHook::moves_particles`]). Theory in
    /// `stabilisation::correction_energy` and `stabilisation::hook_work`.
    pub limit_correction_energy: bool,
}

impl Default for SafetySettings {
    fn default() -> Self {
        SafetySettings {
            max_correction_speed: None,
            conserve_angular_momentum: true,
            limit_correction_energy: true,
        }
    }
}

/// What a step measures for the caller (a group of [`SolverSettings`]; all off by default).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
pub struct DiagnosticSettings {
    /// Evaluate every constraint after the step to fill [`crate::FamilyStats::after`] and
    /// [`crate::StepStats::inverted`]. Costs about one extra sweep; off by default.
    pub measure_error: bool,
    /// Also evaluate every constraint before the step ([`crate::FamilyStats::before`]).
    pub measure_before: bool,
}

/// How a step uses threads (feature `parallel`; without it every step is serial and these
/// are ignored). Results are bit-identical for every combination and any number of threads.
///
/// Where a step runs: on the pool given to
/// [`Solver::set_thread_pool`](crate::Solver), or else in the caller's rayon context (the
/// pool whose thread calls the step, or rayon's global pool from any other thread). The
/// solver never builds, resizes or configures the global pool.
///
/// By default a parallel pass enters the pool through plain rayon (`join`) and the pool's
/// threads go back to sleep between passes, as rayon's do; nothing touches a thread's CPU
/// mask. The two `*_helpers_*` options trade that politeness for speed on machines the
/// simulation has to itself.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(default))]
pub struct ParallelSettings {
    /// Run every pass on the stepping thread, whatever the pool (default `false`). Turn on
    /// when the host's threads are busy with other work of the same frame, or to rule
    /// threads out while debugging.
    pub serial: bool,
    /// Keep the pool's other threads waiting for work, spinning and yielding, from one
    /// parallel pass to the next for the whole step, instead of letting them sleep between
    /// passes (default `false`). A helper still leaves after 0.5 ms without a pass (e.g. a
    /// long hook), so the spinning is bounded, but while a step runs it holds every core of
    /// the pool. Worth turning on for large bodies (≳ 50k tetrahedra) when the simulation
    /// has the pool's cores to itself: it saves the wake-up of the sleeping threads at each
    /// of the dozens of passes of a frame. Takes effect only when the step runs on one of
    /// the pool's threads (called inside `pool.install(..)`); a step called from another
    /// thread hands each pass to the pool as by default.
    pub keep_helpers_awake: bool,
    /// Linux only, and only with [`ParallelSettings::keep_helpers_awake`]: a helper that finds
    /// itself on the stepping thread's core narrows its own CPU mask to the other cores it
    /// may use, and restores its mask when it stops helping (default `false`). The kernel
    /// often wakes a helper on its waker's core, where two spinning threads run no faster
    /// than one. Changes the CPU mask of the pool's threads for the duration of a step:
    /// turn on only for a pool the simulation owns, on a machine it has to itself.
    pub move_helpers_off_step_core: bool,
}

impl Default for SolverSettings {
    fn default() -> Self {
        SolverSettings {
            dt: 1.0 / 60.0,
            substeps: 10,
            iterations: 1,
            gravity: Vector3::new(0.0, -9.81, 0.0),
            damping: 0.0,
            order: Family::ALL,
            safety: SafetySettings::default(),
            kernel: systems::Kernel::Simd,
            diagnostics: DiagnosticSettings::default(),
            parallel: ParallelSettings::default(),
        }
    }
}

impl SolverSettings {
    /// Checks every field; the first bad one is returned.
    pub fn validate(&self) -> Result<(), SettingsError> {
        if !(self.dt.is_finite() && self.dt > 0.0) {
            return Err(SettingsError::BadDt { value: self.dt });
        }
        if self.substeps == 0 {
            return Err(SettingsError::ZeroCount { what: "substeps" });
        }
        if self.iterations == 0 {
            return Err(SettingsError::ZeroCount { what: "iterations" });
        }
        if !self.gravity.iter().all(|g| g.is_finite()) {
            return Err(SettingsError::NonFiniteGravity);
        }
        if !(self.damping.is_finite() && self.damping >= 0.0) {
            return Err(SettingsError::BadDamping {
                value: self.damping,
            });
        }
        if let Some(v) = self.safety.max_correction_speed {
            if !(v.is_finite() && v > 0.0) {
                return Err(SettingsError::BadCorrectionSpeed { value: v });
            }
        }
        let mut seen = [false; 3];
        for f in self.order {
            let i = f as usize;
            if seen[i] {
                return Err(SettingsError::BadOrder);
            }
            seen[i] = true;
        }
        Ok(())
    }

    /// Substep length `dt / substeps`, s.
    pub fn substep_dt(&self) -> f32 {
        self.dt / self.substeps as f32
    }

    /// [`SolverSettings::validate`] for a frame of length `dt` (s) under `gravity` (m/s²)
    /// given by the caller: those are checked in place of the settings' own `dt` and
    /// `gravity`, which are not looked at ([`crate::Solver::step_frame`]).
    pub fn validate_frame(&self, dt: f32, gravity: Vector3<f32>) -> Result<(), SettingsError> {
        SolverSettings {
            dt,
            gravity,
            ..self.clone()
        }
        .validate()
    }
}
