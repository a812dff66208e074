//! Error types: one per kind of call, each naming what is wrong.

use std::fmt;

/// Why a soft body could not be built.
#[derive(Clone, Debug, PartialEq)]
pub enum BuildError {
    /// The mesh has no vertices.
    NoVertices,
    /// A vertex coordinate is NaN or infinite.
    NonFiniteVertex {
        /// Vertex index.
        vertex: usize,
    },
    /// A tetrahedron refers to a vertex that does not exist.
    IndexOutOfRange {
        /// Tetrahedron index.
        tet: usize,
        /// The offending vertex index.
        index: u32,
        /// Number of vertices.
        vertex_count: usize,
    },
    /// A tetrahedron uses the same vertex twice.
    RepeatedVertex {
        /// Tetrahedron index.
        tet: usize,
        /// The repeated vertex index.
        index: u32,
    },
    /// A tetrahedron's |volume| is below `epsilon · (longest edge)³`.
    DegenerateTetrahedron {
        /// Tetrahedron index.
        tet: usize,
        /// Its signed volume, m³.
        volume: f32,
        /// The threshold it fell below, m³.
        threshold: f32,
    },
    /// A vertex belongs to no tetrahedron, so it would have no mass.
    UnreferencedVertex {
        /// Vertex index.
        vertex: usize,
    },
    /// A pinned index does not exist.
    PinnedOutOfRange {
        /// The offending index.
        index: u32,
        /// Number of vertices.
        vertex_count: usize,
    },
    /// Density must be finite and > 0, kg/m³.
    BadDensity {
        /// The value given.
        value: f32,
    },
    /// A compliance must be finite and ≥ 0.
    BadCompliance {
        /// Which family ("edge", "vertex-face", "volume").
        family: &'static str,
        /// The value given.
        value: f32,
    },
    /// The volume epsilon must be finite and ≥ 0.
    BadEpsilon {
        /// The value given.
        value: f32,
    },
    /// The initial velocity is NaN or infinite.
    NonFiniteVelocity,
    /// The placement's rotation or translation has a non-finite component.
    NonFinitePose,
    /// The placement's scale is not finite and positive.
    BadScale {
        /// The value given.
        value: f32,
    },
    /// A plasticity setting is out of range.
    Plasticity(PlasticityError),
    /// A tearing setting is out of range.
    Tearing(TearingError),
    /// A generator parameter is out of range.
    BadGeneratorParameter {
        /// Parameter name.
        name: &'static str,
        /// The value given.
        value: f32,
    },
}

impl fmt::Display for BuildError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            BuildError::NoVertices => write!(f, "the mesh has no vertices"),
            BuildError::NonFiniteVertex { vertex } => {
                write!(f, "vertex {vertex} has a non-finite coordinate")
            }
            BuildError::IndexOutOfRange {
                tet,
                index,
                vertex_count,
            } => write!(
                f,
                "tetrahedron {tet} refers to vertex {index}, but there are only {vertex_count} vertices"
            ),
            BuildError::RepeatedVertex { tet, index } => {
                write!(f, "tetrahedron {tet} uses vertex {index} more than once")
            }
            BuildError::DegenerateTetrahedron {
                tet,
                volume,
                threshold,
            } => write!(
                f,
                "tetrahedron {tet} has volume {volume:e} m³, below the threshold {threshold:e} m³"
            ),
            BuildError::UnreferencedVertex { vertex } => {
                write!(f, "vertex {vertex} belongs to no tetrahedron")
            }
            BuildError::PinnedOutOfRange {
                index,
                vertex_count,
            } => write!(
                f,
                "pinned vertex {index} does not exist ({vertex_count} vertices)"
            ),
            BuildError::BadDensity { value } => {
                write!(f, "density must be finite and > 0 kg/m³, got {value}")
            }
            BuildError::BadCompliance { family, value } => write!(
                f,
                "{family} compliance must be finite and >= 0, got {value}"
            ),
            BuildError::BadEpsilon { value } => {
                write!(f, "volume epsilon must be finite and >= 0, got {value}")
            }
            BuildError::NonFiniteVelocity => {
                write!(f, "initial linear or angular velocity is not finite")
            }
            BuildError::NonFinitePose => write!(f, "placement rotation or translation is not finite"),
            BuildError::BadScale { value } => {
                write!(f, "scale must be finite and positive, got {value}")
            }
            BuildError::Plasticity(e) => write!(f, "{e}"),
            BuildError::Tearing(e) => write!(f, "{e}"),
            BuildError::BadGeneratorParameter { name, value } => {
                write!(f, "generator parameter `{name}` is out of range: {value}")
            }
        }
    }
}

