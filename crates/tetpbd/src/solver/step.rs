//! [`Solver`]: a frame as `substeps × iterations` of the systems; [`Solver::run_step`] is
//! where a frame and each of its substeps start.

use std::time::{Duration, Instant};

use hecs::World;
use nalgebra::Vector3;

use crate::body::activation::Asleep;
use crate::error::{SettingsError, StepError};
use crate::kernels::working_copy::{self, CopyMode};
use crate::solver::hook::{FrameContext, SubstepHook};
use crate::solver::settings::SolverSettings;
use crate::solver::sleeping;
use crate::solver::stats::StepStats;
use crate::solver::systems;
use crate::stabilisation::hook_work::{self, Changed};
use crate::stabilisation::{correction_energy, deformation_damping};

/// Runs frames of the soft-body systems on a [`hecs::World`].
///
/// ```text
/// for each of `substeps` substeps (h = dt / substeps):
///     predict            x_prev ← x; v ← (v + h(g + a + F/m))·damping; x ← x + h v
///     reset λ
///     repeat `iterations` times:
///         copy the particles into the projections' working copy (crate::kernels::working_copy)
///         project families in `order` on it, then the slivers' orientation constraints
///         once more (stabilisation::sliver_orientation), remove the rigid rotation of their
///         corrections (conserve_angular_momentum), limit the kinetic energy they add
///         (limit_correction_energy), copy back, project the grabs (Grab), then
///         hook.project
///     update velocities  v ← (x − x_prev) / h, then damp deformation (DeformationDamping)
///     hook.end_substep
/// after the last substep: the grabs' targets roll on (systems::roll_grab_targets), rest
///     shapes flow (systems::flow_plastically, bodies with a Plasticity)
/// after the frame (hook's end of frame, sleeping): faces tear (systems::tear_faces,
///     bodies with a Tearing); the events are in Solver::tear_events
/// ```
///
/// Threads (feature `parallel`): a step runs its parallel passes on the pool given to
/// [`Solver::set_thread_pool`] (e.g. the one the integrator gives rapier's pipeline), or
/// else in the caller's rayon context; [`SolverSettings::parallel`] makes it serial or
/// keeps the pool's threads awake for the step. The solver never changes rayon's global
/// pool.
#[derive(Clone, Debug, Default)]
pub struct Solver {
    /// The settings used by the next step.
    pub settings: SolverSettings,
    /// Pool running the parallel passes of a step; `None` uses whichever pool the calling
    /// thread is in.
    #[cfg(feature = "parallel")]
    thread_pool: Option<std::sync::Arc<rayon::ThreadPool>>,
    /// Scratch of the sleeping systems, kept so that a step allocates nothing.
    sleep: SleepScratch,
    /// What the last step's tearing pass did.
    events: Vec<crate::TearEvent>,
}

impl Solver {
    /// A solver with validated settings.
    pub fn new(settings: SolverSettings) -> Result<Solver, SettingsError> {
        settings.validate()?;
        Ok(Solver {
            settings,
            #[cfg(feature = "parallel")]
            thread_pool: None,
            sleep: SleepScratch::default(),
            events: Vec::new(),
        })
    }

    /// Advances every soft body in `world` by one frame.
    ///
    /// Errors: [`StepError::Settings`] (nothing stepped) or [`StepError::NonFiniteState`]
    /// (a particle was not finite at the start of a substep; it was restored and the frame
    /// stepped to its end, see the error's documentation).
    pub fn step(&mut self, world: &mut World) -> Result<StepStats, StepError> {
        self.step_with(world, &mut ())
    }

    /// Advances every soft body by one frame, running `hook` inside the substep loop.
    pub fn step_with(
        &mut self,
        world: &mut World,
        hook: &mut dyn SubstepHook,
    ) -> Result<StepStats, StepError> {
        let (dt, gravity) = (self.settings.dt, self.settings.gravity);
        self.step_frame(world, dt, gravity, hook)
    }

