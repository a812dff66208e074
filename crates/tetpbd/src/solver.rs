//! The solver: a frame as `substeps × iterations` of the systems.

use std::time::Instant;

use hecs::World;
use nalgebra::Vector3;

use crate::error::SettingsError;
use crate::stats::{Family, StepStats};
use crate::systems;
use crate::work::{self, CopyMode};

/// Settings of a [`Solver`]. Fields are public; [`SolverSettings::validate`] (called by every
/// step) rejects bad values with a typed error before they reach the state.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct SolverSettings {
    /// Frame time step, s (> 0).
    pub dt: f32,
    /// Substeps per frame (≥ 1); each has length `h = dt / substeps`.
    pub substeps: u32,
    /// Constraint iterations per substep (≥ 1). Macklin et al. 2019 ("Small Steps in
    /// Physics Simulation") show that spending a budget on substeps beats iterations, so the
    /// default is many substeps of one iteration.
    pub iterations: u32,
    /// Gravity, m/s².
    pub gravity: Vector3<f32>,
    /// Linear velocity damping, 1/s (0 = none).
    pub damping: f32,
    /// The order in which the families are projected in an iteration. Default: volume,
    /// vertex–face, edge — edges last, so lengths are closest to rest at the end.
    pub order: [Family; 3],
    /// Safety net: the velocity a substep's projections add to a particle is clamped to this
    /// length, m/s (positions keep their full correction). `None` = no clamp. On a body
    /// without pinned particles, the linear and angular momentum the clamps removed are
    /// given back as a rigid velocity change of the whole body, so the net never changes the
    /// body's momentum; a body with pinned particles gets the per-particle clamp alone.
    /// Cost: a compare per particle per substep, plus two serial passes over a body's
    /// particles in substeps where it clamped one of them. See
    /// [`systems::update_velocities`]; clamps are counted in
    /// [`StepStats::velocity_clamps`].
    pub max_correction_speed: Option<f32>,
    /// Remove the rigid rotation the families' corrections carry, once per iteration, so
    /// that a free body's internal constraints conserve its angular momentum (default on).
    /// Gauss–Seidel projections conserve it only to second order, which in a body that
    /// cannot meet all its constraints (a tangled, self-intersecting state) is a steady
    /// torque: undamped, such a body spins itself up from rest. Bodies with pinned
    /// particles are left alone, as are a hook's contacts. Cost: the copy back from the
    /// working copy also measures the corrections, plus one more pass over a free body's
    /// particles per iteration (+2–13 % per frame, docs/performance.md); both counted in
    /// [`StepStats::spin_time`] instead of [`StepStats::copy_time`] (see the `spin` module
    /// docs).
    pub conserve_angular_momentum: bool,
    /// Scalar or SIMD projection kernels (default SIMD; they agree to rounding).
    pub kernel: systems::Kernel,
    /// Evaluate every constraint after the step to fill [`crate::FamilyStats::after`] and
    /// [`StepStats::inverted`]. Costs about one extra sweep; off by default.
    pub measure_error: bool,
    /// Also evaluate every constraint before the step ([`crate::FamilyStats::before`]).
    pub measure_before: bool,
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
            max_correction_speed: None,
            conserve_angular_momentum: true,
            kernel: systems::Kernel::Simd,
            measure_error: false,
            measure_before: false,
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
        if let Some(v) = self.max_correction_speed {
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
}

/// Extra work run inside the solver's substep loop, e.g. collision constraints of a
/// coupling crate. Every method has an empty default.
pub trait SubstepHook {
    /// Once per frame, before the first substep (gather collision candidates here).
    fn begin_frame(&mut self, _world: &mut World, _dt: f32) {}
    /// After prediction, before the first iteration of a substep.
    fn begin_substep(&mut self, _world: &mut World, _h: f32) {}
    /// Each iteration, after the internal constraint families.
    fn project(&mut self, _world: &mut World, _h: f32) {}
    /// After the velocity update of a substep (velocity-level friction and restitution).
    fn end_substep(&mut self, _world: &mut World, _h: f32) {}
    /// Once per frame, after the last substep.
    fn end_frame(&mut self, _world: &mut World, _dt: f32) {}
}

/// The empty hook.
impl SubstepHook for () {}

/// Two hooks run one after the other at every point (e.g. rigid coupling, then soft–soft
/// contacts).
impl<A: SubstepHook, B: SubstepHook> SubstepHook for (A, B) {
    fn begin_frame(&mut self, world: &mut World, dt: f32) {
        self.0.begin_frame(world, dt);
        self.1.begin_frame(world, dt);
    }
    fn begin_substep(&mut self, world: &mut World, h: f32) {
        self.0.begin_substep(world, h);
        self.1.begin_substep(world, h);
    }
    fn project(&mut self, world: &mut World, h: f32) {
        self.0.project(world, h);
        self.1.project(world, h);
    }
    fn end_substep(&mut self, world: &mut World, h: f32) {
        self.0.end_substep(world, h);
        self.1.end_substep(world, h);
    }
    fn end_frame(&mut self, world: &mut World, dt: f32) {
        self.0.end_frame(world, dt);
        self.1.end_frame(world, dt);
    }
}

