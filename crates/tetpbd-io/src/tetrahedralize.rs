//! Filling a closed triangle surface with tetrahedra (parry's `volume_mesh`).

use crate::glam::{to_glam, to_na};
use nalgebra::Vector3;
use parry3d::transformation::{volume_mesh, MeshEnclosure, VolumeMeshParameters};
use tetpbd::constraint::signed_volume;
use tetpbd::{SoftBodyBuilder, TetMesh};

use crate::mesher_error::SurfaceError;
use crate::surface::SurfaceMesh;

/// Fills a closed [`SurfaceMesh`] with tetrahedra of about `cell_size` (m) using parry's
/// `volume_mesh` (a body-centred cubic lattice cover, Labelle–Shewchuk cells kept whole).
///
/// The result *contains* the surface: every lattice cell the solid reaches is kept, so the
/// tetrahedral body is up to about one cell larger than the surface and blocky at the cell
/// size; [`Self::smoothing`] shrink-wraps it toward the surface while keeping containment.
/// Because the surface is inside the tetrahedra, it can be embedded in them
/// ([`crate::Skin`]) to drive a fine render mesh from a coarse simulation.
///
/// ```
/// use tetpbd_io::{SurfaceMesh, TetrahedralizeBuilder};
/// let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
/// let surface = SurfaceMesh::from_obj_str(obj)?;
/// let mesh = TetrahedralizeBuilder::new(0.25).build(&surface)?;
/// assert!(mesh.tets.len() > 10);
/// let err = TetrahedralizeBuilder::new(0.0).build(&surface).unwrap_err();
/// assert_eq!(err.to_string(), "cell size 0 m is not a positive finite number");
/// # Ok::<(), tetpbd_io::SurfaceError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TetrahedralizeBuilder {
    cell_size: f32,
    smoothing: u32,
    subdivisions: u32,
    max_lattice_points: u64,
}

impl TetrahedralizeBuilder {
    /// Default limit on lattice points (about 14 million tetrahedra at most).
    pub const DEFAULT_MAX_LATTICE_POINTS: u64 = 2_000_000;

    /// Lattice cell size `cell_size` (m; the edge of the cube the lattice is made of). Defaults:
    /// no smoothing, no subdivision, [`Self::DEFAULT_MAX_LATTICE_POINTS`].
    pub fn new(cell_size: f32) -> Self {
        TetrahedralizeBuilder {
            cell_size,
            smoothing: 0,
            subdivisions: 0,
            max_lattice_points: Self::DEFAULT_MAX_LATTICE_POINTS,
        }
    }

    /// Shrink-wrap iterations pulling the blocky cover toward the surface (parry's
    /// `cover_smoothing`); 0 keeps the raw lattice cells.
    pub fn smoothing(mut self, iterations: u32) -> Self {
        self.smoothing = iterations;
        self
    }

    /// Halvings of the cell size allowed for cells crossing the surface (parry's
    /// `cover_subdivisions`, clamped to 4); 0 keeps the boundary at the cell size.
    pub fn subdivisions(mut self, levels: u32) -> Self {
        self.subdivisions = levels.min(4);
        self
    }

    /// Largest lattice the cell size may ask for, as a guard against a cell size far too
    /// small for the surface (which would exhaust memory rather than fail). It counts the
    /// uniform lattice at the cell size over the surface's box; [`Self::subdivisions`] adds
    /// points near the surface on top of that.
    pub fn max_lattice_points(mut self, limit: u64) -> Self {
        self.max_lattice_points = limit;
        self
    }

    /// Tetrahedralizes `surface` (welded and checked with [`SurfaceMesh::closed`] first).
    ///
    /// The tetrahedra are positively oriented; every vertex is used. Errors: those of
    /// [`SurfaceMesh::closed`], [`SurfaceError::BadCellSize`],
    /// [`SurfaceError::TooManyLatticePoints`], [`SurfaceError::NoTetrahedra`],
    /// [`SurfaceError::DegenerateOutput`] (a tetrahedron [`SoftBodyBuilder`] would reject).
    pub fn build(&self, surface: &SurfaceMesh) -> Result<TetMesh, SurfaceError> {
        let cell = self.cell_size;
        if !(cell.is_finite() && cell > 0.0) {
            return Err(SurfaceError::BadCellSize { value: cell });
        }
        let closed = surface.closed()?;
        let points = lattice_points(&closed, cell);
        if points > self.max_lattice_points {
            return Err(SurfaceError::TooManyLatticePoints {
                points,
                limit: self.max_lattice_points,
            });
        }
        let vertices: Vec<_> = closed.vertices.iter().map(to_glam).collect();
        let mut params = VolumeMeshParameters::new(cell);
        params.enclosure = MeshEnclosure::Cover;
        params.cover_smoothing = self.smoothing;
        params.cover_subdivisions = self.subdivisions;
        let out =
            volume_mesh(&vertices, &closed.triangles, &params).ok_or(SurfaceError::NoTetrahedra)?;
        let mesh = TetMesh {
            vertices: out.vertices.into_iter().map(to_na).collect(),
            tets: out.cells,
        };
        if mesh.tets.is_empty() {
            return Err(SurfaceError::NoTetrahedra);
        }
        check_output(&mesh)?;
        Ok(mesh)
    }
}

/// Points of the uniform lattice parry lays over the surface's box grown by two cells a
/// side (its domain margin plus the lattice's own), as parry counts them.
fn lattice_points(surface: &SurfaceMesh, cell: f32) -> u64 {
    let mut lo = surface.vertices[0];
    let mut hi = lo;
    for v in &surface.vertices {
        lo = lo.inf(v);
        hi = hi.sup(v);
    }
    let half = f64::from(cell) * 0.5;
    let dims = (hi - lo).map(|e| {
        ((f64::from(e) + 4.0 * f64::from(cell)) / half)
            .ceil()
            .max(2.0)
    });
    let even = dims.map(|d| (d / 2.0).floor() + 1.0);
    let odd = dims.map(|d| ((d + 1.0) / 2.0).floor());
    let total = even.x * even.y * even.z + odd.x * odd.y * odd.z;
    if total >= u64::MAX as f64 {
        u64::MAX
    } else {
        total as u64
    }
}

/// Rejects non-finite vertices and tetrahedra [`SoftBodyBuilder`] would call degenerate.
fn check_output(mesh: &TetMesh) -> Result<(), SurfaceError> {
    for (tet, t) in mesh.tets.iter().enumerate() {
        let (volume, ok) = builder_volume(&t.map(|i| mesh.vertices[i as usize]));
        if !ok || volume <= 0.0 {
            return Err(SurfaceError::DegenerateOutput { tet, volume });
        }
    }
    Ok(())
}

/// Signed volume (m³) of a tetrahedron and whether [`SoftBodyBuilder`] would accept it:
/// finite, and `|V| ≥ DEFAULT_EPSILON · (longest edge)³` with `V ≠ 0`.
pub(crate) fn builder_volume(corners: &[Vector3<f32>; 4]) -> (f32, bool) {
    let [a, b, c, d] = corners;
    let volume = signed_volume(a, b, c, d);
    let longest = [b - a, c - a, d - a, c - b, d - b, d - c]
        .iter()
        .map(|e| e.norm())
        .fold(0.0f32, f32::max);
    let min = SoftBodyBuilder::DEFAULT_EPSILON * longest.powi(3);
    let ok = volume.is_finite() && volume != 0.0 && volume.abs() >= min;
    (volume, ok)
}
