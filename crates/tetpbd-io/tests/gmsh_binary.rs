//! Gmsh `.msh` 4.1 binary: round trips in both byte orders and errors with byte offsets.

use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::nalgebra::Vector3;
use tetpbd::TetMesh;
use tetpbd_io::{read_msh_bytes, read_msh_file, read_msh_str, ReadError};

/// Appends numbers in the chosen byte order.
struct Out {
    bytes: Vec<u8>,
    big: bool,
}

impl Out {
    fn raw<const N: usize>(&mut self, mut b: [u8; N]) {
        if self.big {
            b.reverse();
        }
        self.bytes.extend_from_slice(&b);
    }
    fn int(&mut self, v: i32) {
        self.raw(v.to_le_bytes());
    }
    fn size(&mut self, v: u64) {
        self.raw(v.to_le_bytes());
    }
    fn text(&mut self, s: &str) {
        self.bytes.extend_from_slice(s.as_bytes());
    }
}

/// `mesh` as a binary file: a skipped `$Entities` section, one parametric node block
/// (tags `i + 1`), a triangle block and a tetrahedron block.
fn write_binary(mesh: &TetMesh, big: bool) -> Vec<u8> {
    let mut o = Out {
        bytes: Vec::new(),
        big,
    };
    o.text("$MeshFormat\n4.1 1 8\n");
    o.int(1);
    o.text("\n$EndMeshFormat\n$Entities\n");
    o.size(0);
    o.int(0x0a24_0a24);
    o.text("\n$EndEntities\n$Nodes\n");
    let n = mesh.vertices.len() as u64;
    for v in [1, n, 1, n] {
        o.size(v);
    }
    o.int(3);
    o.int(1);
    o.int(1);
    o.size(n);
    for i in 1..=n {
        o.size(i);
    }
    for v in &mesh.vertices {
        for c in [v.x, v.y, v.z, 0.5, 0.25, 0.125] {
            o.raw(f64::from(c).to_le_bytes());
        }
    }
    o.text("\n$EndNodes\n$Elements\n");
    let m = mesh.tets.len() as u64;
    for v in [2, m + 1, 1, m + 1] {
        o.size(v);
    }
    for (ty, count) in [(2, 1), (4, m)] {
        o.int(3);
        o.int(1);
        o.int(ty);
        o.size(count);
        if ty == 2 {
            for v in [m + 1, 1, 2, 3] {
                o.size(v);
            }
            continue;
        }
        for (i, t) in mesh.tets.iter().enumerate() {
            o.size(i as u64 + 1);
            for k in t {
                o.size(u64::from(*k) + 1);
            }
        }
    }
    o.text("\n$EndElements\n");
    o.bytes
}

fn grid() -> TetMesh {
    box_grid(Vector3::new(0.3, 0.6, 0.9), [2, 3, 2], CellSplit::Six).unwrap()
}

#[test]
fn round_trips_in_both_byte_orders_and_from_a_file() {
    let mesh = grid();
    for big in [false, true] {
        assert_eq!(
            read_msh_bytes(&write_binary(&mesh, big)).unwrap(),
            mesh,
            "big {big}"
        );
    }
    let path = std::env::temp_dir().join(format!("tetpbd-io-bin-{}.msh", std::process::id()));
    std::fs::write(&path, write_binary(&mesh, false)).unwrap();
    assert_eq!(read_msh_file(&path).unwrap(), mesh);
    std::fs::remove_file(&path).unwrap();
}

#[test]
fn text_reader_names_binary_as_unsupported() {
    let bytes = write_binary(&grid(), false);
    let head = String::from_utf8_lossy(&bytes[..20]).into_owned();
    let err = read_msh_str(&head).unwrap_err();
    assert!(
        matches!(err, ReadError::Unsupported { line: 2, .. }),
        "{err}"
    );
}

/// Expects a [`ReadError::Binary`] at `offset` whose message contains `what`.
fn binary_error(bytes: &[u8], offset: usize, what: &str) {
    let err = read_msh_bytes(bytes).unwrap_err();
    assert!(
        matches!(err, ReadError::Binary { offset: o, .. } if o == offset),
        "{err}"
    );
    assert_eq!(err.line(), None);
    let text = err.to_string();
    assert!(
        text.starts_with(&format!(".msh (binary) byte {offset}: ")),
        "{text}"
    );
    assert!(text.contains(what), "{text}");
}

#[test]
fn errors_give_byte_offsets() {
    let mesh = grid();
    let good = write_binary(&mesh, false);
    let nodes = good.windows(7).position(|w| w == b"$Nodes\n").unwrap() + 7;
    let tet_block = good.len() - "\n$EndElements\n".len() - mesh.tets.len() * 40 - 20;
    // Truncated inside the node coordinates.
    binary_error(&good[..nodes + 100], nodes + 32 + 20, "input ends before");
    // A 4-byte size_t.
    let mut bad = good.clone();
    bad[18] = b'4';
    binary_error(&bad, 12, "expected `4.1 1 8`");
    let spaced = [&b"$MeshFormat\n4.1  1 8\n"[..], &good[20..]].concat();
    assert_eq!(read_msh_bytes(&spaced).unwrap(), mesh);
    // Byte-order marker not 1.
    let mut bad = good.clone();
    bad[20] = 2;
    binary_error(&bad, 20, "byte-order marker");
    // A node tag defined twice (second tag = first).
    let mut bad = good.clone();
    bad[nodes + 60..nodes + 68].copy_from_slice(&1u64.to_le_bytes());
    binary_error(&bad, nodes + 60, "node tag 1 defined twice");
    // A NaN coordinate.
    let coords = nodes + 52 + 8 * mesh.vertices.len();
    let mut bad = good.clone();
    bad[coords..coords + 8].copy_from_slice(&f64::NAN.to_le_bytes());
    binary_error(&bad, coords, "x coordinate is not finite");
    // An unknown element type in the tetrahedron block header.
    let mut bad = good.clone();
    bad[tet_block + 8..tet_block + 12].copy_from_slice(&77i32.to_le_bytes());
    binary_error(&bad, tet_block + 8, "unknown element type 77");
    // A node tag that does not exist in the first tetrahedron.
    let mut bad = good.clone();
    let first = tet_block + 20 + 8;
    bad[first..first + 8].copy_from_slice(&999u64.to_le_bytes());
    binary_error(&bad, first + 8, "node tag 999 does not exist (36 nodes)");
    // Section not closed.
    let cut = good.len() - "$EndElements\n".len();
    binary_error(&good[..cut], cut - 1, "expected `$EndElements`");
}