    /// Advances every soft body by one frame of length `dt` (s) under `gravity` (m/s²),
    /// running `hook` inside the substep loop: [`Solver::step_with`] with the frame's length
    /// and gravity given by the caller instead of taken from the settings, whose `dt` and
    /// `gravity` are neither used nor changed. For a caller whose clock and gravity belong
    /// to another engine, as a coupled scene's belong to its rigid-body engine.
    ///
    /// Errors: as [`Solver::step`]; `dt` and `gravity` are validated as the settings' own
    /// would be ([`SettingsError::BadDt`], [`SettingsError::NonFiniteGravity`] in
    /// [`StepError::Settings`]).
    pub fn step_frame(
        &mut self,
        world: &mut World,
        dt: f32,
        gravity: Vector3<f32>,
        hook: &mut dyn SubstepHook,
    ) -> Result<StepStats, StepError> {
        self.settings.validate_frame(dt, gravity)?;
        let frame = FrameContext::new(&self.settings, dt, gravity);
        let mut sleep = std::mem::take(&mut self.sleep);
        let mut out = self.run_step_in_pool(world, frame, hook, &mut sleep);
        self.sleep = sleep;
        // Tearing changes particle and surface counts: after the hook's end of frame, so a
        // hook sees one mesh per frame.
        let t = Instant::now();
        self.events.clear();
        crate::body::tear_relaxation::relax(world, dt, frame.h(), gravity);
        let torn = systems::tear_faces(world, dt, frame.h(), &mut self.events);
        if let Ok(stats) = &mut out {
            stats.faces_torn = torn;
            stats.tearing_time = t.elapsed();
            stats.total_time += stats.tearing_time;
        }
        out
    }

    /// What the last step's tearing pass did: one event per body that tore (empty in a
    /// frame without tearing). Cuts ([`crate::cut`]) return their events directly.
    pub fn tear_events(&self) -> &[crate::TearEvent] {
        &self.events
    }

    /// [`Solver::run_step`] in the solver's pool (feature `parallel`).
    fn run_step_in_pool(
        &self,
        world: &mut World,
        frame: FrameContext,
        hook: &mut dyn SubstepHook,
        sleep: &mut SleepScratch,
    ) -> Result<StepStats, StepError> {
        #[cfg(feature = "parallel")]
        {
            let p = self.settings.parallel;
            let _context = crate::parallel::context::enter(self.thread_pool.clone(), p.serial);
            // Asked for, and with a body large enough for a parallel pass, the pool's other
            // threads stay awake for the step (crate::parallel::team), so the passes need not
            // wake them.
            if p.keep_helpers_awake && crate::parallel::sweeps::any_parallel(world) {
                let move_off = p.move_helpers_off_step_core;
                return crate::parallel::team::with_team(move_off, || {
                    self.run_step(world, frame, hook, sleep)
                });
            }
            self.run_step(world, frame, hook, sleep)
        }
        #[cfg(not(feature = "parallel"))]
        self.run_step(world, frame, hook, sleep)
    }

