//! Ray casts against soft bodies, checked against the analytic answers of placed cubes.

mod queries_common;

use hecs::World;
use nalgebra::Vector3;
use queries_common::{glam, location_point, na, spawn_cube, Rng};
use rapier3d::geometry::Ray;
use rapier3d::math::Vector;
use tetpbd_rapier::{QueryError, SoftLocation, SoftQueries, SoftQueryFilter};

const ALL: SoftQueryFilter = SoftQueryFilter {
    groups: None,
    exclude_entity: None,
    predicate: None,
};

/// The six face normals of a box, local frame.
fn faces() -> [Vector3<f32>; 6] {
    [
        Vector3::x(),
        -Vector3::x(),
        Vector3::y(),
        -Vector3::y(),
        Vector3::z(),
        -Vector3::z(),
    ]
}

/// Two unit tangents of a face with normal `n`.
fn tangents(n: &Vector3<f32>) -> (Vector3<f32>, Vector3<f32>) {
    let a = if n.x.abs() > 0.5 {
        Vector3::y()
    } else {
        Vector3::x()
    };
    let t1 = n.cross(&a).normalize();
    (t1, n.cross(&t1))
}

#[test]
fn rays_hit_every_face_of_placed_cubes_at_the_analytic_distance() {
    let mut rng = Rng::new(11);
    for case in 0..40 {
        let h = rng.range(0.05, 2.0);
        let cells = 1 + case % 3;
        let pose = rng.pose(5.0);
        let mut world = World::new();
        let cube = spawn_cube(&mut world, h, cells, pose);
        let mut queries = SoftQueries::new();
        queries.update(&world);
        for n in faces() {
            let (t1, t2) = tangents(&n);
            let gap = rng.range(0.01, 3.0);
            let along = t1 * rng.range(-0.95, 0.95) * h + t2 * rng.range(-0.95, 0.95) * h;
            // Tilted up to ~35° off the face normal, still aimed at the same face point.
            let tilt = (t1 * rng.range(-0.5, 0.5) + t2 * rng.range(-0.5, 0.5)) * 0.7;
            let dir_local = (-n + tilt).normalize() * rng.range(0.5, 2.0);
            let target = n * h + along;
            let speed = dir_local.norm();
            let origin_local = target - dir_local / speed * gap;
            let ray = Ray::new(
                glam(&(pose * nalgebra::Point3::from(origin_local)).coords),
                glam(&(pose.rotation * dir_local)),
            );
            let what = format!("case {case} (h {h}, {cells} cells), face {n:?}");
            let hit = queries
                .cast_ray(&ray, f32::MAX, true, ALL)
                .expect("finite ray")
                .unwrap_or_else(|| panic!("{what}: no hit"));
            assert_eq!(hit.entity, cube, "{what}");
            let tol = 2e-4 * (1.0 + h + gap + pose.translation.vector.norm());
            assert!(
                (hit.time_of_impact * speed - gap).abs() < tol,
                "{what}: toi {} × {speed} vs {gap}",
                hit.time_of_impact
            );
            let target_world = (pose * nalgebra::Point3::from(target)).coords;
            assert!((na(hit.point) - target_world).norm() < tol, "{what}: point");
            assert!(
                (na(hit.normal) - pose.rotation * n).norm() < 1e-4,
                "{what}: normal {:?}",
                hit.normal
            );
            assert!(
                (location_point(&world, cube, &hit.location) - target_world).norm() < tol,
                "{what}: barycentrics"
            );
            let SoftLocation::Surface { barycentric, .. } = hit.location else {
                panic!("{what}: not a surface hit");
            };
            assert!(barycentric.iter().all(|w| (-1e-6..=1.0 + 1e-6).contains(w)));
            assert!((barycentric.iter().sum::<f32>() - 1.0).abs() < 1e-5);
            // A max time of impact short of the face misses; one just past it hits.
            let short = (gap - tol * 4.0) / speed;
            if short > 0.0 {
                assert!(
                    queries.cast_ray(&ray, short, true, ALL).unwrap().is_none(),
                    "{what}"
                );
            }
            assert!(
                queries
                    .cast_ray(&ray, (gap + tol * 4.0) / speed, true, ALL)
                    .unwrap()
                    .is_some(),
                "{what}"
            );
        }
    }
}

