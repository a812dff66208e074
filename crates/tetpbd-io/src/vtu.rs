//! VTK unstructured grid (`.vtu`, XML, ASCII) output of tetrahedra, for ParaView.

use std::fmt::Write as _;
use std::path::Path;

use tetpbd::{Particles, Tetrahedra};

use crate::error::WriteError;

/// VTK cell type of a linear tetrahedron.
const VTK_TETRA: u8 = 10;

/// `.vtu` text of a soft body's tetrahedra at its current positions (m).
///
/// Points are the body's particles in particle order ([`Particles::source`] gives the input
/// vertex of each when the builder renumbered them).
///
/// Cell data per tetrahedron, in the body's stored (solver) order:
/// * `volume_ratio`: current signed volume over signed rest volume (1 at rest, negative when
///   inverted; 0 for a zero rest volume);
/// * `inverted`: 1 when the current signed volume has the opposite sign of, or is zero
///   against, the rest volume (as [`Tetrahedra::count_inverted`] counts), else 0.
pub fn tetrahedra_vtu(particles: &Particles, tets: &Tetrahedra) -> Result<String, WriteError> {
    let positions = particles.positions();
    if let Some(&bad) = tets
        .indices()
        .iter()
        .flatten()
        .find(|&&i| i as usize >= positions.len())
    {
        return Err(WriteError::IndexOutOfRange {
            index: bad,
            len: positions.len(),
        });
    }
    let n = tets.len();
    let mut s = String::from(
        "<?xml version=\"1.0\"?>\n\
         <VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n\
         <UnstructuredGrid>\n",
    );
    let _ = writeln!(
        s,
        "<Piece NumberOfPoints=\"{}\" NumberOfCells=\"{n}\">",
        positions.len()
    );
    s.push_str(
        "<Points>\n<DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"ascii\">\n",
    );
    for p in positions {
        let _ = writeln!(s, "{} {} {}", p.x, p.y, p.z);
    }
    s.push_str("</DataArray>\n</Points>\n<Cells>\n");
    s.push_str("<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n");
    for t in tets.indices() {
        let _ = writeln!(s, "{} {} {} {}", t[0], t[1], t[2], t[3]);
    }
    s.push_str("</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
    for c in 1..=n as u64 {
        let _ = writeln!(s, "{}", 4 * c);
    }
    s.push_str("</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
    for _ in 0..n {
        let _ = writeln!(s, "{VTK_TETRA}");
    }
    s.push_str("</DataArray>\n</Cells>\n<CellData Scalars=\"volume_ratio\">\n");
    let volumes: Vec<(f32, f32)> = (0..n)
        .map(|t| (tets.volume_at(t, positions), tets.rest_volumes()[t]))
        .collect();
    s.push_str("<DataArray type=\"Float32\" Name=\"volume_ratio\" format=\"ascii\">\n");
    for &(now, rest) in &volumes {
        let ratio = if rest != 0.0 { now / rest } else { 0.0 };
        let _ = writeln!(s, "{ratio}");
    }
    s.push_str("</DataArray>\n<DataArray type=\"UInt8\" Name=\"inverted\" format=\"ascii\">\n");
    for &(now, rest) in &volumes {
        let _ = writeln!(s, "{}", u8::from(now * rest <= 0.0));
    }
    s.push_str("</DataArray>\n</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
    Ok(s)
}

/// Writes [`tetrahedra_vtu`] to `path`.
pub fn write_tetrahedra_vtu(
    path: impl AsRef<Path>,
    particles: &Particles,
    tets: &Tetrahedra,
) -> Result<(), WriteError> {
    std::fs::write(path, tetrahedra_vtu(particles, tets)?)?;
    Ok(())
}
