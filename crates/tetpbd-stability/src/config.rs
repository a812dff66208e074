//! The configurations every case runs under: a constraint set and a compliance level.

use tetpbd::SoftBodyBuilder;

/// Which constraint families a body gets.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ConstraintSet {
    /// Edge distance + signed volume.
    EdgesVolume,
    /// The four vertex–face constraints per tetrahedron alone.
    VertexFace,
    /// Vertex–face + edge distance.
    VertexFaceEdges,
}

/// A constraint set with either hard (α = 0) or soft compliance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Config {
    /// The families.
    pub set: ConstraintSet,
    /// `false`: α = 0 (the seed's hard PBD constraints); `true`: the soft compliances below.
    pub soft: bool,
}

impl Config {
    /// Soft edge and vertex–face compliance, m/N (stiffness 10⁶ N/m per constraint).
    pub const SOFT_LENGTH: f32 = 1e-6;
    /// Soft volume compliance, m⁵/N (α = V/K: K ≈ 7 MPa for the 1 m, 3³-cell cube's tetrahedra).
    pub const SOFT_VOLUME: f32 = 1e-9;

    /// The six configurations of the matrix.
    pub fn all() -> Vec<Config> {
        let mut v = Vec::new();
        for set in [
            ConstraintSet::EdgesVolume,
            ConstraintSet::VertexFace,
            ConstraintSet::VertexFaceEdges,
        ] {
            for soft in [false, true] {
                v.push(Config { set, soft });
            }
        }
        v
    }

    /// A short column label.
    pub fn label(&self) -> String {
        let set = match self.set {
            ConstraintSet::EdgesVolume => "edges+volume",
            ConstraintSet::VertexFace => "vertex-face",
            ConstraintSet::VertexFaceEdges => "vertex-face+edges",
        };
        format!("{set}, {}", if self.soft { "soft" } else { "α=0" })
    }

    /// Adds this configuration's families to a builder; `scale` multiplies the compliances
    /// (a case's "stiffest finite compliance" passes a tiny value with `soft`).
    pub fn apply(&self, b: SoftBodyBuilder, scale: f32) -> SoftBodyBuilder {
        let (l, v) = if self.soft {
            (Self::SOFT_LENGTH * scale, Self::SOFT_VOLUME * scale)
        } else {
            (0.0, 0.0)
        };
        match self.set {
            ConstraintSet::EdgesVolume => b.edges(l).volume(v),
            ConstraintSet::VertexFace => b.vertex_face(l),
            ConstraintSet::VertexFaceEdges => b.vertex_face(l).edges(l),
        }
    }
}