/// A borrowed hook.
impl<H: SubstepHook + ?Sized> SubstepHook for &mut H {
    fn begin_frame(&mut self, world: &mut World, dt: f32) {
        (**self).begin_frame(world, dt);
    }
    fn begin_substep(&mut self, world: &mut World, h: f32) {
        (**self).begin_substep(world, h);
    }
    fn project(&mut self, world: &mut World, h: f32) {
        (**self).project(world, h);
    }
    fn end_substep(&mut self, world: &mut World, h: f32) {
        (**self).end_substep(world, h);
    }
    fn end_frame(&mut self, world: &mut World, dt: f32) {
        (**self).end_frame(world, dt);
    }
}

/// Runs frames of the soft-body systems on a [`hecs::World`].
///
/// ```text
/// for each of `substeps` substeps (h = dt / substeps):
///     predict            x_prev ← x; v ← (v + h(g + a))·damping; x ← x + h v
///     reset λ
///     repeat `iterations` times:
///         copy the particles into the projections' working copy (crate::work)
///         project families in `order` on it, remove the rigid rotation of their
///         corrections (conserve_angular_momentum), copy back, then hook.project
///     update velocities  v ← (x − x_prev) / h
///     hook.end_substep
/// ```
#[derive(Clone, Debug, Default)]
pub struct Solver {
    /// The settings used by the next step.
    pub settings: SolverSettings,
}

impl Solver {
    /// A solver with validated settings.
    pub fn new(settings: SolverSettings) -> Result<Solver, SettingsError> {
        settings.validate()?;
        Ok(Solver { settings })
    }

    /// Advances every soft body in `world` by one frame.
    pub fn step(&mut self, world: &mut World) -> Result<StepStats, SettingsError> {
        self.step_with(world, &mut ())
    }

    /// Advances every soft body by one frame, running `hook` inside the substep loop.
    pub fn step_with(
        &mut self,
        world: &mut World,
        hook: &mut dyn SubstepHook,
    ) -> Result<StepStats, SettingsError> {
        self.settings.validate()?;
        // With the `parallel` feature and a body large enough for a parallel pass, the pool's
        // other threads stay awake for the step (crate::team), so the passes need not wake
        // them.
        #[cfg(feature = "parallel")]
        if crate::parallel::any_parallel(world) {
            return crate::team::with_team(|| self.run_step(world, hook));
        }
        self.run_step(world, hook)
    }

    /// One frame with validated settings.
    fn run_step(
        &self,
        world: &mut World,
        hook: &mut dyn SubstepHook,
    ) -> Result<StepStats, SettingsError> {
        let s = &self.settings;
        let start = Instant::now();
        let mut stats = StepStats {
            substeps: s.substeps,
            iterations: s.iterations,
            ..StepStats::default()
        };
        count_constraints(world, &mut stats);
        if s.measure_before {
            let m = systems::measure(world);
            stats.edge.before = Some(m.edge);
            stats.vertex_face.before = Some(m.vertex_face);
            stats.volume.before = Some(m.volume);
        }
        let h = s.substep_dt();
        let t = Instant::now();
        hook.begin_frame(world, s.dt);
        let mut hook_time = t.elapsed();
        for _ in 0..s.substeps {
            let t = Instant::now();
            systems::predict(world, h, s.gravity, s.damping);
            systems::reset_lambdas(world);
            stats.predict_time += t.elapsed();
            let t = Instant::now();
            hook.begin_substep(world, h);
            hook_time += t.elapsed();
            for _ in 0..s.iterations {
                let t = Instant::now();
                work::load_bodies(world);
                stats.copy_time += t.elapsed();
                for family in s.order {
                    let t = Instant::now();
                    let c = systems::project_family(world, family, h, s.kernel, CopyMode::Resident);
                    let f = stats.family_mut(family);
                    f.time += t.elapsed();
                    f.projections += c.applied;
                    f.degenerate += c.degenerate;
                }
                let t = Instant::now();
                if s.conserve_angular_momentum {
                    crate::spin::store_bodies_without_spin(world);
                    stats.spin_time += t.elapsed();
                } else {
                    work::store_bodies(world);
                    stats.copy_time += t.elapsed();
                }
                let t = Instant::now();
                hook.project(world, h);
                hook_time += t.elapsed();
            }
            let t = Instant::now();
            let u = systems::update_velocities(world, h, s.max_correction_speed);
            stats.non_finite_resets += u.non_finite_resets;
            stats.velocity_clamps += u.clamped;
            stats.velocity_time += t.elapsed();
            let t = Instant::now();
            hook.end_substep(world, h);
            hook_time += t.elapsed();
        }
        let t = Instant::now();
        hook.end_frame(world, s.dt);
        hook_time += t.elapsed();
        stats.hook_time = hook_time;
        if s.measure_error {
            let t = Instant::now();
            let m = systems::measure(world);
            stats.edge.after = Some(m.edge);
            stats.vertex_face.after = Some(m.vertex_face);
            stats.volume.after = Some(m.volume);
            stats.inverted = Some(m.inverted);
            stats.measure_time = t.elapsed();
        }
        stats.total_time = start.elapsed();
        Ok(stats)
    }
}

fn count_constraints(world: &mut World, stats: &mut StepStats) {
    use crate::{EdgeConstraints, Particles, VertexFaceConstraints, VolumeConstraints};
    for p in world.query_mut::<&Particles>() {
        stats.bodies += 1;
        stats.particles += p.len();
    }
    for e in world.query_mut::<&EdgeConstraints>() {
        stats.edge.count += e.len();
    }
    for v in world.query_mut::<&VertexFaceConstraints>() {
        stats.vertex_face.count += v.len();
    }
    for v in world.query_mut::<&VolumeConstraints>() {
        stats.volume.count += v.len();
    }
}