#[test]
fn rays_from_inside_hit_at_zero_when_solid_and_leave_through_the_face_otherwise() {
    let mut rng = Rng::new(12);
    for case in 0..30 {
        let h = rng.range(0.1, 1.5);
        let pose = rng.pose(3.0);
        let mut world = World::new();
        let cube = spawn_cube(&mut world, h, 1 + case % 3, pose);
        let mut queries = SoftQueries::new();
        queries.update(&world);
        for n in faces() {
            let inner = rng.cube() * (0.9 * h);
            let origin = (pose * nalgebra::Point3::from(inner)).coords;
            let ray = Ray::new(glam(&origin), glam(&(pose.rotation * n)));
            let what = format!("case {case}, face {n:?}");
            let solid = queries
                .cast_ray(&ray, f32::MAX, true, ALL)
                .unwrap()
                .expect("solid hit");
            assert_eq!((solid.entity, solid.time_of_impact), (cube, 0.0), "{what}");
            assert_eq!(solid.normal, Vector::ZERO, "{what}");
            assert!(
                matches!(solid.location, SoftLocation::Interior { .. }),
                "{what}"
            );
            assert!(
                (location_point(&world, cube, &solid.location) - origin).norm() < 1e-4 * (1.0 + h),
                "{what}"
            );
            let exit = queries
                .cast_ray(&ray, f32::MAX, false, ALL)
                .unwrap()
                .expect("exit hit");
            let expected = h - inner.dot(&n);
            assert!(
                (exit.time_of_impact - expected).abs() < 2e-4 * (1.0 + h),
                "{what}: {} vs {expected}",
                exit.time_of_impact
            );
            assert!(
                (na(exit.normal) - pose.rotation * n).norm() < 1e-4,
                "{what}: outward normal"
            );
        }
    }
}

#[test]
fn rays_that_pass_beside_or_away_from_a_cube_miss() {
    let mut rng = Rng::new(13);
    for case in 0..40 {
        let h = rng.range(0.05, 2.0);
        let pose = rng.pose(4.0);
        let mut world = World::new();
        spawn_cube(&mut world, h, 2, pose);
        let mut queries = SoftQueries::new();
        queries.update(&world);
        let centre = pose.translation.vector;
        let d = (rng.cube() + Vector3::new(0.0, 0.0, 1e-3)).normalize();
        // Beside: the line passes farther from the centre than the cube's half diagonal.
        let side = d.cross(&rng.cube()).normalize() * (h * 3f32.sqrt() * rng.range(1.01, 3.0));
        let origin = centre + side - d * rng.range(0.0, 10.0);
        let beside = Ray::new(glam(&origin), glam(&d));
        assert!(
            queries
                .cast_ray(&beside, f32::MAX, true, ALL)
                .unwrap()
                .is_none(),
            "case {case}: beside"
        );
        assert!(
            queries
                .intersect_ray(&beside, f32::MAX, true, ALL)
                .unwrap()
                .is_empty(),
            "case {case}"
        );
        // Away: starting outside the cube's bounding sphere and pointing away from it.
        let out = centre + d * (h * 3f32.sqrt() * rng.range(1.01, 3.0));
        let away = Ray::new(glam(&out), glam(&d));
        assert!(
            queries
                .cast_ray(&away, f32::MAX, true, ALL)
                .unwrap()
                .is_none(),
            "case {case}: away"
        );
        // Towards it, it hits.
        let towards = Ray::new(glam(&out), glam(&-d));
        assert!(
            queries
                .cast_ray(&towards, f32::MAX, true, ALL)
                .unwrap()
                .is_some(),
            "case {case}: towards"
        );
    }
}

