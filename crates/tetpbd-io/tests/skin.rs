//! Barycentric skinning: rest positions reproduce themselves, affine and rigid motions move
//! the skin exactly, points outside extrapolate as documented, bad input gets typed errors.
#![cfg(feature = "mesher")]

use nalgebra::{Matrix3, Rotation3, Vector3};
use tetpbd::generators::{self, CellSplit};
use tetpbd::SoftBodyBuilder;
use tetpbd_io::{shapes, Skin, SkinError, TetrahedralizeBuilder};

/// Tetrahedron vertices, tetrahedra and points to embed.
type Setup = (Vec<Vector3<f32>>, Vec<[u32; 4]>, Vec<Vector3<f32>>);

/// A 2 × 2 × 2 cube of 1 m split into tetrahedra, and points on a lattice inside it and a
/// few outside.
fn cube_and_points() -> Setup {
    let mesh = generators::box_grid(Vector3::repeat(1.0), [2, 2, 2], CellSplit::Six).unwrap();
    let mut points = Vec::new();
    for i in 0..7 {
        for j in 0..7 {
            for k in 0..7 {
                points
                    .push(Vector3::new(i as f32, j as f32, k as f32) / 6.0 - Vector3::repeat(0.5));
            }
        }
    }
    (mesh.vertices, mesh.tets, points)
}

fn max_error(a: &[Vector3<f32>], b: &[Vector3<f32>]) -> f32 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).norm())
        .fold(0.0, f32::max)
}

#[test]
fn points_reproduce_themselves_at_rest() {
    let (v, t, p) = cube_and_points();
    let lo = v.iter().fold(Vector3::repeat(f32::MAX), |m, x| m.inf(x));
    assert!(p
        .iter()
        .all(|x| x.iter().zip(lo.iter()).all(|(a, b)| a >= b)));
    let skin = Skin::embed(&v, &t, &p).unwrap();
    assert_eq!(skin.outside_count(), 0);
    for b in skin.bindings() {
        let sum: f32 = b.weights.iter().sum();
        assert!((sum - 1.0).abs() < 1e-6);
        assert!(b.weights.iter().all(|&w| w > -1e-5), "{:?}", b.weights);
    }
    let mut out = vec![Vector3::zeros(); p.len()];
    skin.deform(&v, &mut out).unwrap();
    assert!(max_error(&out, &p) < 1e-5, "{}", max_error(&out, &p));
}

#[test]
fn affine_and_rigid_motions_move_the_skin_exactly() {
    let (v, t, mut p) = cube_and_points();
    // Two points outside, extrapolated: affine motions move them exactly too.
    p.push(Vector3::new(1.5, 0.1, 0.2));
    p.push(Vector3::new(-0.2, -0.9, 0.3));
    let skin = Skin::embed(&v, &t, &p).unwrap();
    assert_eq!(skin.outside_count(), 2);
    let affine = Matrix3::new(1.2, 0.3, -0.1, 0.0, 0.8, 0.2, 0.1, -0.4, 1.1);
    let rigid = Rotation3::from_euler_angles(0.4, -1.1, 2.0).into_inner();
    let shift = Vector3::new(3.0, -2.0, 0.5);
    let mut out = vec![Vector3::zeros(); p.len()];
    for m in [affine, rigid] {
        let moved: Vec<_> = v.iter().map(|x| m * x + shift).collect();
        let expected: Vec<_> = p.iter().map(|x| m * x + shift).collect();
        skin.deform(&moved, &mut out).unwrap();
        let err = max_error(&out, &expected);
        assert!(err < 2e-5, "{err}");
    }
}

