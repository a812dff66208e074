//! A skin follows a cut: every point embedded in a cube, re-bound to the piece holding its
//! tetrahedron, moves with that piece, and every point on the cube's surface stays on the
//! surface of its piece.

use nalgebra::Vector3;
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::hecs::World;
use tetpbd::{cut, Blade, Particles, SoftBodyBuilder, Surface, Tetrahedra};
use tetpbd_io::{Skin, SkinError};

/// Whether `p` lies on triangle `t` (within 1e-5 m of its plane, inside its edges).
fn on_triangle(p: Vector3<f32>, t: [Vector3<f32>; 3]) -> bool {
    let n = (t[1] - t[0]).cross(&(t[2] - t[0]));
    let area2 = n.norm();
    if area2 <= 0.0 || ((p - t[0]).dot(&n) / area2).abs() > 1e-5 {
        return false;
    }
    (0..3).all(|i| {
        let (a, b) = (t[i], t[(i + 1) % 3]);
        (b - a).cross(&(p - a)).dot(&n) / area2 >= -1e-5
    })
}

/// Points on the faces of the unit cube centred at the origin, and a few inside.
fn points() -> (Vec<Vector3<f32>>, usize) {
    let mut on_surface = Vec::new();
    let steps = [-0.45, -0.3, -0.1, 0.05, 0.2, 0.4];
    for axis in 0..3 {
        for side in [-0.5, 0.5] {
            for &u in &steps {
                for &v in &steps {
                    let mut p = Vector3::zeros();
                    p[axis] = side;
                    p[(axis + 1) % 3] = u;
                    p[(axis + 2) % 3] = v;
                    on_surface.push(p);
                }
            }
        }
    }
    let n = on_surface.len();
    on_surface.extend([Vector3::new(0.1, 0.2, -0.3), Vector3::new(-0.2, -0.1, 0.3)]);
    (on_surface, n)
}

#[test]
fn a_skin_follows_the_pieces_of_a_cut_cube() {
    for (normal, offset) in [(Vector3::x(), 0.0), (Vector3::new(1.0, 1.0, 0.3), 0.1)] {
        let mut world = World::new();
        let mesh = box_grid(Vector3::repeat(1.0), [2, 2, 2], CellSplit::Six).unwrap();
        let body = SoftBodyBuilder::new(mesh)
            .edges(1e-6)
            .volume(1e-8)
            .build()
            .unwrap();
        let (pts, on_surface) = points();
        let skin =
            Skin::embed(body.particles.positions(), body.tetrahedra.indices(), &pts).unwrap();
        let e = body.spawn(&mut world);
        let blade = Blade::Plane {
            point: normal.normalize() * offset,
            normal,
        };
        let event = cut(&mut world, e, &blade)
            .unwrap()
            .expect("the blade crosses the cube");
        assert!(event.pieces.len() >= 2, "{} pieces", event.pieces.len());
        let tets: Vec<Vec<[u32; 4]>> = event
            .pieces
            .iter()
            .map(|p| {
                world
                    .get::<&Tetrahedra>(p.entity)
                    .unwrap()
                    .indices()
                    .to_vec()
            })
            .collect();
        let refs: Vec<&[[u32; 4]]> = tets.iter().map(|t| t.as_slice()).collect();
        let pieces = skin.follow(&event, &refs).unwrap();
        assert_eq!(pieces.len(), event.pieces.len());
        let total: usize = pieces.iter().map(|p| p.points.len()).sum();
        assert_eq!(total, pts.len(), "every point lands in one piece");
        for (k, (piece, ps)) in event.pieces.iter().zip(&pieces).enumerate() {
            // Move each piece away from the others.
            let shift = Vector3::new(0.0, 3.0 * k as f32, 0.0);
            let mut particles = world.get::<&mut Particles>(piece.entity).unwrap();
            for i in 0..particles.len() {
                let x = particles.positions()[i];
                particles.set_position(i, x + shift).unwrap();
            }
            let x = particles.positions();
            let mut out = vec![Vector3::zeros(); ps.points.len()];
            ps.skin.deform(x, &mut out).unwrap();
            let surface = world.get::<&Surface>(piece.entity).unwrap();
            for (&i, o) in ps.points.iter().zip(&out) {
                let expected = pts[i as usize] + shift;
                assert!((o - expected).norm() < 1e-5, "point {i}: {o} vs {expected}");
                if (i as usize) < on_surface {
                    let on = surface
                        .triangles()
                        .iter()
                        .any(|t| on_triangle(*o, t.map(|j| x[j as usize])));
                    assert!(on, "point {i} is not on the surface of piece {k}");
                }
            }
        }
        assert!(matches!(
            skin.follow(&event, &refs[..1]),
            Err(SkinError::LengthMismatch { .. })
        ));
    }
}
