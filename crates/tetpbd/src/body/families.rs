//! The three constraint families, each an optional hecs component with its own compliance.
//!
//! A body without a family's component pays nothing for it: the family's system queries
//! for the component and never sees the body. Multipliers (`λ`) live next to the data they
//! belong to and are reset by the solver at the start of every substep.

#[cfg(feature = "serde")]
use serde::{Deserialize, Serialize};

/// Edge distance constraints `C = |p0 − p1| − d`, one per unique edge of the tetrahedra.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct EdgeConstraints {
    pub(crate) edges: Vec<[u32; 2]>,
    pub(crate) rest_lengths: Vec<f32>,
    pub(crate) lambdas: Vec<f32>,
    /// Compliance α, m/N (inverse stiffness; 0 = rigid). Must be finite and ≥ 0.
    pub(crate) compliance: f32,
    /// Colour classes of `edges` (edges of one class share no particle).
    pub(crate) classes: crate::ordering::colouring::ColourClasses,
}

/// Vertex–face constraints: four per tetrahedron, each vertex held at its signed rest height
/// above the plane of the other three (see [`crate::constraints::vertex_face`]). Uses the
/// body's [`crate::Tetrahedra`].
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct VertexFaceConstraints {
    pub(crate) rest_heights: Vec<[f32; 4]>,
    pub(crate) lambdas: Vec<[f32; 4]>,
    /// Compliance α, m/N.
    pub(crate) compliance: f32,
}

/// Signed volume constraints, one per tetrahedron (rest volumes in the body's
/// [`crate::Tetrahedra`]). Combine with [`EdgeConstraints`]: volume alone does not keep shape.
#[derive(Clone, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(Serialize, Deserialize))]
pub struct VolumeConstraints {
    pub(crate) lambdas: Vec<f32>,
    /// Compliance α, m⁵/N.
    pub(crate) compliance: f32,
}

macro_rules! compliance_accessors {
    ($t:ty, $unit:literal) => {
        impl $t {
            #[doc = concat!("Compliance α, ", $unit, ".")]
            pub fn compliance(&self) -> f32 {
                self.compliance
            }

            #[doc = concat!("Sets the compliance α (", $unit, "); rejects negative or non-finite values.")]
            pub fn set_compliance(&mut self, alpha: f32) -> Result<(), crate::StateError> {
                if alpha.is_finite() && alpha >= 0.0 {
                    self.compliance = alpha;
                    Ok(())
                } else {
                    Err(crate::StateError::BadCompliance { value: alpha })
                }
            }
        }
    };
}

compliance_accessors!(EdgeConstraints, "m/N");
compliance_accessors!(VertexFaceConstraints, "m/N");
compliance_accessors!(VolumeConstraints, "m⁵/N");

impl EdgeConstraints {
    /// Number of edge constraints.
    pub fn len(&self) -> usize {
        self.edges.len()
    }

    /// `true` when there is no edge.
    pub fn is_empty(&self) -> bool {
        self.edges.is_empty()
    }

    /// The sweep order of the edges: colour classes, tasks and phases (see
    /// [`crate::ordering::colouring::ColourClasses`]).
    pub fn classes(&self) -> &crate::ordering::colouring::ColourClasses {
        &self.classes
    }

    /// The edges as particle index pairs.
    pub fn edges(&self) -> &[[u32; 2]] {
        &self.edges
    }

    /// Rest length of each edge, m.
    pub fn rest_lengths(&self) -> &[f32] {
        &self.rest_lengths
    }
}

impl VertexFaceConstraints {
    /// Number of scalar constraints (four per tetrahedron).
    pub fn len(&self) -> usize {
        4 * self.rest_heights.len()
    }

    /// `true` when there is no constraint.
    pub fn is_empty(&self) -> bool {
        self.rest_heights.is_empty()
    }

    /// Signed rest heights, per tetrahedron, of corners 0..4 above their opposite faces, m.
    pub fn rest_heights(&self) -> &[[f32; 4]] {
        &self.rest_heights
    }
}

impl VolumeConstraints {
    /// Number of volume constraints (one per tetrahedron).
    pub fn len(&self) -> usize {
        self.lambdas.len()
    }

    /// `true` when there is no constraint.
    pub fn is_empty(&self) -> bool {
        self.lambdas.is_empty()
    }
}

/// The constraint families of the core crate.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Family {
    /// [`crate::EdgeConstraints`].
    Edge,
    /// [`crate::VertexFaceConstraints`].
    VertexFace,
    /// [`crate::VolumeConstraints`].
    Volume,
}

impl Family {
    /// All families, in the solver's default order.
    pub const ALL: [Family; 3] = [Family::Volume, Family::VertexFace, Family::Edge];

    /// A short lowercase name ("edge", "vertex-face", "volume").
    pub fn name(self) -> &'static str {
        match self {
            Family::Edge => "edge",
            Family::VertexFace => "vertex-face",
            Family::Volume => "volume",
        }
    }
}
