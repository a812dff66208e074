//! Gmsh `.msh` 2.2 ASCII: round trip of a generated grid, Gmsh's element layout, errors.

#[macro_use]
mod common;

use std::fmt::Write as _;

use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::nalgebra::Vector3;
use tetpbd::TetMesh;
use tetpbd_io::{read_msh_str, ReadError};

/// `mesh` in format 2.2 with node tags `10·(i+1)`, a triangle element first, and two
/// tags (physical, elementary) on every element.
fn write_v22(mesh: &TetMesh) -> String {
    let mut s = String::from("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n");
    let _ = writeln!(s, "{}", mesh.vertices.len());
    for (i, v) in mesh.vertices.iter().enumerate() {
        let _ = writeln!(s, "{} {} {} {}", 10 * (i + 1), v.x, v.y, v.z);
    }
    let _ = writeln!(s, "$EndNodes\n$Elements\n{}", mesh.tets.len() + 1);
    let _ = writeln!(s, "1 2 2 7 3 10 20 30");
    for (i, t) in mesh.tets.iter().enumerate() {
        let [a, b, c, d] = t.map(|k| 10 * (k + 1));
        let _ = writeln!(s, "{} 4 2 1 1 {a} {b} {c} {d}", i + 2);
    }
    s.push_str("$EndElements\n");
    s
}

fn grid() -> TetMesh {
    box_grid(Vector3::new(1.0, 0.5, 0.25), [3, 2, 2], CellSplit::Five).unwrap()
}

#[test]
fn box_grid_round_trips_exactly() {
    assert_eq!(read_msh_str(&write_v22(&grid())).unwrap(), grid());
}

/// The grid file with the first `from` replaced by `to`; expects an error on `line`.
fn error(from: &str, to: &str, line: usize) -> ReadError {
    let text = write_v22(&grid());
    assert!(text.contains(from), "{from}");
    let err = read_msh_str(&text.replacen(from, to, 1)).unwrap_err();
    assert_eq!(err.line(), Some(line), "{err}");
    assert!(
        err.to_string().starts_with(&format!(".msh line {line}:")),
        "{err}"
    );
    err
}

#[test]
fn errors_name_the_line() {
    // Line 5 is the node count (36 nodes), 6..=41 the nodes, 42 $EndNodes, 43 $Elements,
    // 44 the element count, 45 the triangle, 46..=105 the 60 tetrahedra, 106 $EndElements.
    let err = error("\n36\n", "\n37\n", 42);
    assert_error!(err, ReadError::MissingRows, expected: 37, found: 36);
    let err = error("\n20 ", "\n20 q", 7);
    assert_error!(err, ReadError::BadNumber, field: "x coordinate");
    let err = error("\n20 ", "\n10 ", 7);
    assert_error!(err, ReadError::DuplicateTag, tag: 10);
    let err = error("\n30 ", "\n30 1 ", 8);
    assert_error!(err, ReadError::FieldCount, expected: 4, found: 5);
    let err = error("2 4 2 1 1 ", "2 4 3 1 1 ", 46);
    assert_error!(err, ReadError::FieldCount, expected: 10, found: 9);
    let err = error("2 4 2 1 1 10 ", "2 4 2 1 1 15 ", 46);
    assert_error!(err, ReadError::IndexOutOfRange, index: 15, vertex_count: 36);
    let err = error("1 2 2 7 3", "1 2 x 7 3", 45);
    assert_error!(err, ReadError::BadNumber, field: "number of tags");
    let err = error("$EndElements", "$EndElement", 106);
    assert_error!(err, ReadError::MissingSection, section: "$EndElements");
}
