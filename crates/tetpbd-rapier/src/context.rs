//! [`RapierContext`]: the integrator's rapier state, borrowed for one coupled step.

use rapier3d::dynamics::{
    CCDSolver, ImpulseJointSet, IntegrationParameters, IslandManager, MultibodyJointSet,
    RigidBodySet, SoftBodySet,
};
use rapier3d::geometry::{BroadPhaseBvh, ColliderSet, NarrowPhase};
use rapier3d::math::Vector;
use rapier3d::pipeline::{EventHandler, PhysicsHooks, PhysicsPipeline, PhysicsWorld};

/// The user's rapier state, borrowed for one coupled step. Every field is the argument of
/// the same name of [`PhysicsPipeline::step`]; the integrator keeps owning all of it.
pub struct RapierContext<'a> {
    /// The integrator's physics pipeline.
    pub pipeline: &'a mut PhysicsPipeline,
    /// Gravity, m/s²: the scene's, for the rigid and the soft bodies alike.
    pub gravity: Vector,
    /// Integration parameters; their `dt` is the scene's frame time, for the soft bodies too.
    pub integration_parameters: &'a IntegrationParameters,
    /// Islands.
    pub islands: &'a mut IslandManager,
    /// Broad phase; its BVH finds the colliders near each soft body.
    pub broad_phase: &'a mut BroadPhaseBvh,
    /// Narrow phase (its query dispatcher runs the queries).
    pub narrow_phase: &'a mut NarrowPhase,
    /// Rigid bodies.
    pub bodies: &'a mut RigidBodySet,
    /// Colliders.
    pub colliders: &'a mut ColliderSet,
    /// Impulse joints.
    pub impulse_joints: &'a mut ImpulseJointSet,
    /// Multibody joints.
    pub multibody_joints: &'a mut MultibodyJointSet,
    /// rapier's own soft bodies (independent of `tetpbd`'s).
    pub soft_bodies: &'a mut SoftBodySet,
    /// CCD solver.
    pub ccd_solver: &'a mut CCDSolver,
    /// Physics hooks.
    pub hooks: &'a dyn PhysicsHooks,
    /// Event handler.
    pub events: &'a dyn EventHandler,
}

impl<'a> RapierContext<'a> {
    /// Borrows the integrator's rapier state: the arguments of [`PhysicsPipeline::step`] in
    /// its order, without the hooks and the event handler (none until
    /// [`RapierContext::with_hooks`] and [`RapierContext::with_events`] give them). An
    /// integrator's `pipeline.step(gravity, &params, …, &mut ccd, &hooks, &events)` becomes
    /// `RapierContext::new(&mut pipeline, gravity, &params, …, &mut ccd)` followed by the
    /// two `with_` calls. Gravity is rapier's (glam) vector, m/s².
    ///
    /// ```
    /// use rapier3d::prelude::*;
    /// use tetpbd_rapier::{Coupling, RapierContext};
    ///
    /// // An integrator's own rapier state, as in rapier's examples.
    /// let mut pipeline = PhysicsPipeline::new();
    /// let params = IntegrationParameters::default();
    /// let (mut islands, mut broad_phase, mut narrow_phase) =
    ///     (IslandManager::new(), DefaultBroadPhase::default(), NarrowPhase::new());
    /// let (mut bodies, mut colliders) = (RigidBodySet::new(), ColliderSet::new());
    /// let (mut impulse_joints, mut multibody_joints) =
    ///     (ImpulseJointSet::new(), MultibodyJointSet::new());
    /// let (mut soft_bodies, mut ccd) = (SoftBodySet::new(), CCDSolver::new());
    /// let events = ();
    ///
    /// let mut coupling = Coupling::new(Default::default(), Default::default())?;
    /// let mut soft = hecs::World::new();
    /// let ctx = RapierContext::new(
    ///     &mut pipeline, Vector::new(0.0, -9.81, 0.0), &params, &mut islands,
    ///     &mut broad_phase, &mut narrow_phase, &mut bodies, &mut colliders,
    ///     &mut impulse_joints, &mut multibody_joints, &mut soft_bodies, &mut ccd,
    /// )
    /// .with_events(&events);
    /// coupling.step(&mut soft, ctx)?;
    /// # Ok::<(), tetpbd_rapier::CouplingError>(())
    /// ```
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        pipeline: &'a mut PhysicsPipeline,
        gravity: Vector,
        integration_parameters: &'a IntegrationParameters,
        islands: &'a mut IslandManager,
        broad_phase: &'a mut BroadPhaseBvh,
        narrow_phase: &'a mut NarrowPhase,
        bodies: &'a mut RigidBodySet,
        colliders: &'a mut ColliderSet,
        impulse_joints: &'a mut ImpulseJointSet,
        multibody_joints: &'a mut MultibodyJointSet,
        soft_bodies: &'a mut SoftBodySet,
        ccd_solver: &'a mut CCDSolver,
    ) -> Self {
        RapierContext {
            pipeline,
            gravity,
            integration_parameters,
            islands,
            broad_phase,
            narrow_phase,
            bodies,
            colliders,
            impulse_joints,
            multibody_joints,
            soft_bodies,
            ccd_solver,
            hooks: &(),
            events: &(),
        }
    }

    /// The physics hooks rapier's step runs with (none by default).
    pub fn with_hooks(mut self, hooks: &'a dyn PhysicsHooks) -> Self {
        self.hooks = hooks;
        self
    }

    /// The event handler rapier's step reports its collision and contact-force events to
    /// (none by default). The soft contacts are reported by [`crate::Coupling::contacts`].
    pub fn with_events(mut self, events: &'a dyn EventHandler) -> Self {
        self.events = events;
        self
    }

    /// Borrows every part of a rapier [`PhysicsWorld`], with no hooks and no events (the
    /// `with_` calls add them).
    pub fn from_physics_world(w: &'a mut PhysicsWorld) -> Self {
        RapierContext {
            pipeline: &mut w.physics_pipeline,
            gravity: w.gravity,
            integration_parameters: &w.integration_parameters,
            islands: &mut w.islands,
            broad_phase: &mut w.broad_phase,
            narrow_phase: &mut w.narrow_phase,
            bodies: &mut w.bodies,
            colliders: &mut w.colliders,
            impulse_joints: &mut w.impulse_joints,
            multibody_joints: &mut w.multibody_joints,
            soft_bodies: &mut w.soft_bodies,
            ccd_solver: &mut w.ccd_solver,
            hooks: &(),
            events: &(),
        }
    }
}

/// [`RapierContext::from_physics_world`].
impl<'a> From<&'a mut PhysicsWorld> for RapierContext<'a> {
    fn from(w: &'a mut PhysicsWorld) -> Self {
        RapierContext::from_physics_world(w)
    }
}
