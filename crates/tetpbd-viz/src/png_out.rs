//! PNG output of [`Raster`]s: single pictures, frame strips and animated PNGs.

use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

use crate::error::VizError;
use crate::raster::{Raster, Rgb};

/// Width of the gap between the frames of a strip, pixels.
const STRIP_GAP: u32 = 2;

/// `frames` side by side, left to right, separated by `STRIP_GAP` pixels of `gap_color`.
/// All frames must have the height of the first; an empty list or a mismatch is an
/// [`VizError::ImageSize`].
pub fn strip(frames: &[Raster], gap_color: Rgb) -> Result<Raster, VizError> {
    let Some(first) = frames.first() else {
        return Err(VizError::ImageSize {
            width: 0,
            height: 0,
        });
    };
    let height = first.height();
    if let Some(bad) = frames.iter().find(|f| f.height() != height) {
        return Err(VizError::ImageSize {
            width: bad.width(),
            height: bad.height(),
        });
    }
    let width: u32 =
        frames.iter().map(Raster::width).sum::<u32>() + STRIP_GAP * (frames.len() as u32 - 1);
    let mut out = Raster::new(width, height, gap_color)?;
    let mut x0 = 0;
    for f in frames {
        out.blit(f, x0);
        x0 += f.width() + STRIP_GAP;
    }
    Ok(out)
}

fn create(path: &Path) -> Result<BufWriter<File>, VizError> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|source| VizError::Io {
            path: dir.to_path_buf(),
            source,
        })?;
    }
    let file = File::create(path).map_err(|source| VizError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    Ok(BufWriter::new(file))
}

/// Writes `frames` to `path` as one PNG, or as an animated PNG (APNG) of `delay_ms` per
/// frame when there are several (viewers without APNG support show the first frame).
/// Frames must all have the first one's size.
pub fn write_png(path: impl AsRef<Path>, frames: &[Raster], delay_ms: u16) -> Result<(), VizError> {
    let path = path.as_ref();
    let Some(first) = frames.first() else {
        return Err(VizError::ImageSize {
            width: 0,
            height: 0,
        });
    };
    if let Some(bad) = frames
        .iter()
        .find(|f| (f.width(), f.height()) != (first.width(), first.height()))
    {
        return Err(VizError::ImageSize {
            width: bad.width(),
            height: bad.height(),
        });
    }
    let png_err = |source| VizError::Png {
        path: path.to_path_buf(),
        source,
    };
    let mut encoder = png::Encoder::new(create(path)?, first.width(), first.height());
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder.set_compression(png::Compression::Best);
    if frames.len() > 1 {
        encoder
            .set_animated(frames.len() as u32, 0)
            .map_err(png_err)?;
        encoder.set_frame_delay(delay_ms, 1000).map_err(png_err)?;
    }
    let mut writer = encoder.write_header().map_err(png_err)?;
    for f in frames {
        writer.write_image_data(&f.bytes()).map_err(png_err)?;
    }
    writer.finish().map_err(png_err)
}
