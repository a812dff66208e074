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
    /// The Neo-Hookean material alone ([`tetpbd::Material`]): `soft` picks
    /// [`tetpbd::Material::SOFT_TISSUE`], otherwise [`tetpbd::Material::RUBBER`] (E = 1.2 MPa,
    /// ν = 0.49: the stiffest preset, nearly incompressible). Its substeps are chosen from
    /// [`tetpbd::NeoHookeanMaterial::max_stable_substep`] ([`crate::run::substeps_for`]).
    Material,
}

/// A constraint set with either hard (α = 0) or soft compliance (for the material: rubber or
/// soft tissue).
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

    /// The eight configurations of the matrix: [`Config::families`] and the material's two.
    pub fn all() -> Vec<Config> {
        let mut v = Self::families();
        for soft in [false, true] {
            v.push(Config {
                set: ConstraintSet::Material,
                soft,
            });
        }
        v
    }

    /// The six configurations of the seed's families (the coupled cases run these).
    pub fn families() -> Vec<Config> {
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
        if self.set == ConstraintSet::Material {
            let preset = if self.soft { "soft tissue" } else { "rubber" };
            return format!("material, {preset}");
        }
        let set = match self.set {
            ConstraintSet::EdgesVolume => "edges+volume",
            ConstraintSet::VertexFace => "vertex-face",
            ConstraintSet::VertexFaceEdges => "vertex-face+edges",
            ConstraintSet::Material => "material",
        };
        format!("{set}, {}", if self.soft { "soft" } else { "α=0" })
    }

    /// Adds this configuration's families to a builder; `scale` multiplies the compliances
    /// (a case's "stiffest finite compliance" passes a tiny value with `soft`). The material
    /// has no compliance to scale: it keeps its preset's E and ν (its stiff case is rubber).
    pub fn apply(&self, b: SoftBodyBuilder, scale: f32) -> SoftBodyBuilder {
        self.apply_scaled(b, scale, scale)
    }

    /// [`Config::apply`] with the length compliances (edges, vertex–face) multiplied by
    /// `length_scale` and the volume compliance by `volume_scale`.
    pub fn apply_scaled(
        &self,
        b: SoftBodyBuilder,
        length_scale: f32,
        volume_scale: f32,
    ) -> SoftBodyBuilder {
        let (l, v) = if self.soft {
            (
                Self::SOFT_LENGTH * length_scale,
                Self::SOFT_VOLUME * volume_scale,
            )
        } else {
            (0.0, 0.0)
        };
        match self.set {
            ConstraintSet::EdgesVolume => b.edges(l).volume(v),
            ConstraintSet::VertexFace => b.vertex_face(l),
            ConstraintSet::VertexFaceEdges => b.vertex_face(l).edges(l),
            ConstraintSet::Material if self.soft => b.material(tetpbd::Material::SOFT_TISSUE),
            ConstraintSet::Material => b.material(tetpbd::Material::RUBBER),
        }
    }
}
