//! Queries follow a body the user deformed: after `update`, rays, projections and
//! containment answer for the stretched shape (the BVHs are refitted, not rebuilt).

mod queries_common;

use hecs::World;
use nalgebra::{Isometry3, Vector3};
use queries_common::{glam, location_point, na, spawn_cube, Rng};
use rapier3d::geometry::Ray;
use tetpbd::Particles;
use tetpbd_rapier::{SoftQueries, SoftQueryFilter};

#[test]
fn stretched_and_moved_cubes_are_hit_where_their_new_faces_are() {
    let mut rng = Rng::new(51);
    for case in 0..20 {
        let h = rng.range(0.1, 1.0);
        let mut world = World::new();
        let cube = spawn_cube(&mut world, h, 1 + case % 3, Isometry3::identity());
        let mut queries = SoftQueries::new();
        queries.update(&world);
        // Several stretches and moves in a row, each from the previous shape, each refitting
        // the same trees.
        for round in 0..4 {
            let stretch = Vector3::new(
                rng.range(0.3, 3.0),
                rng.range(0.3, 3.0),
                rng.range(0.3, 3.0),
            );
            let shift = rng.cube() * 2.0;
            let base: Vec<Vector3<f32>> = {
                let p = world.get::<&Particles>(cube).unwrap();
                p.positions().to_vec()
            };
            let (lo, hi) = base.iter().fold(
                (Vector3::repeat(f32::MAX), Vector3::repeat(f32::MIN)),
                |(lo, hi), x| (lo.inf(x), hi.sup(x)),
            );
            let centre = (lo + hi) / 2.0;
            let new_centre = centre + shift;
            {
                let mut p = world.get::<&mut Particles>(cube).unwrap();
                for x in p.positions_mut() {
                    *x = new_centre + (*x - centre).component_mul(&stretch);
                }
            }
            queries.update(&world);
            let half = (hi - lo).component_mul(&stretch) / 2.0;
            for axis in 0..3 {
                for sign in [-1.0f32, 1.0] {
                    let what = format!("case {case}, round {round}, axis {axis}, side {sign}");
                    let face = Face {
                        axis,
                        sign,
                        centre: new_centre,
                        half,
                    };
                    check_face(&queries, &world, cube, &face, &mut rng, &what);
                }
            }
        }
    }
}

/// A face of an axis-aligned box: its axis, side (±1), the box's centre and half extents, m.
struct Face {
    axis: usize,
    sign: f32,
    centre: Vector3<f32>,
    half: Vector3<f32>,
}

/// A ray at a random point of the face hits it at the analytic distance, and points just
/// inside and outside the face are told apart and projected onto it.
fn check_face(
    queries: &SoftQueries,
    world: &World,
    cube: hecs::Entity,
    face: &Face,
    rng: &mut Rng,
    what: &str,
) {
    let f = SoftQueryFilter::new();
    let (axis, half) = (face.axis, face.half);
    let mut n = Vector3::zeros();
    n[axis] = face.sign;
    let mut target = face.centre + n.component_mul(&half);
    for k in (0..3).filter(|&k| k != axis) {
        target[k] += rng.range(-0.9, 0.9) * half[k];
    }
    let gap = rng.range(0.1, 2.0);
    let ray = Ray::new(glam(&(target + n * gap)), glam(&-n));
    let hit = queries
        .cast_ray(&ray, f32::MAX, true, f)
        .unwrap()
        .expect(what);
    let tol = 2e-4 * (1.0 + half.norm() + face.centre.norm() + gap);
    assert!(
        (hit.time_of_impact - gap).abs() < tol,
        "{what}: {} vs {gap}",
        hit.time_of_impact
    );
    assert!((na(hit.normal) - n).norm() < 1e-4, "{what}");
    assert!(
        (location_point(world, cube, &hit.location) - target).norm() < tol,
        "{what}"
    );
    let inside = target - n * (0.01 * half[axis]);
    let outside = target + n * (0.01 * half[axis]);
    assert!(
        queries.contains_point(glam(&inside), f).unwrap().is_some(),
        "{what}: inside"
    );
    assert!(
        queries.contains_point(glam(&outside), f).unwrap().is_none(),
        "{what}: outside"
    );
    let p = queries
        .project_point(glam(&outside), f32::MAX, f)
        .unwrap()
        .expect(what);
    assert!((na(p.point) - target).norm() < tol, "{what}: projection");
}
