//! [`VizError`]: what can go wrong exporting or rendering frames.

use std::path::PathBuf;

/// An error of the frame exporter or the renderer.
#[derive(Debug)]
pub enum VizError {
    /// A file or folder could not be written.
    Io {
        /// The path.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// A mesh could not be written as OBJ or VTU.
    Write {
        /// The path.
        path: PathBuf,
        /// The cause.
        source: tetpbd_io::WriteError,
    },
    /// The PNG encoder failed.
    Png {
        /// The path.
        path: PathBuf,
        /// The cause.
        source: png::EncodingError,
    },
    /// An image size of zero or larger than 16384 pixels on a side.
    ImageSize {
        /// Width asked for, pixels.
        width: u32,
        /// Height asked for, pixels.
        height: u32,
    },
}

impl std::fmt::Display for VizError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            VizError::Io { path, source } => write!(f, "{}: {source}", path.display()),
            VizError::Write { path, source } => write!(f, "{}: {source}", path.display()),
            VizError::Png { path, source } => write!(f, "{}: PNG: {source}", path.display()),
            VizError::ImageSize { width, height } => write!(
                f,
                "image size {width}×{height}: each side must be 1 to 16384 pixels"
            ),
        }
    }
}

impl std::error::Error for VizError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            VizError::Io { source, .. } => Some(source),
            VizError::Write { source, .. } => Some(source),
            VizError::Png { source, .. } => Some(source),
            _ => None,
        }
    }
}
