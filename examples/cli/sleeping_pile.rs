//! The command line of the `sleeping_pile` example.

use clap::{Parser, ValueEnum};
use tetpbd_viz::VizOptions;

/// A pile of soft cubes (0.5 m, 4×4×4 cells) that falls asleep, then a thrown rigid ball
/// that wakes it; or a field of resting cubes asleep around one awake cube.
///
/// Prints per frame the awake soft bodies and the frame's cost, then the median cost of the
/// resting pile awake and asleep. Progress goes to standard error.
#[derive(Debug, Parser)]
#[command(name = "sleeping_pile")]
pub struct Cli {
    /// The scene.
    #[arg(value_name = "SCENE", value_enum, default_value_t = Scene::Pile)]
    pub scene: Scene,
    /// Soft cubes: in the pile, or resting apart in the field.
    #[arg(
        value_name = "CUBES",
        default_value_t = 20,
        value_parser = clap::value_parser!(u32).range(1..),
        allow_negative_numbers = true
    )]
    pub cubes: u32,
    /// Longest time the pile may take to fall asleep, s (60 frames a second).
    #[arg(long, value_name = "SECONDS", default_value_t = 15)]
    pub max_seconds: u32,
    /// Frames stepped after the ball is thrown (pile) or the awake cube dropped (field).
    #[arg(long, value_name = "FRAMES", default_value_t = 120)]
    pub frames_after: u32,
    /// Speed of the thrown ball, m/s.
    #[arg(long, value_name = "M_PER_S", default_value_t = 10.0)]
    pub throw_speed: f32,
    /// Print every frame (default: every frame from the throw on, every 30th before it).
    #[arg(long)]
    pub every_frame: bool,
    #[command(flatten)]
    pub viz: VizOptions,
}

/// What is built.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Scene {
    /// Cubes dropped in layers of 3 × 3 onto rigid ground; a ball thrown at them once asleep.
    Pile,
    /// Cubes resting apart on rigid ground; once asleep, one more cube dropped among them.
    Field,
}
