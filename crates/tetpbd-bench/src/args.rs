//! Command-line pieces shared by the benchmark binaries (each bin declares its own options
//! with clap; these are the ones several of them take).

/// The particle orders to measure (`--spatial-order`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum SpatialOrder {
    /// The builder's spatial particle order only.
    On,
    /// The mesh's own numbering only.
    Off,
    /// Both, one after the other.
    Both,
}

/// The particle orders to measure for `choice`: both, one, or (`None`) the builder's default
/// ([`tetpbd::SoftBodyBuilder::DEFAULT_SPATIAL_ORDER`]).
pub fn orders(choice: Option<SpatialOrder>) -> Vec<bool> {
    match choice {
        Some(SpatialOrder::On) => vec![true],
        Some(SpatialOrder::Off) => vec![false],
        Some(SpatialOrder::Both) => vec![false, true],
        None => vec![tetpbd::SoftBodyBuilder::DEFAULT_SPATIAL_ORDER],
    }
}

/// The family sets the solver benchmarks measure (`--set`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum FamilySet {
    /// Edges + volume.
    #[value(name = "edges+volume")]
    EdgesVolume,
    /// Vertex–face alone.
    VertexFace,
    /// The Neo-Hookean material alone (`Material::SOFT_TISSUE`; measured at the benchmark's
    /// substeps whether or not they are stable for it: a cost, not a motion).
    Material,
}

impl FamilySet {
    /// The name printed in reports (the value the command line takes).
    pub fn name(self) -> &'static str {
        match self {
            FamilySet::EdgesVolume => "edges+volume",
            FamilySet::VertexFace => "vertex-face",
            FamilySet::Material => "material",
        }
    }

    /// `b` with this set's families at the cost benchmarks' compliances: edges 1e-6 m/N +
    /// volume 1e-9 m⁵/N, vertex–face 1e-6 m/N, or the soft-tissue material.
    pub fn add_to(self, b: tetpbd::SoftBodyBuilder) -> tetpbd::SoftBodyBuilder {
        match self {
            FamilySet::EdgesVolume => b.edges(1e-6).volume(1e-9),
            FamilySet::VertexFace => b.vertex_face(1e-6),
            FamilySet::Material => b.material(tetpbd::Material::SOFT_TISSUE),
        }
    }
}