    /// A dedicated pool of `num_threads` threads for this solver's parallel passes (0: rayon's
    /// default, one per core).
    #[cfg(feature = "parallel")]
    pub fn configure_thread_pool(
        &mut self,
        num_threads: usize,
    ) -> Result<(), rayon::ThreadPoolBuildError> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(num_threads)
            .thread_name(|i| format!("tetpbd-worker-{i}"))
            .build()?;
        self.thread_pool = Some(std::sync::Arc::new(pool));
        Ok(())
    }

    /// The pool running this solver's parallel passes, if it was given one.
    #[cfg(feature = "parallel")]
    pub fn thread_pool(&self) -> Option<std::sync::Arc<rayon::ThreadPool>> {
        self.thread_pool.clone()
    }

    /// Sets (or clears, with `None`) the pool running this solver's parallel passes, e.g.
    /// the one an integrator gives rapier's `PhysicsPipeline::set_thread_pool`. The step
    /// itself stays on the calling thread; each parallel pass runs on the pool's threads.
    #[cfg(feature = "parallel")]
    pub fn set_thread_pool(&mut self, pool: Option<std::sync::Arc<rayon::ThreadPool>>) {
        self.thread_pool = pool;
    }

    /// [`Solver::set_thread_pool`] as a builder.
    #[cfg(feature = "parallel")]
    pub fn with_thread_pool(mut self, pool: Option<std::sync::Arc<rayon::ThreadPool>>) -> Self {
        self.thread_pool = pool;
        self
    }

    /// Removes the dedicated pool: the parallel passes run in the calling thread's rayon
    /// context again.
    #[cfg(feature = "parallel")]
    pub fn clear_thread_pool(&mut self) {
        self.thread_pool = None;
    }

    /// The number of threads of the dedicated pool, if there is one.
    #[cfg(feature = "parallel")]
    pub fn num_threads(&self) -> Option<usize> {
        self.thread_pool.as_ref().map(|p| p.current_num_threads())
    }

    /// One frame with validated settings: the frame starts here, each substep in
    /// [`Solver::substep`].
    fn run_step(
        &self,
        world: &mut World,
        frame: FrameContext,
        hook: &mut dyn SubstepHook,
        sleep: &mut SleepScratch,
    ) -> Result<StepStats, StepError> {
        let s = &self.settings;
        let mut restored = crate::solver::non_finite::Restored::default();
        let start = Instant::now();
        let mut stats = StepStats {
            substeps: s.substeps,
            iterations: s.iterations,
            ..StepStats::default()
        };
        sleep.touching.clear();
        stats.bodies_woken = sleeping::wake_written(world, &mut sleep.entities);
        count_constraints(world, &mut stats);
        if s.diagnostics.measure_before {
            let m = systems::measure(world);
            stats.edge.before = Some(m.edge);
            stats.vertex_face.before = Some(m.vertex_face);
            stats.volume.before = Some(m.volume);
        }
        let t = Instant::now();
        hook.begin_frame(world, frame);
        let mut hook_time = t.elapsed();
        let asleep = count_asleep(world);
        stats.bodies_woken += stats.bodies_asleep.saturating_sub(asleep);
        stats.bodies_asleep = asleep;
        for i in 0..s.substeps {
            let r = self.substep(world, hook, frame, i, &mut stats, &mut hook_time);
            restored.count += r.count;
            restored.first = restored.first.or(r.first);
        }
        systems::roll_grab_targets(world);
        systems::flow_plastically(world, frame.dt());
        let t = Instant::now();
        hook.end_frame(world, frame);
        hook.touching(world, &mut sleep.touching);
        hook_time += t.elapsed();
        stats.hook_time = hook_time;
        if !hook.moves_particles() {
            let g = frame.gravity();
            stats.bodies_untangled =
                crate::stabilisation::untangle::untangle_bodies(world, frame.dt(), g);
        }
        let slept = sleeping::fall_asleep(world, frame.dt(), &sleep.touching, &mut sleep.islands);
        stats.bodies_fell_asleep = slept.fell_asleep;
        stats.bodies_asleep_after = slept.asleep;
        if s.diagnostics.measure_error {
            let t = Instant::now();
            let m = systems::measure(world);
            stats.edge.after = Some(m.edge);
            stats.vertex_face.after = Some(m.vertex_face);
            stats.volume.after = Some(m.volume);
            stats.inverted = Some(m.inverted);
            stats.measure_time = t.elapsed();
        }
        stats.total_time = start.elapsed();
        stats.non_finite_restored = restored.count;
        match restored.first {
            None => Ok(stats),
            Some((entity, particle, what, value)) => Err(StepError::NonFiniteState {
                entity,
                particle,
                what,
                value,
                restored: restored.count,
            }),
        }
    }

    /// Substep `index` of `frame` (length `h = dt / substeps`): prediction, `iterations`
    /// iterations, the velocity update. Returns the particles prediction found non-finite
    /// and restored.
    fn substep(
        &self,
        world: &mut World,
        hook: &mut dyn SubstepHook,
        frame: FrameContext,
        index: u32,
        stats: &mut StepStats,
        hook_time: &mut Duration,
    ) -> crate::solver::non_finite::Restored {
        let s = &self.settings;
        let h = frame.h();
        let t = Instant::now();
        let restored = systems::predict(world, h, frame.gravity(), s.damping);
        systems::reset_lambdas(world);
        stats.predict_time += t.elapsed();
        // The hook's and the grabs' corrections are external work in the correction-energy
        // budget.
        let grabs = world
            .query_mut::<&crate::Grab>()
            .into_iter()
            .next()
            .is_some();
        let measure =
            (s.safety.limit_correction_energy && (grabs || hook.moves_particles())).then_some(h);
        let t = Instant::now();
        measured(world, measure, Changed::Positions, |w| {
            hook.begin_substep(w, frame.substep(index, 0))
        });
        *hook_time += t.elapsed();
        let frac = (index + 1) as f32 / s.substeps as f32;
        for k in 0..s.iterations {
            self.iteration(world, (h, frame.gravity()), stats);
            let t = Instant::now();
            measured(world, measure, Changed::Positions, |w| {
                systems::project_grabs(w, h, frac);
                hook.project(w, frame.substep(index, k))
            });
            *hook_time += t.elapsed();
        }
        let t = Instant::now();
        let u = systems::update_velocities(world, h, s.safety.max_correction_speed);
        stats.non_finite_resets += u.non_finite_resets;
        stats.velocity_clamps += u.clamped;
        deformation_damping::damp_deformation(world, h);
        stats.velocity_time += t.elapsed();
        let t = Instant::now();
        measured(world, measure, Changed::Velocities, |w| {
            hook.end_substep(w, frame.substep(index, 0))
        });
        *hook_time += t.elapsed();
        restored
    }

    /// One iteration: copy the particles into the working copy, project the families in
    /// order, copy back (removing the corrections' rigid rotation and limiting the kinetic
    /// energy they add, if asked).
    fn iteration(
        &self,
        world: &mut World,
        (h, gravity): (f32, Vector3<f32>),
        stats: &mut StepStats,
    ) {
        let s = &self.settings;
        let t = Instant::now();
        working_copy::load_bodies(world);
        stats.copy_time += t.elapsed();
        let t = Instant::now();
        let c = crate::solver::material_systems::project_neo_hookean_in(
            world,
            h,
            s.kernel,
            CopyMode::Resident,
        );
        stats.material.time += t.elapsed();
        stats.material.projections += c.applied;
        stats.material.degenerate += c.degenerate;
        for family in s.order {
            let t = Instant::now();
            let c = systems::project_family(world, family, h, s.kernel, CopyMode::Resident);
            let f = stats.family_mut(family);
            f.time += t.elapsed();
            f.projections += c.applied;
            f.degenerate += c.degenerate;
        }
        crate::stabilisation::sliver_orientation::project_slivers(world, h);
        let t = Instant::now();
        if s.safety.conserve_angular_momentum || s.safety.limit_correction_energy {
            let (spin, limit) = (
                s.safety.conserve_angular_momentum,
                s.safety.limit_correction_energy,
            );
            stats.energy_limited +=
                correction_energy::store_bodies(world, (h, gravity, s.damping), spin, limit);
            stats.spin_time += t.elapsed();
        } else {
            working_copy::store_bodies(world);
            stats.copy_time += t.elapsed();
        }
    }
}

