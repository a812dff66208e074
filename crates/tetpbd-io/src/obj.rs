//! Wavefront OBJ output of triangle meshes (soft-body surfaces, collider meshes).

use std::fmt::Write as _;
use std::path::Path;

use nalgebra::Vector3;
use tetpbd::Surface;

use crate::error::WriteError;

/// OBJ text of the triangles `triangles` over `positions` (m): only the vertices the
/// triangles use are written (in increasing index order), faces keep their winding.
pub fn triangles_obj(
    positions: &[Vector3<f32>],
    triangles: &[[u32; 3]],
) -> Result<String, WriteError> {
    let mut used: Vec<u32> = triangles.iter().flatten().copied().collect();
    used.sort_unstable();
    used.dedup();
    if let Some(&last) = used.last() {
        if last as usize >= positions.len() {
            return Err(WriteError::IndexOutOfRange {
                index: last,
                len: positions.len(),
            });
        }
    }
    let mut s = String::new();
    for &i in &used {
        let p = positions[i as usize];
        let _ = writeln!(s, "v {} {} {}", p.x, p.y, p.z);
    }
    for tri in triangles {
        // Every corner is in `used`, so the search succeeds; OBJ indices are 1-based.
        let [a, b, c] = tri.map(|i| used.binary_search(&i).unwrap_or(0) + 1);
        let _ = writeln!(s, "f {a} {b} {c}");
    }
    Ok(s)
}

/// OBJ text of a soft body's outward-wound boundary at `positions` (m), e.g.
/// `surface_obj(&surface, particles.positions())`.
pub fn surface_obj(surface: &Surface, positions: &[Vector3<f32>]) -> Result<String, WriteError> {
    triangles_obj(positions, surface.triangles())
}

/// Writes [`surface_obj`] to `path`.
pub fn write_surface_obj(
    path: impl AsRef<Path>,
    surface: &Surface,
    positions: &[Vector3<f32>],
) -> Result<(), WriteError> {
    std::fs::write(path, surface_obj(surface, positions)?)?;
    Ok(())
}
