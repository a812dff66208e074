//! TetGen `.node` / `.ele` files (ASCII).
//!
//! `.node`: a header `<points> [<dimension = 3> [<attributes> [<boundary markers 0|1>]]]`,
//! then one row per point: `<number> <x> <y> <z> [attributes…] [marker]`.
//! `.ele`: a header `<tetrahedra> [<nodes per tetrahedron 4|10> [<region attributes>]]`,
//! then one row per tetrahedron: `<number> <n0> <n1> <n2> <n3> [6 more nodes] [attributes…]`.
//!
//! `#` starts a comment; blank lines are skipped. Rows are numbered consecutively from 0 or 1;
//! `.ele` node numbers use the numbering of the `.node` file. Of 10-node tetrahedra only the
//! four corners are kept. Attributes and markers are read and checked, then dropped.

use std::fmt::Write as _;
use std::path::Path;

use nalgebra::Vector3;
use tetpbd::TetMesh;

use crate::error::{FileKind, ReadError};
use crate::text::{capacity_hint, Rows};

/// Vertices of a `.node` file and the number of its first row (0 or 1).
struct Nodes {
    vertices: Vec<Vector3<f32>>,
    first: u64,
}

/// Reads a mesh from the text of a `.node` and an `.ele` file.
pub fn read_tetgen_str(node: &str, ele: &str) -> Result<TetMesh, ReadError> {
    let nodes = read_nodes(node)?;
    let tets = read_eles(ele, &nodes)?;
    Ok(TetMesh {
        vertices: nodes.vertices,
        tets,
    })
}

/// Reads a mesh from a `.node` and an `.ele` file.
pub fn read_tetgen_files(
    node: impl AsRef<Path>,
    ele: impl AsRef<Path>,
) -> Result<TetMesh, ReadError> {
    let node_text = read_to_string(node.as_ref(), FileKind::Node)?;
    let ele_text = read_to_string(ele.as_ref(), FileKind::Ele)?;
    read_tetgen_str(&node_text, &ele_text)
}

/// Writes `mesh` as the text of a `.node` and an `.ele` file (rows numbered from 0, no
/// attributes or markers; coordinates in the shortest form that reads back exactly).
pub fn write_tetgen(mesh: &TetMesh) -> (String, String) {
    let mut node = String::new();
    let _ = writeln!(node, "{} 3 0 0", mesh.vertices.len());
    for (i, v) in mesh.vertices.iter().enumerate() {
        let _ = writeln!(node, "{i} {} {} {}", v.x, v.y, v.z);
    }
    let mut ele = String::new();
    let _ = writeln!(ele, "{} 4 0", mesh.tets.len());
    for (i, t) in mesh.tets.iter().enumerate() {
        let _ = writeln!(ele, "{i} {} {} {} {}", t[0], t[1], t[2], t[3]);
    }
    (node, ele)
}

/// Reads a whole file, mapping failure to [`ReadError::Io`].
fn read_to_string(path: &Path, kind: FileKind) -> Result<String, ReadError> {
    std::fs::read_to_string(path).map_err(|source| ReadError::Io {
        kind,
        path: path.to_path_buf(),
        source,
    })
}

/// Header field `i` as an unsigned integer, or `default` when absent.
fn header_field(
    rows: &Rows<'_>,
    line: usize,
    fields: &[&str],
    i: usize,
    name: &'static str,
    default: u64,
) -> Result<u64, ReadError> {
    match fields.get(i) {
        Some(text) => rows.uint(line, name, text),
        None => Ok(default),
    }
}

/// Checks a row's own number against the expected sequence; returns it.
fn row_number(
    rows: &Rows<'_>,
    line: usize,
    text: &str,
    expected: Option<u64>,
) -> Result<u64, ReadError> {
    let found = rows.uint(line, "row number", text)?;
    match expected {
        None if found > 1 => Err(ReadError::Unsupported {
            kind: rows.kind(),
            line,
            what: format!("first row number {found} (rows are numbered from 0 or 1)"),
        }),
        Some(e) if e != found => Err(ReadError::BadRowNumber {
            kind: rows.kind(),
            line,
            expected: e,
            found,
        }),
        _ => Ok(found),
    }
}

/// Fails with [`ReadError::ExtraRows`] if any row is left.
fn no_extra_rows(rows: &mut Rows<'_>) -> Result<(), ReadError> {
    match rows.next_row() {
        Some((line, _)) => Err(ReadError::ExtraRows {
            kind: rows.kind(),
            line,
        }),
        None => Ok(()),
    }
}

