//! The command line of the `soft_on_rigid_stack` example.

use clap::Parser;
use tetpbd_viz::VizOptions;

/// A soft cube lands on a stack of three dynamic rigid boxes standing on fixed ground.
///
/// Headless: prints one line of statistics per frame (contacts, deepest penetration, largest
/// edge error, the top box's height, the cube's lowest point, wall time per frame).
#[derive(Debug, Parser)]
#[command(name = "soft_on_rigid_stack")]
pub struct Cli {
    /// Frames to simulate, 1/60 s each.
    #[arg(
        value_name = "FRAMES",
        default_value_t = 180,
        allow_negative_numbers = true
    )]
    pub frames: usize,
    #[command(flatten)]
    pub viz: VizOptions,
}