impl std::error::Error for BuildError {}

/// Why solver settings were rejected.
#[derive(Clone, Debug, PartialEq)]
pub enum SettingsError {
    /// Frame time step must be finite and > 0, s.
    BadDt {
        /// The value given.
        value: f32,
    },
    /// Substeps and iterations must be ≥ 1.
    ZeroCount {
        /// Which count ("substeps" or "iterations").
        what: &'static str,
    },
    /// Gravity must be finite, m/s².
    NonFiniteGravity,
    /// Damping must be finite and ≥ 0, 1/s.
    BadDamping {
        /// The value given.
        value: f32,
    },
    /// The family order must list each family exactly once.
    BadOrder,
    /// The correction speed limit must be finite and > 0, m/s.
    BadCorrectionSpeed {
        /// The value given.
        value: f32,
    },
}

impl fmt::Display for SettingsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SettingsError::BadDt { value } => {
                write!(f, "frame dt must be finite and > 0 s, got {value}")
            }
            SettingsError::ZeroCount { what } => write!(f, "{what} must be at least 1"),
            SettingsError::NonFiniteGravity => write!(f, "gravity is not finite"),
            SettingsError::BadDamping { value } => {
                write!(f, "damping must be finite and >= 0 1/s, got {value}")
            }
            SettingsError::BadOrder => write!(f, "family order must list each family once"),
            SettingsError::BadCorrectionSpeed { value } => write!(
                f,
                "max correction speed must be finite and > 0 m/s, got {value}"
            ),
        }
    }
}

impl std::error::Error for SettingsError {}

/// Why a write to a body's state was rejected.
#[derive(Clone, Debug, PartialEq)]
pub enum StateError {
    /// Particle index out of range.
    ParticleOutOfRange {
        /// The offending index.
        index: usize,
        /// Number of particles.
        len: usize,
    },
    /// A value is NaN or infinite.
    NonFinite {
        /// What was written ("position", "velocity", "acceleration").
        what: &'static str,
        /// Particle index (0 for per-body values).
        index: usize,
    },
    /// Compliance must be finite and ≥ 0.
    BadCompliance {
        /// The value given.
        value: f32,
    },
    /// Every particle that would take an impulse is pinned.
    AllPinned,
    /// The body has no tetrahedron to take an impulse at a point.
    NoTetrahedra,
    /// A parameter is out of range (a radius ≤ 0, a non-finite speed).
    BadParameter {
        /// Which parameter.
        what: &'static str,
        /// The value given.
        value: f32,
    },
    /// Tetrahedron index out of range.
    TetrahedronOutOfRange {
        /// The offending index.
        index: usize,
        /// Number of tetrahedra.
        len: usize,
    },
    /// Barycentric coordinates that are not finite, clearly negative, or do not sum to 1.
    BadBarycentric {
        /// The coordinates given.
        coords: [f32; 4],
    },
    /// A per-particle component was made for a body with another number of particles.
    LengthMismatch {
        /// Which component.
        what: &'static str,
        /// Its length.
        len: usize,
        /// The body's number of particles.
        particles: usize,
    },
}

impl fmt::Display for StateError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            StateError::ParticleOutOfRange { index, len } => {
                write!(f, "particle {index} out of range ({len} particles)")
            }
            StateError::NonFinite { what, index } => {
                write!(f, "{what} of particle {index} is not finite")
            }
            StateError::BadCompliance { value } => {
                write!(f, "compliance must be finite and >= 0, got {value}")
            }
            StateError::AllPinned => write!(f, "every particle that would take it is pinned"),
            StateError::NoTetrahedra => write!(f, "the body has no tetrahedron"),
            StateError::BadParameter { what, value } => {
                write!(f, "{what} is out of range: {value}")
            }
            StateError::TetrahedronOutOfRange { index, len } => {
                write!(f, "tetrahedron {index} out of range ({len} tetrahedra)")
            }
            StateError::BadBarycentric { coords } => write!(
                f,
                "barycentric coordinates {coords:?} must be finite, >= 0 and sum to 1"
            ),
            StateError::LengthMismatch {
                what,
                len,
                particles,
            } => write!(
                f,
                "{what} has {len} entries but the body has {particles} particles"
            ),
        }
    }
}

impl std::error::Error for StateError {}

