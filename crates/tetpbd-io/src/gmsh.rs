//! Gmsh `.msh` files, format 4.1 ASCII (and 2.2 ASCII through [`crate::gmsh22`]).
//!
//! Read: `$MeshFormat` (must say `4.1 0 <data size>` or `2.2 0 <data size>`), `$Nodes` (entity blocks of node tags
//! then coordinates, parametric coordinates allowed and dropped) and `$Elements`, of which
//! only type 4 (4-node tetrahedron) is kept; other element types and all other sections are
//! skipped. Vertices are the nodes in file order; node tags are mapped to those indices.
//! Nodes used by no tetrahedron are kept (the soft-body builder rejects them).
//!
//! Binary 4.1 files are read by [`read_msh_bytes`] and [`read_msh_file`] (through
//! [`crate::gmsh_binary`]); given as text to [`read_msh_str`] they are
//! [`ReadError::Unsupported`].

use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::Path;

use nalgebra::Vector3;
use tetpbd::TetMesh;

use crate::error::{FileKind, ReadError};
use crate::text::{capacity_hint, Rows};

/// Vertices in file order and the map from node tag to vertex index.
pub(crate) type NodeTable = (Vec<Vector3<f32>>, HashMap<u64, u32>);

/// Gmsh element type of the 4-node tetrahedron.
pub(crate) const TETRAHEDRON: i64 = 4;

/// The format versions read.
#[derive(Clone, Copy)]
enum Version {
    V41,
    V22,
}

/// Reads a mesh from the text of a `.msh` file, format 4.1 or 2.2 ASCII.
pub fn read_msh_str(text: &str) -> Result<TetMesh, ReadError> {
    let mut rows = Rows::new(text, FileKind::Msh, false);
    let mut format = None;
    let mut nodes: Option<NodeTable> = None;
    let mut tets: Option<Vec<[u32; 4]>> = None;
    while let Some((line, fields)) = rows.next_row() {
        let name = fields[0];
        if fields.len() != 1 || !name.starts_with('$') {
            return Err(ReadError::Unsupported {
                kind: FileKind::Msh,
                line,
                what: format!(
                    "text outside a section: `{}`",
                    name.chars().take(32).collect::<String>()
                ),
            });
        }
        match name {
            "$MeshFormat" if format.is_some() => return Err(repeated(line, "$MeshFormat")),
            "$MeshFormat" => format = Some(read_format(&mut rows)?),
            "$Nodes" | "$Elements" if format.is_none() => {
                return Err(ReadError::MissingSection {
                    kind: FileKind::Msh,
                    line,
                    section: "$MeshFormat",
                });
            }
            "$Nodes" if nodes.is_some() => return Err(repeated(line, "$Nodes")),
            "$Nodes" => {
                nodes = Some(match format {
                    Some(Version::V22) => crate::gmsh22::read_nodes(&mut rows, text)?,
                    _ => read_nodes(&mut rows, text)?,
                })
            }
            "$Elements" if tets.is_some() => return Err(repeated(line, "$Elements")),
            "$Elements" => {
                let Some((vertices, tags)) = &nodes else {
                    return Err(ReadError::MissingSection {
                        kind: FileKind::Msh,
                        line,
                        section: "$Nodes (before $Elements)",
                    });
                };
                tets = Some(match format {
                    Some(Version::V22) => {
                        crate::gmsh22::read_elements(&mut rows, text, tags, vertices.len())?
                    }
                    _ => read_elements(&mut rows, text, tags, vertices.len())?,
                });
            }
            _ => skip_section(&mut rows, name)?,
        }
    }
    let end = rows.last_line();
    let missing = |section| ReadError::MissingSection {
        kind: FileKind::Msh,
        line: end,
        section,
    };
    if format.is_none() {
        return Err(missing("$MeshFormat"));
    }
    let (vertices, _) = nodes.ok_or_else(|| missing("$Nodes"))?;
    let tets = tets.ok_or_else(|| missing("$Elements"))?;
    Ok(TetMesh { vertices, tets })
}

/// Reads a mesh from the bytes of a `.msh` file: format 4.1 binary, or 4.1 or 2.2 ASCII.
pub fn read_msh_bytes(bytes: &[u8]) -> Result<TetMesh, ReadError> {
    let mut lines = bytes
        .split(|&b| b == b'\n')
        .map(<[u8]>::trim_ascii)
        .filter(|l| !l.is_empty());
    let binary = lines.next() == Some(b"$MeshFormat")
        && lines.next().is_some_and(|l| {
            let mut fields = l.split(u8::is_ascii_whitespace).filter(|f| !f.is_empty());
            fields.nth(1) == Some(b"1")
        });
    if binary {
        crate::gmsh_binary::read_binary(bytes)
    } else {
        read_msh_str(&String::from_utf8_lossy(bytes))
    }
}

/// Reads a mesh from a `.msh` file: format 4.1 binary, or 4.1 or 2.2 ASCII.
pub fn read_msh_file(path: impl AsRef<Path>) -> Result<TetMesh, ReadError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|source| ReadError::Io {
        kind: FileKind::Msh,
        path: path.to_path_buf(),
        source,
    })?;
    read_msh_bytes(&bytes)
}

