//! The command line of the `asset_drop` example.

use std::path::PathBuf;

use clap::Parser;
use tetpbd_viz::VizOptions;

/// A surface asset (OBJ) is filled with tetrahedra, dropped on fixed ground, and its fine
/// surface mesh is driven by the coarse simulation through barycentric skinning.
///
/// Headless: prints the meshing figures, then one line of statistics per frame (contacts,
/// deepest penetration, largest speed, volume ratio, inverted tetrahedra, lowest simulated and
/// skinned points, wall time per frame).
#[derive(Debug, Parser)]
#[command(name = "asset_drop")]
pub struct Cli {
    /// Closed triangle surface to tetrahedralize, OBJ.
    #[arg(
        value_name = "OBJ",
        default_value = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/assets/bunny_blob.obj")
    )]
    pub obj: PathBuf,
    /// Frames to simulate, 1/60 s each.
    #[arg(
        value_name = "FRAMES",
        default_value_t = 180,
        allow_negative_numbers = true
    )]
    pub frames: usize,
    /// Edge of the tetrahedralization's background grid cells, m (finite, > 0).
    #[arg(
        value_name = "CELL_M",
        default_value_t = 0.07,
        value_parser = positive,
        allow_negative_numbers = true
    )]
    pub cell: f32,
    #[command(flatten)]
    pub viz: VizOptions,
}

/// A finite number above zero.
fn positive(text: &str) -> Result<f32, String> {
    match text.parse::<f32>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        Ok(_) => Err("must be a finite number above 0".into()),
        Err(e) => Err(e.to_string()),
    }
}
