//! [`CoupledWorld`]: a convenience that owns a rapier [`PhysicsWorld`], a hecs world of soft
//! bodies and the [`Coupling`], for quick scenes and tests.

use hecs::World;
use rapier3d::pipeline::{PhysicsWorld, QueryPipeline};
use tetpbd::{SolverSettings, SubstepHook};

use crate::context::RapierContext;
use crate::coupling::Coupling;
use crate::error::CouplingError;
use crate::queries::SoftQueries;
use crate::report::CouplingStats;
use crate::settings::CouplingSettings;

/// Everything of a coupled scene in one value. Fields are public: insert rigid bodies into
/// `physics`, spawn soft bodies into `soft`, then call [`CoupledWorld::step`].
///
/// ```
/// use tetpbd_rapier::CoupledWorld;
/// let mut scene = CoupledWorld::new(Default::default(), Default::default())?;
/// let stats = scene.step()?;
/// assert_eq!(stats.contacts, 0);
/// # Ok::<(), tetpbd_rapier::CouplingError>(())
/// ```
pub struct CoupledWorld {
    /// The rapier scene (its `integration_parameters.dt` is the frame time).
    pub physics: PhysicsWorld,
    /// The soft bodies.
    pub soft: World,
    /// The coupling.
    pub coupling: Coupling,
    /// Scene queries against the soft bodies ([`CoupledWorld::queries`]).
    queries: SoftQueries,
}

impl CoupledWorld {
    /// An empty scene with rapier's defaults (gravity −9.81 m/s² along y, dt = 1/60 s).
    pub fn new(solver: SolverSettings, settings: CouplingSettings) -> Result<Self, CouplingError> {
        Ok(CoupledWorld {
            physics: PhysicsWorld::new(),
            soft: World::new(),
            coupling: Coupling::new(solver, settings)?,
            queries: SoftQueries::new(),
        })
    }

    /// Scene queries against the soft bodies, refreshed from their current state (after
    /// the last step and whatever was written since; bodies without a `SoftCollider` use
    /// [`CouplingSettings::default_collider`]), and rapier's query pipeline over the
    /// colliders (rapier's default `QueryFilter`; `with_filter` changes it): everything
    /// [`SoftQueries::cast_ray_scene`] needs. The refresh costs O(particles + tetrahedra)
    /// per body that moved since the last call, nothing for bodies at rest.
    ///
    /// ```
    /// use rapier3d::prelude::{ColliderBuilder, Ray, RigidBodyBuilder, Vector};
    /// use tetpbd::{generators, SoftBodyBuilder};
    /// use tetpbd_rapier::{CoupledWorld, SceneRayHit, SoftQueryFilter};
    ///
    /// let mut scene = CoupledWorld::new(Default::default(), Default::default())?;
    /// scene.physics.insert(RigidBodyBuilder::fixed(), ColliderBuilder::cuboid(2.0, 0.1, 2.0));
    /// let mesh = generators::box_grid(nalgebra::Vector3::repeat(0.2), [2, 2, 2], generators::CellSplit::Six)?;
    /// let cube = SoftBodyBuilder::new(mesh).translation(nalgebra::Vector3::new(0.0, 0.3, 0.0))
    ///     .build()?.spawn(&mut scene.soft);
    /// scene.step()?;
    /// let (soft, rigid) = scene.queries();
    /// let ray = Ray::new(Vector::new(0.0, 2.0, 0.0), Vector::new(0.0, -1.0, 0.0));
    /// let hit = soft.cast_ray_scene(&rigid, &ray, f32::MAX, true, SoftQueryFilter::new())?;
    /// assert!(matches!(hit, Some(SceneRayHit::Soft(h)) if h.entity == cube));
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn queries(&mut self) -> (&SoftQueries, QueryPipeline<'_>) {
        let default = self.coupling.settings().default_collider;
        self.queries.set_default_collider(default);
        self.queries.update(&self.soft);
        (&self.queries, self.physics.query_pipeline())
    }

    /// Advances everything by one frame ([`Coupling::step`]).
    pub fn step(&mut self) -> Result<CouplingStats, CouplingError> {
        self.step_with(&mut ())
    }

    /// Advances everything by one frame with another hook in the substeps
    /// ([`Coupling::step_with`]).
    pub fn step_with(
        &mut self,
        extra: &mut dyn SubstepHook,
    ) -> Result<CouplingStats, CouplingError> {
        let ctx = RapierContext::from_physics_world(&mut self.physics);
        self.coupling.step_with(&mut self.soft, ctx, extra)
    }
}
