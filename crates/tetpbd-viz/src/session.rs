//! [`Viz`]: the frame outputs of one run, fed one frame at a time.

use crate::error::VizError;
use crate::export::FrameExport;
use crate::options::VizOptions;
use crate::png_out::{strip, write_png};
use crate::render::{RenderSettings, View};
use crate::snapshot::{SceneView, Snapshot};

/// Most frames of an animated PNG; longer runs keep every k-th frame.
const MAX_ANIMATION_FRAMES: usize = 100;
/// Frame time the animation assumes, s.
const FRAME_TIME: f32 = 1.0 / 60.0;

/// The outputs [`VizOptions`] asked for, written as frames arrive ([`Viz::frame`]) and at the
/// end ([`Viz::finish`]). With no output asked for, both do nothing.
///
/// In an example, with the options flattened into its command line (see [`VizOptions`]):
///
/// ```no_run
/// use clap::Parser;
///
/// /// Steps a scene.
/// #[derive(Parser)]
/// struct Cli {
///     #[command(flatten)]
///     viz: tetpbd_viz::VizOptions,
/// }
///
/// # fn main() -> Result<(), Box<dyn std::error::Error>> {
/// # let mut world = tetpbd::hecs::World::new();
/// let cli = Cli::parse(); // `--help`, or a bad option, prints and exits
/// let mut viz = tetpbd_viz::Viz::from_options(cli.viz)?;
/// for _ in 0..120 {
///     // … step the scene …
///     viz.frame(&world)?;
/// }
/// viz.finish()?;
/// # Ok(()) }
/// ```
#[derive(Debug)]
pub struct Viz {
    options: VizOptions,
    settings: RenderSettings,
    export: Option<FrameExport>,
    snapshots: Vec<Snapshot>,
}

impl Viz {
    /// The outputs of `options`, pictures drawn with the default [`RenderSettings`]; creates
    /// the export folder.
    pub fn from_options(options: VizOptions) -> Result<Viz, VizError> {
        Viz::new(options, RenderSettings::default())
    }

    /// The outputs of `options`, pictures drawn with `settings`; creates the export folder.
    pub fn new(options: VizOptions, settings: RenderSettings) -> Result<Viz, VizError> {
        let export = options.export.as_ref().map(FrameExport::new).transpose()?;
        Ok(Viz {
            options,
            settings,
            export,
            snapshots: Vec::new(),
        })
    }

    /// Whether any output is on.
    pub fn is_active(&self) -> bool {
        self.export.is_some() || self.options.renders()
    }

    /// Records the scene's current state as the next frame.
    pub fn frame(&mut self, scene: &dyn SceneView) -> Result<(), VizError> {
        if !self.is_active() {
            return Ok(());
        }
        let snapshot = Snapshot::capture(scene);
        if let Some(export) = &mut self.export {
            export.write(scene, &snapshot)?;
        }
        if self.options.renders() {
            self.snapshots.push(snapshot);
        }
        Ok(())
    }

    /// Writes the pictures (one camera fitted to all recorded frames) and prints one line per
    /// output written.
    pub fn finish(self) -> Result<(), VizError> {
        if let Some(export) = &self.export {
            println!(
                "exported {} frames (OBJ, VTU) to {}",
                export.frames(),
                export.dir().display()
            );
        }
        if self.snapshots.is_empty() {
            return Ok(());
        }
        let all: Vec<&Snapshot> = self.snapshots.iter().collect();
        let view = View::fit(&all, &self.settings);
        let n = self.snapshots.len();
        if let Some(dir) = &self.options.render {
            for (k, s) in self.snapshots.iter().enumerate() {
                let path = dir.join(format!("frame_{k:04}.png"));
                write_png(&path, &[view.render(s, &self.settings)?], 0)?;
            }
            println!("rendered {n} frames to {}", dir.display());
        }
        if let Some(path) = &self.options.strip {
            let m = self.options.strip_frames.min(n);
            let frames = (0..m)
                .map(|k| {
                    let i = if m > 1 { k * (n - 1) / (m - 1) } else { n - 1 };
                    view.render(&self.snapshots[i], &self.settings)
                })
                .collect::<Result<Vec<_>, _>>()?;
            write_png(path, &[strip(&frames, [255, 255, 255])?], 0)?;
            println!("wrote a strip of {m} of {n} frames to {}", path.display());
        }
        if let Some(path) = &self.options.animate {
            let stride = n.div_ceil(MAX_ANIMATION_FRAMES);
            let frames = self
                .snapshots
                .iter()
                .step_by(stride)
                .map(|s| view.render(s, &self.settings))
                .collect::<Result<Vec<_>, _>>()?;
            let delay_ms = (stride as f32 * FRAME_TIME * 1000.0).round() as u16;
            write_png(path, &frames, delay_ms)?;
            println!(
                "wrote an animation of {} frames to {}",
                frames.len(),
                path.display()
            );
        }
        Ok(())
    }
}
