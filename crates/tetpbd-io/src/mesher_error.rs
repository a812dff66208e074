//! Error types of surface import, tetrahedralization and skinning.

use std::fmt;
use std::path::PathBuf;

/// Why a triangle surface could not be read, checked or filled with tetrahedra.
#[derive(Debug)]
pub enum SurfaceError {
    /// The OBJ file could not be read.
    Io {
        /// The path given.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// `tobj` rejected the OBJ text.
    Obj(tobj::LoadError),
    /// The surface has no vertices or no triangles.
    Empty {
        /// Number of vertices given.
        vertices: usize,
        /// Number of triangles given.
        triangles: usize,
    },
    /// A vertex coordinate is NaN or infinite.
    NonFinite {
        /// Index of the vertex.
        vertex: usize,
        /// The offending coordinate value.
        value: f32,
    },
    /// A triangle refers to a vertex that does not exist.
    IndexOutOfRange {
        /// Index of the triangle.
        triangle: usize,
        /// The offending vertex index.
        index: u32,
        /// Number of vertices.
        vertex_count: usize,
    },
    /// A triangle uses the same vertex twice (after welding equal positions).
    DegenerateTriangle {
        /// Index of the triangle.
        triangle: usize,
    },
    /// An edge belongs to one triangle only: the surface has a hole.
    OpenEdge {
        /// First vertex of the edge (welded index).
        a: u32,
        /// Second vertex of the edge (welded index).
        b: u32,
    },
    /// An edge belongs to more than two triangles.
    NonManifoldEdge {
        /// First vertex of the edge (welded index).
        a: u32,
        /// Second vertex of the edge (welded index).
        b: u32,
        /// Number of triangles sharing it.
        triangles: usize,
    },
    /// Two triangles sharing an edge run along it in the same direction, so their windings
    /// disagree.
    InconsistentOrientation {
        /// First vertex of the edge (welded index).
        a: u32,
        /// Second vertex of the edge (welded index).
        b: u32,
    },
    /// The closed surface encloses no volume.
    ZeroVolume,
    /// The cell size is not a positive finite number.
    BadCellSize {
        /// The value given, m.
        value: f32,
    },
    /// The cell size is so small against the surface that the lattice would exceed the limit.
    TooManyLatticePoints {
        /// Lattice points the cell size asks for.
        points: u64,
        /// The limit (see `TetrahedralizeBuilder::max_lattice_points`).
        limit: u64,
    },
    /// parry produced no tetrahedra.
    NoTetrahedra,
    /// parry produced a tetrahedron the soft-body builder would reject.
    DegenerateOutput {
        /// Index of the tetrahedron in the output.
        tet: usize,
        /// Its signed volume, m³.
        volume: f32,
    },
}

impl fmt::Display for SurfaceError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SurfaceError::Io { path, source } => {
                write!(f, "OBJ file {}: {source}", path.display())
            }
            SurfaceError::Obj(e) => write!(f, "OBJ: {e}"),
            SurfaceError::Empty {
                vertices,
                triangles,
            } => write!(
                f,
                "empty surface: {vertices} vertices, {triangles} triangles"
            ),
            SurfaceError::NonFinite { vertex, value } => {
                write!(f, "vertex {vertex} has a non-finite coordinate {value}")
            }
            SurfaceError::IndexOutOfRange {
                triangle,
                index,
                vertex_count,
            } => write!(
                f,
                "triangle {triangle}: vertex {index} does not exist ({vertex_count} vertices)"
            ),
            SurfaceError::DegenerateTriangle { triangle } => {
                write!(f, "triangle {triangle} uses a vertex twice")
            }
            SurfaceError::OpenEdge { a, b } => {
                write!(
                    f,
                    "edge {a}-{b} belongs to one triangle: the surface is open"
                )
            }
            SurfaceError::NonManifoldEdge { a, b, triangles } => write!(
                f,
                "edge {a}-{b} belongs to {triangles} triangles: the surface is not manifold"
            ),
            SurfaceError::InconsistentOrientation { a, b } => write!(
                f,
                "the two triangles at edge {a}-{b} are wound inconsistently"
            ),
            SurfaceError::ZeroVolume => write!(f, "the closed surface encloses no volume"),
            SurfaceError::BadCellSize { value } => {
                write!(f, "cell size {value} m is not a positive finite number")
            }
            SurfaceError::TooManyLatticePoints { points, limit } => write!(
                f,
                "cell size too small: {points} lattice points, limit {limit}"
            ),
            SurfaceError::NoTetrahedra => write!(f, "tetrahedralization produced no tetrahedra"),
            SurfaceError::DegenerateOutput { tet, volume } => write!(
                f,
                "tetrahedralization produced degenerate tetrahedron {tet} (volume {volume} m³)"
            ),
        }
    }
}

impl std::error::Error for SurfaceError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            SurfaceError::Io { source, .. } => Some(source),
            SurfaceError::Obj(e) => Some(e),
            _ => None,
        }
    }
}

/// Why points could not be embedded in tetrahedra, or the skin not updated.
#[derive(Debug, Clone, PartialEq)]
pub enum SkinError {
    /// There are no tetrahedra to embed in.
    NoTetrahedra,
    /// A tetrahedron refers to a vertex that does not exist.
    IndexOutOfRange {
        /// Index of the tetrahedron.
        tet: usize,
        /// The offending vertex index.
        index: u32,
        /// Number of vertices (positions) given.
        vertex_count: usize,
    },
    /// A tetrahedron has (nearly) zero volume, so barycentric coordinates in it are undefined.
    DegenerateTet {
        /// Index of the tetrahedron.
        tet: usize,
        /// Its signed volume, m³.
        volume: f32,
    },
    /// A tetrahedron vertex or an embedded point is NaN or infinite.
    NonFinite {
        /// `"vertex"` or `"point"`.
        what: &'static str,
        /// Its index.
        index: usize,
    },
    /// The positions or output slice given to `Skin::deform` have the wrong length.
    LengthMismatch {
        /// `"positions"` or `"output"`.
        what: &'static str,
        /// Length the skin was embedded with.
        expected: usize,
        /// Length given.
        found: usize,
    },
    /// After a tear, no piece holds the tetrahedron an embedded point is bound to (the event
    /// is not the body's, or the pieces' tetrahedra were not given in the event's order).
    LostTetrahedron {
        /// Index of the point.
        point: usize,
    },
}

impl fmt::Display for SkinError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SkinError::NoTetrahedra => write!(f, "no tetrahedra to embed the skin in"),
            SkinError::IndexOutOfRange {
                tet,
                index,
                vertex_count,
            } => write!(
                f,
                "tetrahedron {tet}: vertex {index} does not exist ({vertex_count} vertices)"
            ),
            SkinError::DegenerateTet { tet, volume } => {
                write!(f, "tetrahedron {tet} is degenerate (volume {volume} m³)")
            }
            SkinError::NonFinite { what, index } => {
                write!(f, "{what} {index} has a non-finite coordinate")
            }
            SkinError::LengthMismatch {
                what,
                expected,
                found,
            } => write!(f, "{what} has length {found}, expected {expected}"),
            SkinError::LostTetrahedron { point } => {
                write!(f, "point {point}: no piece holds its tetrahedron")
            }
        }
    }
}

impl std::error::Error for SkinError {}
