//! The command line of the `soft_pile` example.

use clap::{Parser, ValueEnum};
use tetpbd_viz::VizOptions;

/// Nine soft cubes (4×4×4 cells, 1 m, 1000 kg/m³) dropped in the layout of rapier's
/// `fem_bench` "jelly pile", with soft–soft contacts between them.
///
/// Prints, per second of simulated time, the largest particle speed and the largest
/// penetrations of that second. Progress goes to standard error (a bar on a terminal, a line
/// per 10 % otherwise).
#[derive(Debug, Parser)]
#[command(name = "soft_pile")]
pub struct Cli {
    /// What the cubes land on.
    #[arg(value_name = "GROUND", value_enum, default_value_t = Ground::Rigid)]
    pub ground: Ground,
    /// Simulated time, s (60 frames a second).
    #[arg(
        value_name = "SECONDS",
        default_value_t = 5,
        value_parser = clap::value_parser!(u32).range(1..),
        allow_negative_numbers = true
    )]
    pub seconds: u32,
    #[command(flatten)]
    pub viz: VizOptions,
}

/// The ground under the pile.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Ground {
    /// A fixed rapier box, stepped through the coupling with the soft contacts as its extra
    /// hook.
    Rigid,
    /// A pinned 8 m × 0.2 m × 8 m soft slab, stepped by the core solver with the soft contacts
    /// as its hook.
    Soft,
}
