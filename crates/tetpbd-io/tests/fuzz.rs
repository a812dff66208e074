//! Seeded fuzzing of the parsers: 20,000 inputs per target (`.node`, `.ele`, text `.msh`,
//! binary `.msh`), 80,000 in all, half random bytes and half random mutations of valid files
//! (for text `.msh`, alternately a format 4.1 and a format 2.2 file; for binary `.msh`, the
//! random half starts with a valid binary header). Every input
//! must give `Ok` or `Err` without panicking, and every `Ok` mesh must be consistent
//! (finite coordinates, indices in range).

mod common;

use common::Rng;
use std::panic::{catch_unwind, AssertUnwindSafe};

use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::nalgebra::Vector3;
use tetpbd::TetMesh;
use tetpbd_io::{
    read_msh_bytes, read_msh_str, read_tetgen_str, write_msh, write_tetgen, ReadError,
};

/// A valid format 2.2 file: two tetrahedra and a triangle.
const V22: &str = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n5\n1 0 0 0\n2 1 0 0\n3 0 1 0\n\
4 0 0 1\n5 1 1 1\n$EndNodes\n$Elements\n3\n1 2 2 0 1 1 2 3\n2 4 2 0 1 1 2 3 4\n\
3 4 2 0 1 2 3 4 5\n$EndElements\n";

/// Inputs tried per target.
const INPUTS: usize = 20_000;

/// Bytes the formats are made of, so random inputs get past the first check often.
const ALPHABET: &[u8] = b"0123456789 0 1 2 3 4\n\n\n-+.eE#$\t\rMeshFormatNodesElementsEnd";

/// Tokens that hit edge cases when inserted.
const TOKENS: &[&str] = &[
    "0",
    "1",
    "4",
    "10",
    "-1",
    "4.1",
    "2.2",
    "1e999",
    "nan",
    "inf",
    "18446744073709551616",
    "4294967296",
    "#",
    "$Nodes",
    "$EndNodes",
    "$Elements",
    "$EndElements",
    "$MeshFormat",
    "$EndMeshFormat",
    "\n",
    " ",
    "é",
    "\u{0}",
];

/// A valid binary 4.1 file with one tetrahedron; its first 40 bytes are the format header.
fn binary_seed() -> Vec<u8> {
    let mut b = b"$MeshFormat\n4.1 1 8\n".to_vec();
    b.extend_from_slice(&1i32.to_le_bytes());
    b.extend_from_slice(b"\n$EndMeshFormat\n$Nodes\n");
    let sizes = |b: &mut Vec<u8>, v: &[u64]| v.iter().for_each(|x| b.extend(x.to_le_bytes()));
    let ints = |b: &mut Vec<u8>, v: &[i32]| v.iter().for_each(|x| b.extend(x.to_le_bytes()));
    sizes(&mut b, &[1, 4, 1, 4]);
    ints(&mut b, &[3, 1, 0]);
    sizes(&mut b, &[4, 1, 2, 3, 4]);
    for c in [
        0.0f64, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0,
    ] {
        b.extend(c.to_le_bytes());
    }
    b.extend_from_slice(b"\n$EndNodes\n$Elements\n");
    sizes(&mut b, &[1, 1, 1, 1]);
    ints(&mut b, &[3, 1, 4]);
    sizes(&mut b, &[1, 1, 1, 2, 3, 4]);
    b.extend_from_slice(b"\n$EndElements\n");
    b
}

fn random_bytes(rng: &mut Rng) -> String {
    String::from_utf8_lossy(&random_raw(rng)).into_owned()
}

fn random_raw(rng: &mut Rng) -> Vec<u8> {
    let len = rng.below(300);
    let bytes: Vec<u8> = (0..len)
        .map(|_| {
            if rng.below(8) == 0 {
                rng.next() as u8
            } else {
                ALPHABET[rng.below(ALPHABET.len())]
            }
        })
        .collect();
    bytes
}

