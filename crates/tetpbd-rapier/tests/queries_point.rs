//! Point projection and containment against soft bodies, checked against the analytic
//! answers of placed cubes and balls.

mod queries_common;

use hecs::World;
use nalgebra::{Isometry3, Point3, Vector3};
use queries_common::{box_surface_nearest, glam, location_point, na, spawn_ball, spawn_cube, Rng};
use rapier3d::math::Vector;
use tetpbd::{Particles, Surface};
use tetpbd_rapier::{QueryError, SoftLocation, SoftQueries, SoftQueryFilter};

/// A local point of the region of the box `[-h, h]³` with `outside` coordinates beyond the
/// box (0: inside, 1: face, 2: edge, 3: corner region), `margin` m clear of the region's
/// borders.
fn region_point(rng: &mut Rng, h: f32, outside: usize, margin: f32) -> Vector3<f32> {
    let mut q = Vector3::zeros();
    let first = (rng.unit() * 3.0) as usize % 3;
    for k in 0..3 {
        let axis = (first + k) % 3;
        let sign = if rng.unit() < 0.5 { -1.0 } else { 1.0 };
        q[axis] = if k < outside {
            sign * (h + margin + rng.range(0.0, 2.0 * h))
        } else {
            rng.range(-1.0, 1.0) * (h - margin).max(0.0)
        };
    }
    q
}

#[test]
fn projections_onto_faces_edges_and_corners_of_placed_cubes_are_exact() {
    let mut rng = Rng::new(21);
    for case in 0..40 {
        let h = rng.range(0.05, 2.0);
        let pose = rng.pose(5.0);
        let mut world = World::new();
        let cube = spawn_cube(&mut world, h, 1 + case % 3, pose);
        let mut queries = SoftQueries::new();
        queries.update(&world);
        let filter = SoftQueryFilter::new();
        for outside in 0..4 {
            for _ in 0..5 {
                let q = region_point(&mut rng, h, outside, 0.02 * h);
                let (nearest, dist) = box_surface_nearest(&q, h);
                let x = (pose * Point3::from(q)).coords;
                let what = format!("case {case} (h {h}), region {outside}, local {q:?}");
                let p = queries
                    .project_point(glam(&x), f32::MAX, filter)
                    .unwrap()
                    .unwrap_or_else(|| panic!("{what}: none"));
                let tol = 2e-4 * (1.0 + h + pose.translation.vector.norm() + q.norm());
                assert_eq!(p.entity, cube, "{what}");
                assert_eq!(p.is_inside, outside == 0, "{what}");
                assert!(
                    (p.distance - dist).abs() < tol,
                    "{what}: {} vs {dist}",
                    p.distance
                );
                let expected = (pose * Point3::from(nearest)).coords;
                assert!((na(p.point) - expected).norm() < tol, "{what}: point");
                assert!(
                    (location_point(&world, cube, &p.location) - expected).norm() < tol,
                    "{what}"
                );
                assert!(matches!(p.location, SoftLocation::Surface { .. }), "{what}");
                // Closer than the distance: nothing.
                if dist > 3.0 * tol {
                    let near = queries
                        .project_point(glam(&x), dist - 2.0 * tol, filter)
                        .unwrap();
                    assert!(near.is_none(), "{what}: max_dist");
                }
            }
        }
    }
}

#[test]
fn points_inside_a_placed_cube_are_located_in_a_tet_and_points_outside_are_not() {
    let mut rng = Rng::new(22);
    for case in 0..30 {
        let h = rng.range(0.05, 2.0);
        let pose = rng.pose(5.0);
        let mut world = World::new();
        let cube = spawn_cube(&mut world, h, 1 + case % 4, pose);
        let mut queries = SoftQueries::new();
        queries.update(&world);
        let filter = SoftQueryFilter::new();
        for _ in 0..20 {
            let inner = rng.cube() * (0.99 * h);
            let x = (pose * Point3::from(inner)).coords;
            let found = queries.contains_point(glam(&x), filter).unwrap();
            let v = found.unwrap_or_else(|| panic!("case {case}: {inner:?} not found"));
            assert_eq!(v.entity, cube);
            let SoftLocation::Interior {
                tet, barycentric, ..
            } = v.location
            else {
                panic!("case {case}: not interior");
            };
            assert!(
                barycentric.iter().all(|w| *w >= 0.0),
                "case {case}, tet {tet}"
            );
            assert!((barycentric.iter().sum::<f32>() - 1.0).abs() < 1e-4);
            let back = location_point(&world, cube, &v.location);
            assert!(
                (back - x).norm() < 1e-4 * (1.0 + x.norm()),
                "case {case}: barycentrics"
            );
            // Outside: one coordinate at least 1 % beyond the face.
            let mut outer = rng.cube() * h;
            let axis = (rng.unit() * 3.0) as usize % 3;
            outer[axis] = outer[axis].signum() * h * rng.range(1.01, 2.0);
            let y = (pose * Point3::from(outer)).coords;
            assert!(
                queries.contains_point(glam(&y), filter).unwrap().is_none(),
                "case {case}: {outer:?}"
            );
        }
    }
}

