//! Seeded fuzzing of the surface path (OBJ text through `tobj`, the array checks, welding,
//! the closed-surface checks and, for surfaces that pass, tetrahedralization with a small
//! lattice limit): 20,000 inputs, half random bytes and half random mutations of a valid
//! closed OBJ. Every input must give `Ok` or `Err` without panicking, and every `Ok` must be
//! consistent (finite coordinates, indices in range, tetrahedra the builder accepts).
#![cfg(feature = "mesher")]

mod common;

use common::Rng;
use std::panic::{catch_unwind, AssertUnwindSafe};

use tetpbd::SoftBodyBuilder;
use tetpbd_io::{SurfaceMesh, TetrahedralizeBuilder};

/// A closed, outward-wound tetrahedron, written with a quad-free mix of OBJ features.
const TET_OBJ: &str = "# tet\no tet\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvn 0 0 1\nvt 0 0\n\
f 1 3 2\nf 1//1 2//1 4//1\nf 1/1 4/1 3/1\nf -3 -2 -1\n";

/// Inputs tried.
const INPUTS: usize = 20_000;

/// Bytes OBJ files are made of.
const ALPHABET: &[u8] = b"0123456789 0 1 2 3\n\n\n-+.eE#/\t\rvfntolgsmtllib usemtl";

/// Tokens that hit edge cases when inserted.
const TOKENS: &[&str] = &[
    "0",
    "1",
    "4",
    "-1",
    "-5",
    "9",
    "1e999",
    "nan",
    "inf",
    "4294967296",
    "\nf 1 2 3\n",
    "\nf 1 2 3 4\n",
    "\nv 0 0 0\n",
    "\nv 1 1 1\n",
    "//",
    "/",
    "\no x\n",
    "\nmtllib a.mtl\n",
    "\nusemtl m\n",
    "\nl 1 2\n",
    "\np 1\n",
    "\\\n",
];

fn mutate(rng: &mut Rng, base: &str) -> Vec<u8> {
    let mut bytes = base.as_bytes().to_vec();
    for _ in 0..1 + rng.below(4) {
        let at = rng.below(bytes.len() + 1);
        match rng.below(3) {
            0 => {
                let t = TOKENS[rng.below(TOKENS.len())].as_bytes();
                bytes.splice(at..at, t.iter().copied());
            }
            1 => {
                let end = (at + rng.below(6)).min(bytes.len());
                bytes.drain(at..end);
            }
            _ => {
                if at < bytes.len() {
                    bytes[at] = ALPHABET[rng.below(ALPHABET.len())];
                }
            }
        }
    }
    bytes
}

fn check(text: &str) {
    let Ok(surface) = SurfaceMesh::from_obj_str(text) else {
        return;
    };
    let n = surface.vertices.len();
    assert!(surface
        .vertices
        .iter()
        .all(|v| v.iter().all(|c| c.is_finite())));
    assert!(surface
        .triangles
        .iter()
        .flatten()
        .all(|&i| (i as usize) < n));
    let Ok(closed) = surface.closed() else {
        return;
    };
    assert!(closed.enclosed_volume() > 0.0);
    let (lo, hi) = closed
        .vertices
        .iter()
        .fold((closed.vertices[0], closed.vertices[0]), |(l, h), v| {
            (l.inf(v), h.sup(v))
        });
    let cell = (hi - lo).max() / 3.0;
    if let Ok(mesh) = TetrahedralizeBuilder::new(cell)
        .max_lattice_points(5_000)
        .build(&closed)
    {
        SoftBodyBuilder::new(mesh)
            .build()
            .expect("tetrahedra the builder accepts");
    }
}

#[test]
fn obj_surfaces_never_panic() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let mut parsed = 0;
    let mut closed = 0;
    for k in 0..INPUTS {
        let bytes = if k % 2 == 0 {
            (0..rng.below(120))
                .map(|_| ALPHABET[rng.below(ALPHABET.len())])
                .collect()
        } else {
            mutate(&mut rng, TET_OBJ)
        };
        let text = String::from_utf8_lossy(&bytes).into_owned();
        let result = catch_unwind(AssertUnwindSafe(|| check(&text)));
        assert!(result.is_ok(), "input {k} panicked: {text:?}");
        if let Ok(s) = SurfaceMesh::from_obj_str(&text) {
            parsed += 1;
            closed += usize::from(s.closed().is_ok());
        }
    }
    println!("{INPUTS} inputs: {parsed} parsed, {closed} closed");
    // The mutations keep many inputs valid, so the deeper checks are exercised.
    assert!(closed > INPUTS / 20, "only {closed} closed surfaces");
}
