//! [`VizOptions`]: which frame outputs a run writes, from command-line flags or environment
//! variables.

use std::path::PathBuf;

use crate::error::VizError;

/// Frames in a strip unless `--strip-frames` says otherwise.
const DEFAULT_STRIP_FRAMES: usize = 4;

/// Which outputs a run writes; all off by default.
///
/// | flag | environment variable | output |
/// |---|---|---|
/// | `--export DIR` | `TETPBD_EXPORT=DIR` | every frame as OBJ (soft surfaces, colliders) and VTU (tetrahedra) ([`crate::FrameExport`]) |
/// | `--render DIR` | `TETPBD_RENDER=DIR` | every frame as `DIR/frame_0000.png` |
/// | `--strip FILE` | `TETPBD_STRIP=FILE` | a few frames side by side in one PNG |
/// | `--strip-frames N` | | frames in the strip (default 4, first and last included) |
/// | `--animate FILE` | `TETPBD_ANIMATE=FILE` | an animated PNG of up to 100 frames |
///
/// A flag wins over its environment variable.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct VizOptions {
    /// Folder of per-frame OBJ and VTU files.
    pub export: Option<PathBuf>,
    /// Folder of per-frame PNG pictures.
    pub render: Option<PathBuf>,
    /// File of the frame strip.
    pub strip: Option<PathBuf>,
    /// Frames in the strip (at least 1).
    pub strip_frames: usize,
    /// File of the animated PNG.
    pub animate: Option<PathBuf>,
}

impl VizOptions {
    /// Takes the options' flags (and their values) out of `args`, returning the options and
    /// the other arguments in their order; unset flags fall back on the environment
    /// variables read by `env`.
    pub fn parse(
        args: impl IntoIterator<Item = String>,
        env: impl Fn(&str) -> Option<String>,
    ) -> Result<(VizOptions, Vec<String>), VizError> {
        let mut options = VizOptions {
            strip_frames: DEFAULT_STRIP_FRAMES,
            ..VizOptions::default()
        };
        let mut rest = Vec::new();
        let mut args = args.into_iter();
        while let Some(arg) = args.next() {
            let slot =
                match arg.as_str() {
                    "--export" => &mut options.export,
                    "--render" => &mut options.render,
                    "--strip" => &mut options.strip,
                    "--animate" => &mut options.animate,
                    "--strip-frames" => {
                        let value = args.next().unwrap_or_default();
                        options.strip_frames =
                            value.parse().ok().filter(|&n| n >= 1).ok_or_else(|| {
                                VizError::Option {
                                    name: arg.clone(),
                                    problem: format!("`{value}` is not a whole number ≥ 1"),
                                }
                            })?;
                        continue;
                    }
                    _ => {
                        rest.push(arg);
                        continue;
                    }
                };
            match args
                .next()
                .filter(|v| !v.is_empty() && !v.starts_with("--"))
            {
                Some(value) => *slot = Some(PathBuf::from(value)),
                None => {
                    return Err(VizError::Option {
                        name: arg,
                        problem: "needs a path".into(),
                    })
                }
            }
        }
        for (slot, var) in [
            (&mut options.export, "TETPBD_EXPORT"),
            (&mut options.render, "TETPBD_RENDER"),
            (&mut options.strip, "TETPBD_STRIP"),
            (&mut options.animate, "TETPBD_ANIMATE"),
        ] {
            if slot.is_none() {
                *slot = env(var).filter(|v| !v.is_empty()).map(PathBuf::from);
            }
        }
        Ok((options, rest))
    }

    /// Whether any output needs pictures.
    pub fn renders(&self) -> bool {
        self.render.is_some() || self.strip.is_some() || self.animate.is_some()
    }
}
