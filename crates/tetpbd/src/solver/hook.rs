//! [`SubstepHook`]: extra work run inside the solver's substep loop, and the
//! [`FrameContext`] and [`SubstepContext`] the solver hands it.
//!
//! A frame of length `dt` runs `substeps` substeps of length `h = dt / substeps`, each of
//! `iterations` iterations (`solver::step`). The solver calls a hook at five points:
//!
//! | call | when | context |
//! |---|---|---|
//! | [`SubstepHook::begin_frame`] | once, before the first substep | [`FrameContext`] |
//! | [`SubstepHook::begin_substep`] | after the prediction of substep `i` | [`SubstepContext`], iteration 0 |
//! | [`SubstepHook::project`] | after the internal families of iteration `k` of substep `i` | [`SubstepContext`], iteration `k` |
//! | [`SubstepHook::end_substep`] | after the velocity update of substep `i` | [`SubstepContext`], iteration 0 |
//! | [`SubstepHook::end_frame`] | once, after the last substep | [`FrameContext`] |
//!
//! The context is everything a hook needs to know about where it runs, so that it never
//! counts calls or copies solver settings of its own: the frame's length and gravity (those
//! the frame runs with, which a caller of [`Solver::step_frame`](crate::Solver::step_frame)
//! gives instead of the settings'), the substep count and length, the substep index `i`
//! (0-based), and in [`SubstepHook::project`] the iteration index `k`. A hook that
//! interpolates something across the frame (a rigid body's motion, an animated target)
//! stands at `(i + 1) / substeps` of it at the end of substep `i`. The frame also carries,
//! unreadable outside the crate, the solver's family order and projection kernel, with which
//! [`GroundUpSweep`](crate::GroundUpSweep) projects a body the way the solver's own sweeps
//! do.

use hecs::World;
use nalgebra::Vector3;

use crate::body::families::Family;
use crate::kernels::count::Kernel;
use crate::solver::settings::SolverSettings;
use crate::solver::sleeping::Touching;

/// The frame a [`SubstepHook`] runs in, as the solver runs it: its length and gravity (the
/// ones passed to [`Solver::step_frame`](crate::Solver::step_frame), which are the settings'
/// own for [`Solver::step`](crate::Solver::step)) and its schedule. Also carries the
/// solver's family order and kernel, which [`GroundUpSweep`](crate::GroundUpSweep) projects
/// with.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameContext {
    dt: f32,
    gravity: Vector3<f32>,
    substeps: u32,
    iterations: u32,
    h: f32,
    pub(crate) order: [Family; 3],
    pub(crate) kernel: Kernel,
}

impl FrameContext {
    /// The frame of a step with `settings` (their substeps, iterations, family order and
    /// kernel) that lasts `dt` (s) under `gravity` (m/s²). For an integrator who runs the
    /// [`systems`](crate::systems) on a schedule of their own and calls a hook from it.
    pub fn new(settings: &SolverSettings, dt: f32, gravity: Vector3<f32>) -> FrameContext {
        let substeps = settings.substeps;
        FrameContext {
            dt,
            gravity,
            substeps,
            iterations: settings.iterations,
            h: dt / substeps as f32,
            order: settings.order,
            kernel: settings.kernel,
        }
    }

    /// Frame length, s.
    pub fn dt(&self) -> f32 {
        self.dt
    }

    /// Gravity of the frame, m/s².
    pub fn gravity(&self) -> Vector3<f32> {
        self.gravity
    }

    /// Substeps of the frame (≥ 1 once the settings are valid).
    pub fn substeps(&self) -> u32 {
        self.substeps
    }

    /// Constraint iterations of each substep.
    pub fn iterations(&self) -> u32 {
        self.iterations
    }

    /// Substep length `dt / substeps`, s.
    pub fn h(&self) -> f32 {
        self.h
    }

    /// The context of substep `substep` (0-based) of this frame, at iteration `iteration`
    /// (0-based; 0 outside [`SubstepHook::project`]).
    pub fn substep(&self, substep: u32, iteration: u32) -> SubstepContext {
        SubstepContext {
            frame: *self,
            substep,
            iteration,
        }
    }
}

/// Where in a frame a [`SubstepHook`] call falls: the frame ([`SubstepContext::frame`]),
/// the substep and, in [`SubstepHook::project`], the iteration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SubstepContext {
    frame: FrameContext,
    substep: u32,
    iteration: u32,
}

impl SubstepContext {
    /// The frame this substep belongs to.
    pub fn frame(&self) -> &FrameContext {
        &self.frame
    }

    /// Index of this substep in the frame, 0-based (`< substeps()`).
    pub fn substep(&self) -> u32 {
        self.substep
    }

    /// Substeps of the frame.
    pub fn substeps(&self) -> u32 {
        self.frame.substeps
    }

