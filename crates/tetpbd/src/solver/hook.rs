//! [`SubstepHook`]: extra work run inside the solver's substep loop.

use hecs::World;

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
