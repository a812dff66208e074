//! Gmsh `.msh` 4.1 ASCII reader: round trips, a hand-written file in Gmsh's layout, and
//! every error it reports.

#[macro_use]
mod common;

use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::nalgebra::Vector3;
use tetpbd_io::{read_msh_file, read_msh_str, write_msh, FileKind, ReadError};

#[test]
fn box_grid_round_trips_exactly() {
    for split in [CellSplit::Five, CellSplit::Six] {
        let mesh = box_grid(Vector3::new(0.9, 1.1, 0.4), [4, 3, 2], split).unwrap();
        let back = read_msh_str(&write_msh(&mesh)).unwrap();
        assert_eq!(back, mesh, "{split:?}");
    }
}

#[test]
fn file_round_trip_and_io_error() {
    let mesh = box_grid(Vector3::new(1.0, 1.0, 1.0), [2, 2, 2], CellSplit::Five).unwrap();
    let path = std::env::temp_dir().join(format!("tetpbd-io-{}.msh", std::process::id()));
    std::fs::write(&path, write_msh(&mesh)).unwrap();
    assert_eq!(read_msh_file(&path).unwrap(), mesh);
    std::fs::remove_file(&path).unwrap();
    let err = read_msh_file(&path).unwrap_err();
    assert_error!(err, ReadError::Io, kind: FileKind::Msh);
}

/// Two node blocks (one parametric, tags not contiguous), a triangle block that is skipped,
/// a tetrahedron block, and sections the reader skips.
const GMSH_LIKE: &str = "$MeshFormat
4.1 0 8
$EndMeshFormat
$PhysicalNames
1
3 1 \"body\"
$EndPhysicalNames
$Entities
0 0 1 1
1 0 0 0 1 0 0 0
1 0 0 0 1 1 1 1 1 0
$EndEntities
$Nodes
2 5 10 50
2 1 1 2
10
20
0 0 0 0.5 0.5
1 0 0 1 0
3 1 0 3
30
40
50
0 1 0
0 0 1
1 1 1
$EndNodes
$Elements
2 3 1 3
2 1 2 1
7 10 20 30
3 1 4 2
1 10 20 30 40
2 20 30 40 50
$EndElements
$NodeData
1
\"t\"
$EndNodeData
";

#[test]
fn reads_gmsh_layout_and_skips_other_elements() {
    let mesh = read_msh_str(GMSH_LIKE).unwrap();
    assert_eq!(mesh.vertices.len(), 5);
    assert_eq!(mesh.vertices[4], Vector3::new(1.0, 1.0, 1.0));
    assert_eq!(mesh.tets, vec![[0, 1, 2, 3], [1, 2, 3, 4]]);
    let crlf = GMSH_LIKE.replace('\n', "\r\n");
    assert_eq!(read_msh_str(&crlf).unwrap(), mesh);
}

/// Replaces the first occurrence of `from` in [`GMSH_LIKE`], reads it, expects an error on
/// `line` and returns it.
fn error(from: &str, to: &str, line: usize) -> ReadError {
    assert!(GMSH_LIKE.contains(from), "{from}");
    let err = read_msh_str(&GMSH_LIKE.replacen(from, to, 1)).unwrap_err();
    assert_eq!(err.line(), Some(line), "{err}");
    assert_eq!(err.kind(), FileKind::Msh);
    assert!(
        err.to_string().starts_with(&format!(".msh line {line}:")),
        "{err}"
    );
    err
}

#[test]
fn bad_numbers() {
    let err = error("1 0 0 1 0", "1 0 0 1e0x 0", 19);
    assert_error!(err, ReadError::BadNumber, field: "parametric coordinate");
    let err = error("0 0 1\n", "0 0 1y\n", 25);
    assert_error!(err, ReadError::BadNumber, field: "z coordinate");
    let err = error("2 20 30 40 50", "2 20 30 -40 50", 34);
    assert_error!(err, ReadError::BadNumber, field: "node tag");
    let err = error("4.1 0 8", "4.1 zero 8", 2);
    assert_error!(err, ReadError::BadNumber, field: "file type");
}

