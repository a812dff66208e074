//! The command line of the `tearing` example.

use clap::Parser;
use tetpbd_viz::VizOptions;

/// A soft slab (1 × 0.1 × 0.4 m, 10 × 1 × 4 cells, tearing past a strain of 0.3) pulled apart
/// by two kinematic boxes holding its ends, then a soft cube cut in two by a blade, then the
/// same slab with rapier 0.36's own soft body and tearing.
///
/// Prints one line per frame of the pull (wall time, pieces) and every tear as it happens
/// (body, new pieces, faces torn, particles copied), the cut's event, then both engines side
/// by side: tear events, pieces at the end, fastest fragment, median time per frame.
#[derive(Debug, Parser)]
#[command(name = "tearing")]
pub struct Cli {
    /// Speed of each box pulling the slab, m/s (each travels 0.6 m, then stops).
    #[arg(
        long,
        value_name = "M_PER_S",
        default_value_t = 3.0,
        value_parser = non_negative,
        allow_negative_numbers = true
    )]
    pub speed: f32,
    /// Frames stepped after the boxes stop, 1/60 s each.
    #[arg(
        long,
        value_name = "FRAMES",
        default_value_t = 60,
        allow_negative_numbers = true
    )]
    pub settle_frames: usize,
    /// Skip the run with rapier's own soft body.
    #[arg(long)]
    pub no_rapier: bool,
    #[command(flatten)]
    pub viz: VizOptions,
}

/// A finite number of at least zero.
fn non_negative(text: &str) -> Result<f32, String> {
    match text.parse::<f32>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        Ok(_) => Err("must be a finite number of at least 0".into()),
        Err(e) => Err(e.to_string()),
    }
}
