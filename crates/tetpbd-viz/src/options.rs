//! [`VizOptions`]: which frame outputs a run writes, as command-line options (a
//! [`clap::Args`] group) or environment variables.

use std::path::PathBuf;

/// Frames in a strip unless `--strip-frames` says otherwise.
const DEFAULT_STRIP_FRAMES: usize = 4;

/// Which outputs a run writes; all off by default.
///
/// | option | environment variable | output |
/// |---|---|---|
/// | `--export DIR` | `TETPBD_EXPORT=DIR` | every frame as OBJ (soft surfaces, colliders) and VTU (tetrahedra) ([`crate::FrameExport`]) |
/// | `--render DIR` | `TETPBD_RENDER=DIR` | every frame as `DIR/frame_0000.png` |
/// | `--strip FILE` | `TETPBD_STRIP=FILE` | a few frames side by side in one PNG |
/// | `--strip-frames N` | | frames in the strip (default 4, first and last included) |
/// | `--animate FILE` | `TETPBD_ANIMATE=FILE` | an animated PNG of up to 100 frames |
///
/// An option wins over its environment variable; an empty path (option or variable) is an
/// error. A program flattens the group into its own [`clap`] parser, so that `--help` lists
/// these options beside the program's own:
///
/// ```
/// use clap::Parser;
/// use tetpbd_viz::VizOptions;
///
/// /// Drops a cube.
/// #[derive(Debug, Parser)]
/// struct Cli {
///     /// Frames to simulate (1/60 s each).
///     #[arg(default_value_t = 120)]
///     frames: usize,
///     #[command(flatten)]
///     viz: VizOptions,
/// }
///
/// let cli = Cli::try_parse_from(["drop", "60", "--strip", "drop.png"])?;
/// assert_eq!(cli.frames, 60);
/// assert_eq!(cli.viz.strip.as_deref(), Some("drop.png".as_ref()));
/// let error = Cli::try_parse_from(["drop", "--strip-frames", "0"]).unwrap_err();
/// assert!(error.to_string().contains("--strip-frames"), "{error}");
/// # Ok::<(), clap::Error>(())
/// ```
#[derive(Clone, Debug, PartialEq, Eq, clap::Args)]
#[command(next_help_heading = "Frame output (all off by default)")]
pub struct VizOptions {
    /// Write every frame to DIR: soft surfaces and rigid colliders as OBJ, tetrahedra as VTU
    /// with per-tetrahedron volume ratio and inverted flag.
    #[arg(long, value_name = "DIR", env = "TETPBD_EXPORT")]
    pub export: Option<PathBuf>,
    /// Render every frame to DIR/frame_0000.png, DIR/frame_0001.png, …
    #[arg(long, value_name = "DIR", env = "TETPBD_RENDER")]
    pub render: Option<PathBuf>,
    /// Render a few frames side by side into one PNG file.
    #[arg(long, value_name = "FILE", env = "TETPBD_STRIP")]
    pub strip: Option<PathBuf>,
    /// Frames in the strip, first and last included (at least 1).
    #[arg(
        long,
        value_name = "N",
        default_value_t = DEFAULT_STRIP_FRAMES,
        value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(1..),
        allow_negative_numbers = true,
    )]
    pub strip_frames: usize,
    /// Render an animated PNG file of up to 100 frames.
    #[arg(long, value_name = "FILE", env = "TETPBD_ANIMATE")]
    pub animate: Option<PathBuf>,
}

impl Default for VizOptions {
    /// No output; a strip, once asked for, of 4 frames.
    fn default() -> VizOptions {
        VizOptions {
            export: None,
            render: None,
            strip: None,
            strip_frames: DEFAULT_STRIP_FRAMES,
            animate: None,
        }
    }
}

impl VizOptions {
    /// Whether any output needs pictures.
    pub fn renders(&self) -> bool {
        self.render.is_some() || self.strip.is_some() || self.animate.is_some()
    }
}