#[test]
fn points_inside_a_ball_are_contained_and_points_beyond_its_radius_are_not() {
    let mut rng = Rng::new(23);
    for case in 0..12 {
        let r = rng.range(0.1, 2.0);
        let cells = 2 + case % 3;
        let c = rng.cube() * 4.0;
        let mut world = World::new();
        let ball = spawn_ball(&mut world, r, cells, c);
        let mut queries = SoftQueries::new();
        queries.update(&world);
        // The polyhedral ball holds the sphere of radius `r_in`: the least distance from
        // the centre to a surface triangle's plane (its vertices lie on the sphere of `r`).
        let r_in = {
            let p = world.get::<&Particles>(ball).unwrap();
            let s = world.get::<&Surface>(ball).unwrap();
            s.triangles()
                .iter()
                .map(|t| {
                    let [a, b, cc] = t.map(|i| p.positions()[i as usize]);
                    let n = (b - a).cross(&(cc - a)).normalize();
                    (a - c).dot(&n)
                })
                .fold(f32::MAX, f32::min)
        };
        assert!(r_in > 0.5 * r, "case {case}: r_in {r_in} of {r}");
        let filter = SoftQueryFilter::new();
        for _ in 0..40 {
            let d = (rng.cube() + Vector3::new(1e-3, 0.0, 0.0)).normalize();
            let inside = c + d * (r_in * rng.range(0.0, 0.99));
            let v = queries.contains_point(glam(&inside), filter).unwrap();
            assert_eq!(v.map(|v| v.entity), Some(ball), "case {case}: {inside:?}");
            let outside = c + d * (r * rng.range(1.01, 3.0));
            assert!(
                queries
                    .contains_point(glam(&outside), filter)
                    .unwrap()
                    .is_none(),
                "case {case}"
            );
            let p = queries
                .project_point(glam(&outside), f32::MAX, filter)
                .unwrap()
                .unwrap();
            assert!(!p.is_inside);
            // The nearest surface point is no nearer than the sphere and no farther than the
            // inscribed one.
            let dist = (outside - c).norm();
            assert!(
                p.distance >= dist - r - 1e-4 && p.distance <= dist - r_in + 1e-4,
                "case {case}"
            );
        }
    }
}

#[test]
fn overlapping_bodies_all_report_a_point_inside_both() {
    let mut world = World::new();
    let a = spawn_cube(&mut world, 0.5, 2, Isometry3::identity());
    let b = spawn_cube(&mut world, 0.5, 2, Isometry3::translation(0.6, 0.0, 0.0));
    let mut queries = SoftQueries::new();
    queries.update(&world);
    let filter = SoftQueryFilter::new();
    let both = queries
        .intersect_point(Vector::new(0.3, 0.1, 0.2), filter)
        .unwrap();
    let mut expected = vec![a, b];
    expected.sort_by_key(|e| e.to_bits());
    assert_eq!(both.iter().map(|v| v.entity).collect::<Vec<_>>(), expected);
    let only_b = queries
        .intersect_point(Vector::new(0.9, 0.1, 0.2), filter)
        .unwrap();
    assert_eq!(only_b.iter().map(|v| v.entity).collect::<Vec<_>>(), vec![b]);
}