/// Writes `mesh` as a `.msh` 4.1 ASCII file: one volume entity holding all nodes (tags
/// `1..=n`) and all tetrahedra (tags `1..=m`).
pub fn write_msh(mesh: &TetMesh) -> String {
    let n = mesh.vertices.len();
    let m = mesh.tets.len();
    let mut s = String::from("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n");
    let _ = writeln!(s, "1 {n} {} {n}\n3 1 0 {n}", n.min(1));
    for i in 1..=n {
        let _ = writeln!(s, "{i}");
    }
    for v in &mesh.vertices {
        let _ = writeln!(s, "{} {} {}", v.x, v.y, v.z);
    }
    s.push_str("$EndNodes\n$Elements\n");
    let _ = writeln!(s, "1 {m} {} {m}\n3 1 4 {m}", m.min(1));
    for (i, t) in mesh.tets.iter().enumerate() {
        let _ = writeln!(
            s,
            "{} {} {} {} {}",
            i + 1,
            u64::from(t[0]) + 1,
            u64::from(t[1]) + 1,
            u64::from(t[2]) + 1,
            u64::from(t[3]) + 1
        );
    }
    s.push_str("$EndElements\n");
    s
}

fn repeated(line: usize, section: &str) -> ReadError {
    ReadError::Unsupported {
        kind: FileKind::Msh,
        line,
        what: format!("a second {section} section"),
    }
}

/// The next data row of a section; a `$` row or the end of input means rows are missing.
pub(crate) fn data_row<'a>(
    rows: &mut Rows<'a>,
    what: &'static str,
    expected: u64,
    found: u64,
) -> Result<(usize, Vec<&'a str>), ReadError> {
    match rows.peek_row() {
        Some((_, fields)) if !fields[0].starts_with('$') => rows
            .next_row()
            .ok_or_else(|| rows.missing_rows(what, expected, found)),
        Some((line, _)) => Err(ReadError::MissingRows {
            kind: FileKind::Msh,
            line: *line,
            what,
            expected,
            found,
        }),
        None => Err(rows.missing_rows(what, expected, found)),
    }
}

/// Consumes the `$End…` row closing a section.
pub(crate) fn end_section(rows: &mut Rows<'_>, end: &'static str) -> Result<(), ReadError> {
    match rows.next_row() {
        Some((_, fields)) if fields.len() == 1 && fields[0] == end => Ok(()),
        Some((line, fields)) if !fields[0].starts_with('$') => Err(ReadError::ExtraRows {
            kind: FileKind::Msh,
            line,
        }),
        other => Err(ReadError::MissingSection {
            kind: FileKind::Msh,
            line: other.map_or(rows.last_line(), |(line, _)| line),
            section: end,
        }),
    }
}

/// Skips an unknown section up to its `$End…` row.
fn skip_section(rows: &mut Rows<'_>, name: &str) -> Result<(), ReadError> {
    let end = format!("$End{}", &name[1..]);
    while let Some((_, fields)) = rows.next_row() {
        if fields[0] == end {
            return Ok(());
        }
    }
    Err(ReadError::MissingSection {
        kind: FileKind::Msh,
        line: rows.last_line(),
        section: "$End… of a skipped section",
    })
}

fn read_format(rows: &mut Rows<'_>) -> Result<Version, ReadError> {
    let (line, fields) = data_row(rows, "$MeshFormat rows", 1, 0)?;
    if fields.len() != 3 {
        return Err(rows.field_count(line, "$MeshFormat row", 3, fields.len()));
    }
    let version = match fields[0] {
        "4.1" => Version::V41,
        "2.2" => Version::V22,
        _ => {
            return Err(ReadError::Unsupported {
                kind: FileKind::Msh,
                line,
                what: format!(
                    "format version `{}` (4.1 or 2.2)",
                    fields[0].chars().take(32).collect::<String>()
                ),
            })
        }
    };
    let file_type = rows.uint(line, "file type", fields[1])?;
    rows.uint(line, "data size", fields[2])?;
    if file_type != 0 {
        return Err(ReadError::Unsupported {
            kind: FileKind::Msh,
            line,
            what: "binary file as text (read it with read_msh_bytes or read_msh_file)".to_string(),
        });
    }
    end_section(rows, "$EndMeshFormat")?;
    Ok(version)
}