#[test]
fn wrong_field_counts() {
    let err = error("0 0 0 0.5 0.5", "0 0 0 0.5", 18);
    assert_error!(err, ReadError::FieldCount, expected: 5, found: 4);
    let err = error("1 10 20 30 40", "1 10 20 30", 33);
    assert_error!(err, ReadError::FieldCount, expected: 5, found: 4);
    let err = error("2 5 10 50", "2 5 10", 14);
    assert_error!(err, ReadError::FieldCount, expected: 4, found: 3);
}

#[test]
fn unsupported_versions_binary_and_stray_text() {
    let err = error("4.1 0 8", "3.0 0 8", 2);
    assert!(
        err.to_string().contains("version `3.0` (4.1 or 2.2)"),
        "{err}"
    );
    let err = error("4.1 0 8", "4.1 1 8", 2);
    assert!(err.to_string().contains("binary"), "{err}");
    let err = error("$PhysicalNames", "stray text\n$PhysicalNames", 4);
    assert_error!(err, ReadError::Unsupported);
    let err = error("$NodeData", "$Nodes\n$EndNodes\n$NodeData", 36);
    assert!(err.to_string().contains("second $Nodes"), "{err}");
    let err = error(
        "$PhysicalNames",
        "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames",
        4,
    );
    assert!(err.to_string().contains("second $MeshFormat"), "{err}");
}

#[test]
fn unknown_and_duplicate_node_tags() {
    let err = error("2 20 30 40 50", "2 20 30 40 60", 34);
    assert_error!(err, ReadError::IndexOutOfRange, index: 60, vertex_count: 5);
    let err = error("40\n", "20\n", 22);
    assert_error!(err, ReadError::DuplicateTag, tag: 20);
}

#[test]
fn fewer_rows_than_the_header_says() {
    let err = error("3 1 4 2", "3 1 4 3", 35);
    assert_error!(err, ReadError::MissingRows, expected: 3, found: 2);
    assert!(
        err.to_string().contains("after 2 of 3 element rows"),
        "{err}"
    );
    let truncated = &GMSH_LIKE[..GMSH_LIKE.find("1 1 1\n$EndNodes").unwrap()];
    let err = read_msh_str(truncated).unwrap_err();
    assert_error!(err, ReadError::MissingRows, line: 25, expected: 3, found: 2);
}

#[test]
fn more_rows_than_the_header_says() {
    let err = error("1 1 1\n", "1 1 1\n2 2 2\n", 27);
    assert_error!(err, ReadError::ExtraRows);
}

#[test]
fn header_total_disagrees_with_blocks() {
    let err = error("2 5 10 50", "2 6 10 50", 14);
    assert_error!(err, ReadError::CountMismatch, what: "nodes", expected: 6, found: 5);
    let err = error("2 3 1 3", "2 4 1 3", 29);
    assert_error!(err, ReadError::CountMismatch, what: "elements");
}

#[test]
fn missing_sections() {
    let err = read_msh_str("").unwrap_err();
    assert_error!(err, ReadError::MissingSection, section: "$MeshFormat", line: 0);
    let no_elements = &GMSH_LIKE[..GMSH_LIKE.find("$Elements").unwrap()];
    let err = read_msh_str(no_elements).unwrap_err();
    assert_error!(err, ReadError::MissingSection, section: "$Elements", line: 27);
    let err = error("$EndNodes", "$EndNode", 27);
    assert_error!(err, ReadError::MissingSection, section: "$EndNodes");
    let err = error("$EndNodeData\n", "", 38);
    assert_error!(err, ReadError::MissingSection);
    let err = error("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n", "", 10);
    assert_error!(err, ReadError::MissingSection, section: "$MeshFormat");
}