    /// In [`SubstepHook::project`], the index of the iteration just projected, 0-based
    /// (`< iterations()`); 0 in the other calls.
    pub fn iteration(&self) -> u32 {
        self.iteration
    }

    /// Constraint iterations of each substep.
    pub fn iterations(&self) -> u32 {
        self.frame.iterations
    }

    /// Substep length, s.
    pub fn h(&self) -> f32 {
        self.frame.h
    }

    /// Frame length, s.
    pub fn dt(&self) -> f32 {
        self.frame.dt
    }

    /// Gravity of the frame, m/s².
    pub fn gravity(&self) -> Vector3<f32> {
        self.frame.gravity
    }
}

/// Extra work run inside the solver's substep loop, e.g. collision constraints of a
/// coupling crate. Every method has an empty default.
pub trait SubstepHook {
    /// Once per frame, before the first substep (gather collision candidates here).
    fn begin_frame(&mut self, _world: &mut World, _frame: FrameContext) {}
    /// After prediction, before the first iteration of a substep.
    fn begin_substep(&mut self, _world: &mut World, _substep: SubstepContext) {}
    /// Each iteration, after the internal constraint families.
    fn project(&mut self, _world: &mut World, _substep: SubstepContext) {}
    /// After the velocity update of a substep (velocity-level friction and restitution).
    fn end_substep(&mut self, _world: &mut World, _substep: SubstepContext) {}
    /// Once per frame, after the last substep.
    fn end_frame(&mut self, _world: &mut World, _frame: FrameContext) {}
    /// Once per frame, after [`SubstepHook::end_frame`]: adds the soft bodies that touch
    /// each other, and those something awake keeps awake, to `touching` (the islands of
    /// sleeping, [`crate::Activation`]). The default adds nothing: every body is its own
    /// island.
    fn touching(&mut self, _world: &mut World, _touching: &mut Touching) {}
    /// Whether [`SubstepHook::begin_substep`] or [`SubstepHook::project`] may move particles,
    /// or [`SubstepHook::end_substep`] change their velocities (default `true`). For a hook
    /// that does, the solver measures the kinetic energy its impulses hand the constraint
    /// families (external work in the budget of
    /// [`crate::SafetySettings::limit_correction_energy`]): one copy of the positions or
    /// velocities and one pass over them per call. A hook that never moves a particle may return `false`
    /// to skip that.
    fn moves_particles(&self) -> bool {
        true
    }
}

/// The empty hook.
impl SubstepHook for () {
    fn moves_particles(&self) -> bool {
        false
    }
}

/// Two hooks run one after the other at every point (e.g. rigid coupling, then soft–soft
/// contacts).
impl<A: SubstepHook, B: SubstepHook> SubstepHook for (A, B) {
    fn begin_frame(&mut self, world: &mut World, frame: FrameContext) {
        self.0.begin_frame(world, frame);
        self.1.begin_frame(world, frame);
    }
    fn begin_substep(&mut self, world: &mut World, substep: SubstepContext) {
        self.0.begin_substep(world, substep);
        self.1.begin_substep(world, substep);
    }
    fn project(&mut self, world: &mut World, substep: SubstepContext) {
        self.0.project(world, substep);
        self.1.project(world, substep);
    }
    fn end_substep(&mut self, world: &mut World, substep: SubstepContext) {
        self.0.end_substep(world, substep);
        self.1.end_substep(world, substep);
    }
    fn end_frame(&mut self, world: &mut World, frame: FrameContext) {
        self.0.end_frame(world, frame);
        self.1.end_frame(world, frame);
    }
    fn touching(&mut self, world: &mut World, touching: &mut Touching) {
        self.0.touching(world, touching);
        self.1.touching(world, touching);
    }
    fn moves_particles(&self) -> bool {
        self.0.moves_particles() || self.1.moves_particles()
    }
}

/// A borrowed hook.
impl<H: SubstepHook + ?Sized> SubstepHook for &mut H {
    fn begin_frame(&mut self, world: &mut World, frame: FrameContext) {
        (**self).begin_frame(world, frame);
    }
    fn begin_substep(&mut self, world: &mut World, substep: SubstepContext) {
        (**self).begin_substep(world, substep);
    }
    fn project(&mut self, world: &mut World, substep: SubstepContext) {
        (**self).project(world, substep);
    }
    fn end_substep(&mut self, world: &mut World, substep: SubstepContext) {
        (**self).end_substep(world, substep);
    }
    fn end_frame(&mut self, world: &mut World, frame: FrameContext) {
        (**self).end_frame(world, frame);
    }
    fn touching(&mut self, world: &mut World, touching: &mut Touching) {
        (**self).touching(world, touching);
    }
    fn moves_particles(&self) -> bool {
        (**self).moves_particles()
    }
}
