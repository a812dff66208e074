//! [`CoupledWorld`]: a convenience that owns a rapier [`PhysicsWorld`], a hecs world of soft
//! bodies and the [`Coupling`], for quick scenes and tests.

use hecs::World;
use rapier3d::pipeline::PhysicsWorld;
use tetpbd::{SolverSettings, SubstepHook};

use crate::context::RapierContext;
use crate::coupling::Coupling;
use crate::error::CouplingError;
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
}

impl CoupledWorld {
    /// An empty scene with rapier's defaults (gravity −9.81 m/s² along y, dt = 1/60 s).
    pub fn new(solver: SolverSettings, settings: CouplingSettings) -> Result<Self, CouplingError> {
        Ok(CoupledWorld {
            physics: PhysicsWorld::new(),
            soft: World::new(),
            coupling: Coupling::new(solver, settings)?,
        })
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