fn mutate(rng: &mut Rng, valid: &str) -> String {
    String::from_utf8_lossy(&mutate_raw(rng, valid.as_bytes())).into_owned()
}

fn mutate_raw(rng: &mut Rng, valid: &[u8]) -> Vec<u8> {
    let mut bytes = valid.to_vec();
    for _ in 0..1 + rng.below(4) {
        let at = rng.below(bytes.len() + 1);
        match rng.below(6) {
            0 => {
                let end = (at + 1 + rng.below(8)).min(bytes.len());
                bytes.drain(at.min(end)..end);
            }
            1 => {
                let token = TOKENS[rng.below(TOKENS.len())].as_bytes();
                bytes.splice(at..at, token.iter().copied());
            }
            2 if at < bytes.len() => bytes[at] = ALPHABET[rng.below(ALPHABET.len())],
            3 => bytes.truncate(at),
            4 => {
                let lines: Vec<&[u8]> = bytes.split(|&b| b == b'\n').collect();
                let pick = lines[rng.below(lines.len())].to_vec();
                let mut line = pick;
                line.push(b'\n');
                bytes.splice(at..at, line);
            }
            _ if at < bytes.len() => bytes[at] = rng.next() as u8,
            _ => {}
        }
    }
    bytes
}

/// A successful read must be a consistent mesh.
fn check(result: Result<TetMesh, ReadError>, ok: &mut usize) {
    if let Ok(mesh) = result {
        *ok += 1;
        assert!(mesh
            .vertices
            .iter()
            .all(|v| v.iter().all(|c| c.is_finite())));
        let n = mesh.vertices.len();
        assert!(mesh.tets.iter().flatten().all(|&i| (i as usize) < n));
    } else if let Err(e) = result {
        let text = e.to_string();
        assert!(text.contains("line ") || text.contains("byte "), "{text}");
    }
}

#[test]
fn parsers_never_panic() {
    let grid = box_grid(Vector3::new(1.0, 2.0, 0.5), [2, 1, 2], CellSplit::Five).unwrap();
    let (node, ele) = write_tetgen(&grid);
    let node = format!("# header\n{}", node.replacen("\n", " # c\n", 2));
    let msh = write_msh(&grid);
    assert_eq!(
        read_msh_str(V22).unwrap().tets,
        vec![[0, 1, 2, 3], [1, 2, 3, 4]]
    );
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let mut tried = 0;
    let binary = binary_seed();
    assert_eq!(read_msh_bytes(&binary).unwrap().tets, vec![[0, 1, 2, 3]]);
    let mut ok = [0usize; 4];
    for i in 0..INPUTS {
        let input = |rng: &mut Rng, valid: &str| {
            if i % 2 == 0 {
                random_bytes(rng)
            } else {
                mutate(rng, valid)
            }
        };
        let inputs = [
            input(&mut rng, &node),
            input(&mut rng, &ele),
            input(&mut rng, if i % 4 == 3 { V22 } else { &msh }),
        ];
        let raw = if i % 2 == 0 {
            let mut r = binary[..40].to_vec();
            r.extend(random_raw(&mut rng));
            r
        } else {
            mutate_raw(&mut rng, &binary)
        };
        let outcome = catch_unwind(AssertUnwindSafe(|| {
            check(read_tetgen_str(&inputs[0], &ele), &mut ok[0]);
            check(read_tetgen_str(&node, &inputs[1]), &mut ok[1]);
            check(read_msh_str(&inputs[2]), &mut ok[2]);
            check(read_msh_bytes(&raw), &mut ok[3]);
        }));
        assert!(outcome.is_ok(), "input {i} panicked: {inputs:?} {raw:?}");
        tried += 4;
    }
    println!(
        "fuzz: {tried} inputs ({INPUTS} per target), Ok per target \
         (node, ele, text msh, binary msh): {ok:?}"
    );
    assert_eq!(tried, 4 * INPUTS);
    // The mutations must leave some inputs readable, or they test only the first check.
    assert!(ok.iter().all(|&k| k > 100), "{ok:?}");
}