#[test]
fn non_finite_points_and_bad_distances_are_rejected_by_name() {
    let mut world = World::new();
    spawn_cube(&mut world, 0.5, 1, Isometry3::identity());
    let mut queries = SoftQueries::new();
    queries.update(&world);
    let f = SoftQueryFilter::new();
    let bad = Vector::new(0.0, f32::NEG_INFINITY, 0.0);
    for err in [
        queries.project_point(bad, 1.0, f).unwrap_err(),
        queries.contains_point(bad, f).unwrap_err(),
    ] {
        assert!(
            matches!(err, QueryError::NonFiniteVector { what: "point", value } if value[1] == f32::NEG_INFINITY),
            "{err}"
        );
    }
    let err = queries
        .project_point(Vector::ZERO, f32::NAN, f)
        .unwrap_err();
    assert!(
        matches!(
            err,
            QueryError::BadScalar {
                what: "max_dist",
                ..
            }
        ),
        "{err}"
    );
}

#[test]
fn a_body_with_non_finite_positions_is_left_out_and_listed() {
    let mut world = World::new();
    let good = spawn_cube(&mut world, 0.5, 2, Isometry3::identity());
    let bad = spawn_cube(&mut world, 0.5, 2, Isometry3::translation(0.0, 2.0, 0.0));
    let mut queries = SoftQueries::new();
    queries.update(&world);
    assert_eq!(queries.len(), 2);
    assert!(queries.skipped().is_empty());
    world.get::<&mut Particles>(bad).unwrap().positions_mut()[3].y = f32::NAN;
    queries.update(&world);
    assert_eq!(queries.skipped(), &[bad]);
    assert_eq!(queries.len(), 1);
    let f = SoftQueryFilter::new();
    // A ray down through both: only the good body answers, nothing panics.
    let ray = rapier3d::geometry::Ray::new(Vector::new(0.0, 5.0, 0.0), -Vector::Y);
    let hits = queries.intersect_ray(&ray, f32::MAX, true, f).unwrap();
    assert!(!hits.is_empty() && hits.iter().all(|h| h.entity == good));
    assert!(queries
        .contains_point(Vector::new(0.0, 2.0, 0.0), f)
        .unwrap()
        .is_none());
    // Repaired, it is back.
    world.get::<&mut Particles>(bad).unwrap().positions_mut()[3].y = 2.0 - 0.5;
    queries.update(&world);
    assert!(queries.skipped().is_empty());
    let v = queries
        .contains_point(Vector::new(0.1, 2.1, 0.1), f)
        .unwrap();
    assert_eq!(v.map(|v| v.entity), Some(bad));
}

#[test]
fn degenerate_rays_and_empty_snapshots_answer_nothing_without_panicking() {
    let mut world = World::new();
    let cube = spawn_cube(&mut world, 0.5, 2, Isometry3::identity());
    let mut queries = SoftQueries::new();
    let f = SoftQueryFilter::new();
    let ray = |o: Vector, d: Vector| rapier3d::geometry::Ray::new(o, d);
    // Before any update: nothing to see.
    assert!(queries
        .cast_ray(&ray(Vector::ZERO, Vector::X), f32::MAX, true, f)
        .unwrap()
        .is_none());
    assert!(queries
        .project_point(Vector::ZERO, f32::MAX, f)
        .unwrap()
        .is_none());
    queries.update(&world);
    // A zero direction: a solid ray from inside still hits at 0, from outside nothing.
    let inside = queries
        .cast_ray(&ray(Vector::splat(0.1), Vector::ZERO), f32::MAX, true, f)
        .unwrap();
    assert_eq!(
        inside.map(|h| (h.entity, h.time_of_impact)),
        Some((cube, 0.0))
    );
    let outside = queries
        .intersect_ray(&ray(Vector::splat(3.0), Vector::ZERO), f32::MAX, false, f)
        .unwrap();
    assert!(outside.is_empty());
    // A zero max time of impact from outside: nothing; max_toi = 0 from inside with solid: the body.
    assert!(queries
        .cast_ray(&ray(Vector::new(0.0, 3.0, 0.0), -Vector::Y), 0.0, true, f)
        .unwrap()
        .is_none());
    assert!(queries
        .cast_ray(&ray(Vector::ZERO, Vector::Y), 0.0, true, f)
        .unwrap()
        .is_some());
}