/// Why a [`crate::Solver`] step failed.
#[derive(Clone, Debug, PartialEq)]
pub enum StepError {
    /// The settings are invalid; nothing was stepped.
    Settings(SettingsError),
    /// A particle's position or velocity was not finite at the start of a substep (written by
    /// the caller, e.g. through [`crate::Particles::positions_mut`], or by a hook). The step
    /// ran to its end with every such particle restored: its position put back to its last
    /// finite value (its substep start, the state one substep before it was overwritten; its
    /// rest position if that too is not finite) and a non-finite velocity set to zero. This
    /// names the first one found (lowest body, then particle index).
    NonFiniteState {
        /// The body.
        entity: hecs::Entity,
        /// Particle index within the body.
        particle: usize,
        /// `"position"` or `"velocity"`.
        what: &'static str,
        /// The value found.
        value: [f32; 3],
        /// Particles restored in the step, over all bodies (each counted once per substep in
        /// which it was found; [`crate::StepStats::non_finite_restored`] has the same count).
        restored: u64,
    },
}

impl fmt::Display for StepError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            StepError::Settings(e) => write!(f, "bad solver settings: {e}"),
            StepError::NonFiniteState {
                entity,
                particle,
                what,
                value,
                restored,
            } => write!(
                f,
                "{what} of particle {particle} of body {entity:?} is not finite ({value:?}); \
                 restored to its last finite state ({restored} particle restorations)"
            ),
        }
    }
}

impl std::error::Error for StepError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            StepError::Settings(e) => Some(e),
            StepError::NonFiniteState { .. } => None,
        }
    }
}

impl From<SettingsError> for StepError {
    fn from(e: SettingsError) -> Self {
        StepError::Settings(e)
    }
}

/// Why plasticity settings were rejected ([`crate::PlasticitySettings::validate`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PlasticityError {
    /// The yield strain must be finite and ≥ 0.
    BadYieldStrain {
        /// The value given (dimensionless).
        value: f32,
    },
    /// The flow rate must be ≥ 0 (1/s; infinity allowed).
    BadFlowRate {
        /// The value given, 1/s.
        value: f32,
    },
    /// The maximum plastic strain must be finite, ≥ 0 and < 1.
    BadMaxPlasticStrain {
        /// The value given (dimensionless).
        value: f32,
    },
}

impl fmt::Display for PlasticityError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PlasticityError::BadYieldStrain { value } => {
                write!(f, "yield strain must be finite and >= 0, got {value}")
            }
            PlasticityError::BadFlowRate { value } => {
                write!(f, "plastic flow rate must be >= 0 1/s, got {value}")
            }
            PlasticityError::BadMaxPlasticStrain { value } => write!(
                f,
                "maximum plastic strain must be finite, >= 0 and < 1, got {value}"
            ),
        }
    }
}

impl std::error::Error for PlasticityError {}

impl From<PlasticityError> for BuildError {
    fn from(e: PlasticityError) -> Self {
        BuildError::Plasticity(e)
    }
}

/// Why tearing settings were rejected ([`crate::TearingSettings::validate`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TearingError {
    /// The tearing strain must be finite and > 0.
    BadStrain {
        /// The value given (dimensionless).
        value: f32,
    },
    /// The tearing force must be finite and > 0, N.
    BadForce {
        /// The value given, N.
        value: f32,
    },
    /// The smoothing time must be finite and ≥ 0, s.
    BadSmoothingTime {
        /// The value given, s.
        value: f32,
    },
}

impl fmt::Display for TearingError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TearingError::BadStrain { value } => {
                write!(f, "tearing strain must be finite and > 0, got {value}")
            }
            TearingError::BadForce { value } => {
                write!(f, "tearing force must be finite and > 0 N, got {value}")
            }
            TearingError::BadSmoothingTime { value } => write!(
                f,
                "tearing smoothing time must be finite and >= 0 s, got {value}"
            ),
        }
    }
}

impl std::error::Error for TearingError {}

impl From<TearingError> for BuildError {
    fn from(e: TearingError) -> Self {
        BuildError::Tearing(e)
    }
}

/// Why a cut was rejected ([`crate::cut`]).
#[derive(Clone, Debug, PartialEq)]
pub enum CutError {
    /// The entity is not a soft body (no particles or tetrahedra), or is gone.
    NoSuchBody {
        /// The entity given.
        entity: hecs::Entity,
    },
    /// The blade is not finite, or degenerate (a zero normal, a flat triangle).
    BadBlade {
        /// What is wrong with it.
        what: &'static str,
    },
}

impl fmt::Display for CutError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CutError::NoSuchBody { entity } => write!(f, "{entity:?} is not a soft body"),
            CutError::BadBlade { what } => write!(f, "bad blade: {what}"),
        }
    }
}

impl std::error::Error for CutError {}
