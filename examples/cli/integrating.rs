//! The command line of the `integrating` example.

use clap::Parser;
use tetpbd_viz::VizOptions;

/// An existing rapier game loop gaining soft bodies: rapier's own `PhysicsPipeline` and sets,
/// a fixed physics step with an accumulator, render interpolation of the soft surface,
/// picking by ray cast and a grab that drags the jelly, contact reports and per-frame
/// statistics (the walk-through is `docs/guide/integrating.md`).
///
/// Headless: the "mouse" is scripted (it presses on the jelly at a third of the run, drags
/// it up and sideways, and lets go at two thirds). Prints one line per rendered frame.
#[derive(Debug, Parser)]
#[command(name = "integrating")]
pub struct Cli {
    /// Rendered frames to run.
    #[arg(long, default_value_t = 240, allow_negative_numbers = true)]
    pub frames: usize,
    /// Display rate, Hz: the accumulator gains 1/render-hz s per rendered frame.
    #[arg(long, default_value_t = 144.0)]
    pub render_hz: f32,
    /// Physics rate, Hz (rapier's `dt` is its inverse; the soft bodies step with it).
    #[arg(long, default_value_t = 60.0)]
    pub physics_hz: f32,
    /// Soft-body substeps per physics step.
    #[arg(long, default_value_t = 10)]
    pub substeps: u32,
    /// Largest number of physics steps per rendered frame (a slow frame drops time beyond it
    /// rather than spiralling).
    #[arg(long, default_value_t = 4)]
    pub max_steps_per_frame: u32,
    #[command(flatten)]
    pub viz: VizOptions,
}