fn read_nodes(text: &str) -> Result<Nodes, ReadError> {
    let mut rows = Rows::new(text, FileKind::Node, true);
    let Some((line, header)) = rows.next_row() else {
        return Err(ReadError::MissingSection {
            kind: FileKind::Node,
            line: rows.last_line(),
            section: "header line",
        });
    };
    if header.len() > 4 {
        return Err(rows.field_count(line, "header", 4, header.len()));
    }
    let count = rows.uint(line, "number of points", header[0])?;
    let dim = header_field(&rows, line, &header, 1, "dimension", 3)?;
    let attributes = header_field(&rows, line, &header, 2, "number of attributes", 0)?;
    let markers = header_field(&rows, line, &header, 3, "boundary marker flag", 0)?;
    if dim != 3 {
        return Err(ReadError::Unsupported {
            kind: FileKind::Node,
            line,
            what: format!("dimension {dim} (only 3)"),
        });
    }
    if markers > 1 {
        return Err(ReadError::Unsupported {
            kind: FileKind::Node,
            line,
            what: format!("boundary marker flag {markers} (0 or 1)"),
        });
    }
    let width = 4u64
        .checked_add(attributes)
        .and_then(|w| w.checked_add(markers))
        .and_then(|w| usize::try_from(w).ok())
        .ok_or_else(|| rows.bad_number(line, "number of attributes", header[2]))?;
    let mut vertices = Vec::with_capacity(capacity_hint(count, text, 8));
    let mut first = None;
    for n in 0..count {
        let Some((line, fields)) = rows.next_row() else {
            return Err(rows.missing_rows("point rows", count, n));
        };
        if fields.len() != width {
            return Err(rows.field_count(line, "point row", width, fields.len()));
        }
        let number = row_number(&rows, line, fields[0], first.map(|f: u64| f + n))?;
        first.get_or_insert(number);
        let x = rows.coord(line, "x coordinate", fields[1])?;
        let y = rows.coord(line, "y coordinate", fields[2])?;
        let z = rows.coord(line, "z coordinate", fields[3])?;
        for a in &fields[4..4 + attributes as usize] {
            rows.coord(line, "attribute", a)?;
        }
        if markers == 1 {
            rows.int(line, "boundary marker", fields[width - 1])?;
        }
        vertices.push(Vector3::new(x, y, z));
    }
    no_extra_rows(&mut rows)?;
    Ok(Nodes {
        vertices,
        first: first.unwrap_or(0),
    })
}

fn read_eles(text: &str, nodes: &Nodes) -> Result<Vec<[u32; 4]>, ReadError> {
    let mut rows = Rows::new(text, FileKind::Ele, true);
    let Some((line, header)) = rows.next_row() else {
        return Err(ReadError::MissingSection {
            kind: FileKind::Ele,
            line: rows.last_line(),
            section: "header line",
        });
    };
    if header.len() > 3 {
        return Err(rows.field_count(line, "header", 3, header.len()));
    }
    let count = rows.uint(line, "number of tetrahedra", header[0])?;
    let per_tet = header_field(&rows, line, &header, 1, "nodes per tetrahedron", 4)?;
    let attributes = header_field(&rows, line, &header, 2, "number of region attributes", 0)?;
    if per_tet != 4 && per_tet != 10 {
        return Err(ReadError::Unsupported {
            kind: FileKind::Ele,
            line,
            what: format!("{per_tet} nodes per tetrahedron (4 or 10)"),
        });
    }
    let width = (1 + per_tet)
        .checked_add(attributes)
        .and_then(|w| usize::try_from(w).ok())
        .ok_or_else(|| rows.bad_number(line, "number of region attributes", header[2]))?;
    let vertex_count = nodes.vertices.len();
    let mut tets = Vec::with_capacity(capacity_hint(count, text, 8));
    let mut first = None;
    for n in 0..count {
        let Some((line, fields)) = rows.next_row() else {
            return Err(rows.missing_rows("tetrahedron rows", count, n));
        };
        if fields.len() != width {
            return Err(rows.field_count(line, "tetrahedron row", width, fields.len()));
        }
        let number = row_number(&rows, line, fields[0], first.map(|f: u64| f + n))?;
        first.get_or_insert(number);
        let mut tet = [0u32; 4];
        for (k, text) in fields[1..1 + per_tet as usize].iter().enumerate() {
            let index = rows.uint(line, "node number", text)?;
            let local = index
                .checked_sub(nodes.first)
                .filter(|&i| i < vertex_count as u64)
                .ok_or(ReadError::IndexOutOfRange {
                    kind: FileKind::Ele,
                    line,
                    index,
                    vertex_count,
                })?;
            if k < 4 {
                tet[k] = local as u32;
            }
        }
        for a in &fields[1 + per_tet as usize..] {
            rows.coord(line, "region attribute", a)?;
        }
        tets.push(tet);
    }
    no_extra_rows(&mut rows)?;
    Ok(tets)
}