#[test]
fn outside_points_bind_to_the_nearest_tetrahedron() {
    let (v, t, _) = cube_and_points();
    let p = [
        Vector3::new(0.5 + 0.3, 0.0, 0.0),
        Vector3::new(2.0, 2.0, 2.0),
    ];
    let skin = Skin::embed(&v, &t, &p).unwrap();
    let b = skin.bindings();
    assert!((b[0].distance - 0.3).abs() < 1e-5, "{}", b[0].distance);
    // The far corner point is √3 · 1.5 m from the cube's corner (0.5, 0.5, 0.5).
    assert!(
        (b[1].distance - 3f32.sqrt() * 1.5).abs() < 1e-4,
        "{}",
        b[1].distance
    );
    // The bound tetrahedron is a nearest one: no tetrahedron is closer by brute force.
    for (k, x) in p.iter().enumerate() {
        let tet = t[b[k].tet as usize];
        assert!(tet.contains(&b[k].vertices[0]));
        let own = Skin::embed(&v, &[tet], &[*x]).unwrap().bindings()[0].distance;
        let best = t
            .iter()
            .map(|tt| Skin::embed(&v, &[*tt], &[*x]).unwrap().bindings()[0].distance)
            .fold(f32::MAX, f32::min);
        assert!(own <= best + 1e-6, "{own} vs {best}");
    }
    // Unclamped: the weights of the far point extrapolate (some negative), and still sum to 1.
    assert!(b[1].weights.iter().any(|&w| w < 0.0));
    assert!((b[1].weights.iter().sum::<f32>() - 1.0).abs() < 1e-5);
    assert_eq!(skin.max_outside_distance(), b[1].distance);
}

#[test]
fn bad_input_gets_typed_errors() {
    let (v, t, p) = cube_and_points();
    assert_eq!(
        Skin::embed(&v, &[], &p).unwrap_err(),
        SkinError::NoTetrahedra
    );
    let e = Skin::embed(&v, &[[0, 1, 2, 99]], &p).unwrap_err();
    assert_eq!(
        e,
        SkinError::IndexOutOfRange {
            tet: 0,
            index: 99,
            vertex_count: v.len()
        }
    );
    assert_eq!(
        e.to_string(),
        "tetrahedron 0: vertex 99 does not exist (27 vertices)"
    );
    let mut flat = v.clone();
    let [a, b, c, d] = t[3];
    flat[d as usize] = (flat[a as usize] + flat[b as usize] + flat[c as usize]) / 3.0;
    let e = Skin::embed(&flat, &t[3..4], &p).unwrap_err();
    assert!(matches!(e, SkinError::DegenerateTet { tet: 0, .. }), "{e}");
    let mut nan = v.clone();
    nan[t[0][2] as usize].x = f32::NAN;
    let e = Skin::embed(&nan, &t, &p).unwrap_err();
    assert_eq!(
        e,
        SkinError::NonFinite {
            what: "vertex",
            index: t[0][2] as usize
        }
    );
    let mut bad_points = p.clone();
    bad_points[5].z = f32::INFINITY;
    let e = Skin::embed(&v, &t, &bad_points).unwrap_err();
    assert_eq!(
        e,
        SkinError::NonFinite {
            what: "point",
            index: 5
        }
    );

    let skin = Skin::embed(&v, &t, &p).unwrap();
    let mut out = vec![Vector3::zeros(); p.len()];
    let e = skin.deform(&v[1..], &mut out).unwrap_err();
    assert!(
        matches!(
            e,
            SkinError::LengthMismatch {
                what: "positions",
                ..
            }
        ),
        "{e}"
    );
    let e = skin.deform(&v, &mut out[1..]).unwrap_err();
    assert!(
        matches!(e, SkinError::LengthMismatch { what: "output", .. }),
        "{e}"
    );
}

#[test]
fn skin_follows_a_built_body() {
    // The body's own particle positions and (reordered) tetrahedra, moved by a translation.
    let blob = shapes::bunny_blob(3);
    let mesh = TetrahedralizeBuilder::new(0.08)
        .smoothing(2)
        .build(&blob)
        .unwrap();
    let t = Vector3::new(0.0, 1.0, 0.0);
    let body = SoftBodyBuilder::new(mesh)
        .edges(0.0)
        .translation(t)
        .build()
        .unwrap();
    let points: Vec<_> = blob.vertices.iter().map(|p| p + t).collect();
    let skin = Skin::embed(
        body.particles.positions(),
        body.tetrahedra.indices(),
        &points,
    )
    .unwrap();
    assert_eq!(skin.outside_count(), 0);
    let mut out = vec![Vector3::zeros(); points.len()];
    skin.deform(body.particles.positions(), &mut out).unwrap();
    assert!(
        max_error(&out, &points) < 1e-5,
        "{}",
        max_error(&out, &points)
    );
}