/// A 4-field section or block header as unsigned integers (`signed` marks fields read as
/// signed and returned as their absolute value).
fn header4(
    rows: &mut Rows<'_>,
    what: &'static str,
    names: [&'static str; 4],
    signed: [bool; 4],
) -> Result<(usize, [u64; 4]), ReadError> {
    let (line, fields) = data_row(rows, what, 1, 0)?;
    if fields.len() != 4 {
        return Err(rows.field_count(line, what, 4, fields.len()));
    }
    let mut out = [0u64; 4];
    for k in 0..4 {
        out[k] = if signed[k] {
            rows.int(line, names[k], fields[k])?.unsigned_abs()
        } else {
            rows.uint(line, names[k], fields[k])?
        };
    }
    Ok((line, out))
}

fn read_nodes(rows: &mut Rows<'_>, text: &str) -> Result<NodeTable, ReadError> {
    let names = ["numEntityBlocks", "numNodes", "minNodeTag", "maxNodeTag"];
    let (header_line, [blocks, total, _, _]) = header4(rows, "$Nodes header", names, [false; 4])?;
    let mut vertices = Vec::with_capacity(capacity_hint(total, text, 8));
    let mut tags = HashMap::with_capacity(capacity_hint(total, text, 8));
    let mut sum = 0u64;
    let block_names = ["entityDim", "entityTag", "parametric", "numNodesInBlock"];
    for _ in 0..blocks {
        let (line, [dim, _, parametric, count]) = header4(
            rows,
            "node block header",
            block_names,
            [false, true, false, false],
        )?;
        if dim > 3 || parametric > 1 {
            return Err(ReadError::Unsupported {
                kind: FileKind::Msh,
                line,
                what: format!("node block with entityDim {dim}, parametric {parametric}"),
            });
        }
        let first = vertices.len();
        for n in 0..count {
            let (line, fields) = data_row(rows, "node tags", count, n)?;
            if fields.len() != 1 {
                return Err(rows.field_count(line, "node tag row", 1, fields.len()));
            }
            let tag = rows.uint(line, "node tag", fields[0])?;
            let index = u32::try_from(first as u64 + n).map_err(|_| ReadError::Unsupported {
                kind: FileKind::Msh,
                line,
                what: "more than 2^32 nodes".to_string(),
            })?;
            if tags.insert(tag, index).is_some() {
                return Err(ReadError::DuplicateTag {
                    kind: FileKind::Msh,
                    line,
                    tag,
                });
            }
        }
        let width = 3 + if parametric == 1 { dim as usize } else { 0 };
        for n in 0..count {
            let (line, fields) = data_row(rows, "node coordinates", count, n)?;
            if fields.len() != width {
                return Err(rows.field_count(line, "node coordinate row", width, fields.len()));
            }
            let x = rows.coord(line, "x coordinate", fields[0])?;
            let y = rows.coord(line, "y coordinate", fields[1])?;
            let z = rows.coord(line, "z coordinate", fields[2])?;
            for p in &fields[3..] {
                rows.coord(line, "parametric coordinate", p)?;
            }
            vertices.push(Vector3::new(x, y, z));
        }
        sum = sum.saturating_add(count);
    }
    if sum != total {
        return Err(ReadError::CountMismatch {
            kind: FileKind::Msh,
            line: header_line,
            what: "nodes",
            expected: total,
            found: sum,
        });
    }
    end_section(rows, "$EndNodes")?;
    Ok((vertices, tags))
}

fn read_elements(
    rows: &mut Rows<'_>,
    text: &str,
    tags: &HashMap<u64, u32>,
    vertex_count: usize,
) -> Result<Vec<[u32; 4]>, ReadError> {
    let names = [
        "numEntityBlocks",
        "numElements",
        "minElementTag",
        "maxElementTag",
    ];
    let (header_line, [blocks, total, _, _]) =
        header4(rows, "$Elements header", names, [false; 4])?;
    let mut tets = Vec::with_capacity(capacity_hint(total, text, 8));
    let mut sum = 0u64;
    let block_names = [
        "entityDim",
        "entityTag",
        "elementType",
        "numElementsInBlock",
    ];
    for _ in 0..blocks {
        let (line, fields) = data_row(rows, "element block header", 1, 0)?;
        if fields.len() != 4 {
            return Err(rows.field_count(line, "element block header", 4, fields.len()));
        }
        rows.uint(line, block_names[0], fields[0])?;
        rows.int(line, block_names[1], fields[1])?;
        let element_type = rows.int(line, block_names[2], fields[2])?;
        let count = rows.uint(line, block_names[3], fields[3])?;
        for n in 0..count {
            let (line, fields) = data_row(rows, "element rows", count, n)?;
            rows.uint(line, "element tag", fields[0])?;
            if element_type != TETRAHEDRON {
                continue;
            }
            if fields.len() != 5 {
                return Err(rows.field_count(line, "tetrahedron row", 5, fields.len()));
            }
            let mut tet = [0u32; 4];
            for (slot, text) in tet.iter_mut().zip(&fields[1..]) {
                let tag = rows.uint(line, "node tag", text)?;
                *slot = *tags.get(&tag).ok_or(ReadError::IndexOutOfRange {
                    kind: FileKind::Msh,
                    line,
                    index: tag,
                    vertex_count,
                })?;
            }
            tets.push(tet);
        }
        sum = sum.saturating_add(count);
    }
    if sum != total {
        return Err(ReadError::CountMismatch {
            kind: FileKind::Msh,
            line: header_line,
            what: "elements",
            expected: total,
            found: sum,
        });
    }
    end_section(rows, "$EndElements")?;
    Ok(tets)
}
