//! Typed errors of the coupling crate.

use std::fmt;

use rapier3d::dynamics::RigidBodyHandle;

/// Why a coupling call was rejected. Every variant names what is wrong.
#[derive(Clone, Debug, PartialEq)]
pub enum CouplingError {
    /// A soft-body solver setting is invalid.
    Solver(tetpbd::SettingsError),
    /// A soft body's state was not finite at the start of a substep; the solver restored it
    /// and finished the step ([`tetpbd::StepError::NonFiniteState`] names the body, particle
    /// and value).
    NonFiniteState(tetpbd::StepError),
    /// A coupling setting is out of range.
    BadSetting {
        /// The field's name.
        name: &'static str,
        /// The value given.
        value: f32,
    },
    /// rapier's integration time step must be finite and > 0, s.
    BadRapierDt {
        /// The value given.
        value: f32,
    },
    /// rapier's gravity is not finite.
    NonFiniteGravity,
    /// A rigid body handle does not name a body of the set (e.g. it was removed).
    BodyNotFound {
        /// The handle.
        handle: RigidBodyHandle,
    },
    /// The hecs entity does not exist or is not a soft body (has no `Particles`).
    NotASoftBody {
        /// The entity.
        entity: hecs::Entity,
    },
    /// A particle index is out of range for its soft body.
    ParticleOutOfRange {
        /// The index.
        index: u32,
        /// Number of particles of the body.
        len: usize,
    },
    /// A soft body's `Surface` names a particle its `Particles` do not hold.
    SurfaceOutOfRange {
        /// The soft body.
        entity: hecs::Entity,
        /// The largest particle index of the surface.
        index: u32,
        /// Number of particles of the body.
        len: usize,
    },
    /// An attachment index is out of range.
    AttachmentOutOfRange {
        /// The index.
        index: usize,
        /// Number of attachments.
        len: usize,
    },
    /// The attachment is fixed to a rigid body and has no kinematic target to move.
    NotAPointTarget {
        /// The attachment's index.
        index: usize,
    },
    /// A position, point or velocity given is NaN or infinite.
    NonFinite {
        /// What was given.
        what: &'static str,
    },
    /// A material coefficient (friction, restitution, thickness, compliance) is negative or
    /// not finite.
    BadCoefficient {
        /// The coefficient's name.
        name: &'static str,
        /// The value given.
        value: f32,
    },
}

impl fmt::Display for CouplingError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CouplingError::Solver(e) => write!(f, "soft-body solver settings: {e}"),
            CouplingError::NonFiniteState(e) => write!(f, "soft-body state: {e}"),
            CouplingError::BadSetting { name, value } => {
                write!(f, "coupling setting `{name}` is out of range: {value}")
            }
            CouplingError::BadRapierDt { value } => {
                write!(f, "rapier dt must be finite and > 0 s, got {value}")
            }
            CouplingError::NonFiniteGravity => write!(f, "rapier gravity is not finite"),
            CouplingError::BodyNotFound { handle } => {
                write!(f, "rigid body {handle:?} is not in the rigid body set")
            }
            CouplingError::NotASoftBody { entity } => {
                write!(f, "entity {entity:?} is not a soft body")
            }
            CouplingError::ParticleOutOfRange { index, len } => {
                write!(f, "particle {index} out of range ({len} particles)")
            }
            CouplingError::SurfaceOutOfRange { entity, index, len } => write!(
                f,
                "the surface of soft body {entity:?} names particle {index}, \
                 but the body has {len} particles"
            ),
            CouplingError::AttachmentOutOfRange { index, len } => {
                write!(f, "attachment {index} out of range ({len} attachments)")
            }
            CouplingError::NotAPointTarget { index } => {
                write!(
                    f,
                    "attachment {index} is attached to a rigid body, not to a point target"
                )
            }
            CouplingError::NonFinite { what } => write!(f, "{what} is not finite"),
            CouplingError::BadCoefficient { name, value } => {
                write!(f, "{name} must be finite and >= 0, got {value}")
            }
        }
    }
}

impl std::error::Error for CouplingError {}

impl From<tetpbd::StepError> for CouplingError {
    fn from(e: tetpbd::StepError) -> Self {
        match e {
            tetpbd::StepError::Settings(e) => CouplingError::Solver(e),
            e => CouplingError::NonFiniteState(e),
        }
    }
}

impl From<tetpbd::SettingsError> for CouplingError {
    fn from(e: tetpbd::SettingsError) -> Self {
        CouplingError::Solver(e)
    }
}

/// Checks that `value` is finite and ≥ 0.
pub(crate) fn check_coefficient(name: &'static str, value: f32) -> Result<f32, CouplingError> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(CouplingError::BadCoefficient { name, value })
    }
}