/// Scratch of the sleeping systems for one frame.
#[derive(Clone, Debug, Default)]
struct SleepScratch {
    entities: Vec<(hecs::Entity, bool)>,
    islands: sleeping::Islands,
    touching: sleeping::Touching,
}

/// Runs a hook call, measuring the kinetic energy its corrections hand the families
/// ([`crate::stabilisation::hook_work`]) in a substep of length `measure` (s), if given.
fn measured(
    world: &mut World,
    measure: Option<f32>,
    changed: Changed,
    call: impl FnOnce(&mut World),
) {
    if measure.is_some() {
        hook_work::before_hook(world, changed);
    }
    call(world);
    if let Some(h) = measure {
        hook_work::after_hook(world, h, changed);
    }
}

/// Counts the bodies, and the particles and constraints of the awake ones.
fn count_constraints(world: &mut World, stats: &mut StepStats) {
    use crate::{EdgeConstraints, Particles, VertexFaceConstraints, VolumeConstraints};
    for (p, asleep) in world.query_mut::<(&Particles, Option<&Asleep>)>() {
        stats.bodies += 1;
        if asleep.is_some() {
            stats.bodies_asleep += 1;
        } else {
            stats.particles += p.len();
        }
    }
    for e in world.query_mut::<&EdgeConstraints>().without::<&Asleep>() {
        stats.edge.count += e.len();
    }
    for v in world
        .query_mut::<&VertexFaceConstraints>()
        .without::<&Asleep>()
    {
        stats.vertex_face.count += v.len();
    }
    for v in world.query_mut::<&VolumeConstraints>().without::<&Asleep>() {
        stats.volume.count += v.len();
    }
    for m in world
        .query_mut::<&crate::NeoHookeanMaterial>()
        .without::<&Asleep>()
    {
        stats.material.count += m.len();
    }
}

/// The bodies asleep.
fn count_asleep(world: &mut World) -> usize {
    world.query_mut::<&Asleep>().into_iter().count()
}
