//! The command line of the `rigid_ball_on_soft` example.

use clap::Parser;
use tetpbd_viz::VizOptions;

/// A rigid ball dropped onto a row of three soft cubes lying on fixed ground.
///
/// Headless: prints one line of statistics per frame (contacts, deepest penetration, largest
/// edge error, the ball's height and vertical speed, wall time per frame).
#[derive(Debug, Parser)]
#[command(name = "rigid_ball_on_soft")]
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
