//! The command line of the `kinematic_platform` example.

use clap::Parser;
use tetpbd_viz::VizOptions;

/// A soft body riding a kinematic platform that moves back and forth (0.4 m amplitude),
/// stepped through the integrator's own rapier state (`RapierContext`) rather than the
/// convenience world.
///
/// Headless: prints one line of statistics per frame (contacts, deepest penetration, largest
/// edge error, platform and soft body positions, wall time per frame).
#[derive(Debug, Parser)]
#[command(name = "kinematic_platform")]
pub struct Cli {
    /// Frames to simulate, 1/60 s each.
    #[arg(
        value_name = "FRAMES",
        default_value_t = 240,
        allow_negative_numbers = true
    )]
    pub frames: usize,
    #[command(flatten)]
    pub viz: VizOptions,
}