#[test]
fn all_hits_through_two_bodies_come_in_order_of_time_of_impact() {
    let mut rng = Rng::new(14);
    for case in 0..25 {
        let (ha, hb) = (rng.range(0.1, 1.0), rng.range(0.1, 1.0));
        let gap = rng.range(0.05, 2.0);
        let rot = rng.rotation();
        let base = rng.cube() * 3.0;
        // Two cubes, axis-aligned in the frame `rot`, one behind the other along its x.
        let ca = base;
        let cb = base + rot * Vector3::x() * (ha + gap + hb);
        let mut world = World::new();
        let a = spawn_cube(
            &mut world,
            ha,
            2,
            nalgebra::Isometry3::from_parts(ca.into(), rot),
        );
        let b = spawn_cube(
            &mut world,
            hb,
            2,
            nalgebra::Isometry3::from_parts(cb.into(), rot),
        );
        let mut queries = SoftQueries::new();
        queries.update(&world);
        let lateral =
            (rot * Vector3::new(0.0, rng.range(-0.9, 0.9), rng.range(-0.9, 0.9))) * ha.min(hb);
        let start = rng.range(0.1, 2.0);
        let origin = ca - rot * Vector3::x() * (ha + start) + lateral;
        let ray = Ray::new(glam(&origin), glam(&(rot * Vector3::x())));
        let hits = queries.intersect_ray(&ray, f32::MAX, true, ALL).unwrap();
        let expected = [
            (a, start, -1.0),
            (a, start + 2.0 * ha, 1.0),
            (b, start + 2.0 * ha + gap, -1.0),
            (b, start + 2.0 * (ha + hb) + gap, 1.0),
        ];
        let got: Vec<_> = hits.iter().map(|h| (h.entity, h.time_of_impact)).collect();
        assert_eq!(hits.len(), 4, "case {case}: {got:?}");
        for (hit, (e, toi, sense)) in hits.iter().zip(expected) {
            assert_eq!(hit.entity, e, "case {case}: {got:?}");
            assert!(
                (hit.time_of_impact - toi).abs() < 1e-4 * (1.0 + toi),
                "case {case}: {got:?}"
            );
            assert!(
                (na(hit.normal).dot(&(rot * Vector3::x())) - sense).abs() < 1e-4,
                "case {case}"
            );
        }
        // The first of all hits is the first hit; a max time of impact inside the gap keeps two.
        let first = queries
            .cast_ray(&ray, f32::MAX, true, ALL)
            .unwrap()
            .expect("hit");
        assert_eq!(
            (first.entity, first.time_of_impact),
            (hits[0].entity, hits[0].time_of_impact)
        );
        let part = queries
            .intersect_ray(&ray, start + 2.0 * ha + 0.5 * gap, true, ALL)
            .unwrap();
        assert_eq!(part.len(), 2, "case {case}");
    }
}

#[test]
fn a_ray_through_edges_and_corners_is_reported_once_per_crossing() {
    let mut world = World::new();
    let cube = spawn_cube(&mut world, 0.5, 2, nalgebra::Isometry3::identity());
    let mut queries = SoftQueries::new();
    queries.update(&world);
    // Through two grid vertices on opposite faces (each shared by several triangles), and
    // along a face diagonal through the centre.
    for origin in [
        Vector::new(0.0, 0.0, -2.0),
        Vector::new(-0.5, -0.5, -2.0),
        Vector::new(0.25, 0.0, -2.0),
    ] {
        let ray = Ray::new(origin, Vector::Z);
        let hits = queries.intersect_ray(&ray, f32::MAX, false, ALL).unwrap();
        let tois: Vec<f32> = hits.iter().map(|h| h.time_of_impact).collect();
        assert_eq!(hits.len(), 2, "origin {origin:?}: {tois:?}");
        assert!(hits.iter().all(|h| h.entity == cube));
        assert!(
            (tois[0] - 1.5).abs() < 1e-5 && (tois[1] - 2.5).abs() < 1e-5,
            "{tois:?}"
        );
    }
}

