//! The command line of the `recover` example.

use clap::{Parser, ValueEnum};
use tetpbd_viz::VizOptions;

/// A soft cube (1 m, 1000 kg/m³, no gravity) is mirrored, flattened, squashed or scrambled,
/// then released; prints its recovery frame by frame with the solver's step statistics.
///
/// Each frame is 1/60 s of `SUBSTEPS` substeps × 1 iteration. The run reports the first frame
/// with no inverted tetrahedron and the volume within 1 % of its rest value.
#[derive(Debug, Parser)]
#[command(name = "recover")]
pub struct Cli {
    /// How the cube starts.
    #[arg(value_name = "MODE", value_enum, default_value_t = Mode::Mirror)]
    pub mode: Mode,
    /// Which constraint families hold the cube together.
    #[arg(value_name = "FAMILIES", value_enum, default_value_t = Families::VertexFaceEdges)]
    pub families: Families,
    /// Frames to simulate, 1/60 s each.
    #[arg(
        value_name = "FRAMES",
        default_value_t = 120,
        allow_negative_numbers = true
    )]
    pub frames: usize,
    /// Substeps per frame (at least 1).
    #[arg(
        value_name = "SUBSTEPS",
        default_value_t = 10,
        value_parser = clap::value_parser!(u32).range(1..),
        allow_negative_numbers = true
    )]
    pub substeps: u32,
    /// Cells along each side of the cube (at least 1; the cube has CELLS³ cells of five
    /// tetrahedra).
    #[arg(
        value_name = "CELLS",
        default_value_t = 4,
        value_parser = clap::value_parser!(u32).range(1..),
        allow_negative_numbers = true
    )]
    pub cells: u32,
    /// Compliance of every constraint family: m/N for edges and vertex–face, m⁵/N for volume
    /// (finite, ≥ 0; 0 is rigid).
    #[arg(
        long,
        value_name = "ALPHA",
        default_value_t = 0.0,
        value_parser = non_negative,
        allow_negative_numbers = true
    )]
    pub alpha: f32,
    /// Turns on the solver's safety net: the largest speed a correction may add, m/s (finite,
    /// > 0) [default: off].
    #[arg(
        long,
        value_name = "M_PER_S",
        value_parser = positive,
        allow_negative_numbers = true
    )]
    pub max_correction_speed: Option<f32>,
    #[command(flatten)]
    pub viz: VizOptions,
}

/// How the cube is deformed before it is released.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Mode {
    /// Mirrored through x = 0: every tetrahedron inverted.
    Mirror,
    /// Flattened onto y = 0: every tetrahedron degenerate.
    Flatten,
    /// Every particle at a random point of the unit cube (seeded).
    Scramble,
    /// Squashed to half its height.
    Squash,
    /// Squashed to 95 % of its height.
    Nudge,
}

/// The constraint families of the cube.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Families {
    /// Vertex–face constraints alone.
    #[value(name = "vf")]
    VertexFace,
    /// Edges and volume.
    #[value(name = "ev")]
    EdgesVolume,
    /// Vertex–face constraints and edges.
    #[value(name = "vfe")]
    VertexFaceEdges,
    /// Edges alone (they cannot un-invert a mirrored body).
    #[value(name = "e")]
    Edges,
}

/// A finite number of at least zero.
fn non_negative(text: &str) -> Result<f32, String> {
    match text.parse::<f32>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        Ok(_) => Err("must be a finite number of at least 0".into()),
        Err(e) => Err(e.to_string()),
    }
}

/// A finite number above zero.
fn positive(text: &str) -> Result<f32, String> {
    match text.parse::<f32>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        Ok(_) => Err("must be a finite number above 0".into()),
        Err(e) => Err(e.to_string()),
    }
}