#[test]
fn rays_through_grid_vertices_of_rotated_cubes_do_not_slip_between_triangles() {
    let mut rng = Rng::new(15);
    for case in 0..40 {
        let h = rng.range(0.05, 2.0);
        let cells = 1 + case % 4;
        let pose = rng.pose(5.0);
        let mut world = World::new();
        let cube = spawn_cube(&mut world, h, cells, pose);
        let mut queries = SoftQueries::new();
        queries.update(&world);
        for n in faces() {
            let (t1, t2) = tangents(&n);
            // A grid vertex, the middle of a grid edge or a cell centre inside the face (a
            // ray along a face's boundary grazes the side face: no defined answer).
            let half = h / cells as f32;
            let mut inner = || (1 + (rng.unit() * (2 * cells - 1) as f32) as u32) as f32;
            let target = n * h + t1 * (-h + half * inner()) + t2 * (-h + half * inner());
            let origin = target + n * 1.0;
            let ray = Ray::new(
                glam(&(pose * nalgebra::Point3::from(origin)).coords),
                glam(&(pose.rotation * -n)),
            );
            let hits = queries.intersect_ray(&ray, f32::MAX, false, ALL).unwrap();
            let tois: Vec<f32> = hits.iter().map(|h| h.time_of_impact).collect();
            let what = format!("case {case} (h {h}, {cells} cells), face {n:?}: {tois:?}");
            assert_eq!(hits.len(), 2, "{what}");
            assert!(hits.iter().all(|h| h.entity == cube), "{what}");
            let tol = 2e-4 * (1.0 + h + pose.translation.vector.norm());
            assert!(
                (tois[0] - 1.0).abs() < tol && (tois[1] - 1.0 - 2.0 * h).abs() < tol,
                "{what}"
            );
            let first = queries
                .cast_ray(&ray, f32::MAX, false, ALL)
                .unwrap()
                .expect("hit");
            assert!((first.time_of_impact - 1.0).abs() < tol, "{what}");
        }
    }
}

#[test]
fn non_finite_rays_and_bad_limits_are_rejected_by_name() {
    let mut world = World::new();
    spawn_cube(&mut world, 0.5, 1, nalgebra::Isometry3::identity());
    let mut queries = SoftQueries::new();
    queries.update(&world);
    let ok = Ray::new(Vector::new(0.0, 2.0, 0.0), -Vector::Y);
    let bad_origin = Ray::new(Vector::new(f32::NAN, 2.0, 0.0), -Vector::Y);
    let bad_dir = Ray::new(
        Vector::new(0.0, 2.0, 0.0),
        Vector::new(0.0, f32::INFINITY, 0.0),
    );
    match queries.cast_ray(&bad_origin, 1.0, true, ALL) {
        Err(QueryError::NonFiniteVector { what, value }) => {
            assert_eq!(what, "ray origin");
            assert!(value[0].is_nan());
        }
        other => panic!("{other:?}"),
    }
    assert!(matches!(
        queries.intersect_ray(&bad_dir, 1.0, true, ALL),
        Err(QueryError::NonFiniteVector {
            what: "ray direction",
            ..
        })
    ));
    for max_toi in [-1.0, f32::NAN] {
        let err = queries.cast_ray(&ok, max_toi, true, ALL).unwrap_err();
        assert!(
            matches!(
                err,
                QueryError::BadScalar {
                    what: "max_toi",
                    ..
                }
            ),
            "{err}"
        );
    }
    assert!(queries
        .cast_ray(&ok, f32::INFINITY, true, ALL)
        .unwrap()
        .is_some());
}

#[test]
fn the_snapshot_follows_moved_positions_after_update_only() {
    let mut world = World::new();
    let cube = spawn_cube(&mut world, 0.5, 2, nalgebra::Isometry3::identity());
    let mut queries = SoftQueries::new();
    queries.update(&world);
    let ray = Ray::new(Vector::new(0.0, 5.0, 0.0), -Vector::Y);
    let before = queries
        .cast_ray(&ray, f32::MAX, true, ALL)
        .unwrap()
        .unwrap();
    assert!((before.time_of_impact - 4.5).abs() < 1e-5);
    // The user moves the body up by 1 m: the old snapshot still answers as before …
    for p in world
        .get::<&mut tetpbd::Particles>(cube)
        .unwrap()
        .positions_mut()
    {
        p.y += 1.0;
    }
    let stale = queries
        .cast_ray(&ray, f32::MAX, true, ALL)
        .unwrap()
        .unwrap();
    assert_eq!(stale.time_of_impact, before.time_of_impact);
    // … and the refreshed one sees the move.
    queries.update(&world);
    let after = queries
        .cast_ray(&ray, f32::MAX, true, ALL)
        .unwrap()
        .unwrap();
    assert!(
        (after.time_of_impact - 3.5).abs() < 1e-5,
        "{}",
        after.time_of_impact
    );
    // A despawned body is gone after the next update.
    world.despawn(cube).unwrap();
    queries.update(&world);
    assert!(queries
        .cast_ray(&ray, f32::MAX, true, ALL)
        .unwrap()
        .is_none());
    assert!(queries.is_empty());
}
