//! AABB and shape overlap against soft bodies, and the groups and filters every query
//! honours.

mod queries_common;

use hecs::World;
use nalgebra::{Isometry3, Point3, Vector3};
use queries_common::{box_surface_nearest, glam, spawn_cube, Rng};
use rapier3d::geometry::{Aabb, Ray};
use rapier3d::math::{Pose, Vector};
use rapier3d::parry::shape::{Ball, Cuboid};
use rapier3d::prelude::{Group, InteractionGroups, InteractionTestMode};
use tetpbd_rapier::{SoftColliderBuilder, SoftQueries, SoftQueryFilter};

fn pose_of(iso: &Isometry3<f32>) -> Pose {
    let q = iso.rotation.quaternion();
    Pose::from_parts(
        glam(&iso.translation.vector),
        rapier3d::math::Rotation::from_xyzw(q.i, q.j, q.k, q.w),
    )
}

#[test]
fn balls_overlap_a_placed_cube_exactly_when_closer_than_their_radius() {
    let mut rng = Rng::new(31);
    for case in 0..30 {
        let h = rng.range(0.1, 1.5);
        let pose = rng.pose(4.0);
        let mut world = World::new();
        let cube = spawn_cube(&mut world, h, 1 + case % 3, pose);
        let mut queries = SoftQueries::new();
        queries.update(&world);
        let f = SoftQueryFilter::new();
        for k in 0..20 {
            let q = rng.cube() * (2.0 * h);
            let (_, dist) = box_surface_nearest(&q, h);
            let inside = q.iter().all(|c| c.abs() <= h);
            let r = rng.range(0.02, 1.0) * h;
            // Keep 2 % of the radius away from the touching distance.
            if !inside && (dist - r).abs() < 0.02 * r {
                continue;
            }
            let centre = (pose * Point3::from(q)).coords;
            let ball_pose = Pose::from_translation(glam(&centre));
            let hit = queries
                .intersect_shape(&ball_pose, &Ball::new(r), f)
                .unwrap();
            let expected = inside || dist < r;
            assert_eq!(
                hit == vec![cube],
                expected,
                "case {case}, ball {k}: local {q:?}, r {r}, dist {dist}"
            );
        }
        // A small cuboid wholly inside the cube (touching no triangle) overlaps it.
        let small = Cuboid::new(Vector::splat(0.1 * h));
        let inner_pose = pose * Isometry3::translation(0.2 * h, -0.3 * h, 0.1 * h);
        assert_eq!(
            queries
                .intersect_shape(&pose_of(&inner_pose), &small, f)
                .unwrap(),
            vec![cube]
        );
        // A big cuboid holding the whole cube overlaps it too.
        let big = Cuboid::new(Vector::splat(4.0 * h));
        assert_eq!(
            queries.intersect_shape(&pose_of(&pose), &big, f).unwrap(),
            vec![cube]
        );
    }
}

#[test]
fn aabbs_find_the_bodies_whose_bounds_they_meet() {
    let mut world = World::new();
    let bodies: Vec<_> = (0..5)
        .map(|i| {
            spawn_cube(
                &mut world,
                0.5,
                1,
                Isometry3::translation(2.0 * i as f32, 0.0, 0.0),
            )
        })
        .collect();
    let mut queries = SoftQueries::new();
    queries.update(&world);
    let f = SoftQueryFilter::new();
    for i in 0..5 {
        for j in i..5 {
            // From inside body i to inside body j.
            let aabb = Aabb::new(
                Vector::new(2.0 * i as f32 - 0.2, -0.1, -0.1),
                Vector::new(2.0 * j as f32 + 0.2, 0.1, 0.1),
            );
            let mut expected: Vec<_> = bodies[i..=j].to_vec();
            expected.sort_by_key(|e| e.to_bits());
            assert_eq!(
                queries.intersect_aabb(&aabb, f).unwrap(),
                expected,
                "{i}..={j}"
            );
        }
    }
    // In the gaps between the bodies, and above them: nothing.
    let gap = Aabb::new(Vector::new(0.6, -1.0, -1.0), Vector::new(1.4, 1.0, 1.0));
    assert!(queries.intersect_aabb(&gap, f).unwrap().is_empty());
    let above = Aabb::new(Vector::new(-1.0, 0.6, -1.0), Vector::new(9.0, 2.0, 1.0));
    assert!(queries.intersect_aabb(&above, f).unwrap().is_empty());
}

/// Three cubes in a row along a ray: near (group 1), middle (group 2), far (disabled).
struct Row {
    queries: SoftQueries,
    ray: Ray,
    near: hecs::Entity,
    middle: hecs::Entity,
    /// Centre of cube `k` (1 near, 2 middle, 3 far), m.
    centres: [Vector; 4],
    h: f32,
}

/// Groups that accept only the members of `g`.
fn only(g: Group) -> InteractionGroups {
    InteractionGroups::new(Group::ALL, g, InteractionTestMode::And)
}

impl Row {
    fn new(rng: &mut Rng) -> Row {
        let g1 = InteractionGroups::new(Group::GROUP_1, Group::ALL, InteractionTestMode::And);
        let g2 = InteractionGroups::new(Group::GROUP_2, Group::ALL, InteractionTestMode::And);
        let rot = rng.rotation();
        let x = rot * Vector3::x();
        let start = rng.cube() * 3.0;
        let mut world = World::new();
        let h = rng.range(0.2, 0.6);
        let centre = |k: f32| start + x * (3.0 * k);
        let place = |k: f32| Isometry3::from_parts(centre(k).into(), rot);
        let near = spawn_cube(&mut world, h, 2, place(1.0));
        let middle = spawn_cube(&mut world, h, 2, place(2.0));
        let far = spawn_cube(&mut world, h, 2, place(3.0));
        let collider = |g| {
            SoftColliderBuilder::new()
                .collision_groups(g)
                .build()
                .unwrap()
        };
        world.insert_one(near, collider(g1)).unwrap();
        world.insert_one(middle, collider(g2)).unwrap();
        let mut off = collider(g1);
        off.set_enabled(false);
        world.insert_one(far, off).unwrap();
        let mut queries = SoftQueries::new();
        queries.update(&world);
        let centres = [0.0, 1.0, 2.0, 3.0].map(|k| glam(&centre(k)));
        let ray = Ray::new(glam(&start), glam(&x));
        Row {
            queries,
            ray,
            near,
            middle,
            centres,
            h,
        }
    }

    fn first(&self, f: SoftQueryFilter) -> Option<hecs::Entity> {
        let hit = self
            .queries
            .cast_ray(&self.ray, f32::MAX, false, f)
            .unwrap();
        hit.map(|h| h.entity)
    }

    fn crossed(&self, f: SoftQueryFilter) -> Vec<hecs::Entity> {
        let hits = self
            .queries
            .intersect_ray(&self.ray, f32::MAX, false, f)
            .unwrap();
        let mut e: Vec<_> = hits.iter().map(|h| h.entity).collect();
        e.dedup();
        e
    }
}

#[test]
fn groups_predicates_excluded_and_disabled_bodies_are_not_seen_by_rays() {
    let mut rng = Rng::new(32);
    for case in 0..10 {
        let r = Row::new(&mut rng);
        let (near, middle) = (r.near, r.middle);
        let all = SoftQueryFilter::new();
        assert_eq!(r.first(all), Some(near), "case {case}");
        assert_eq!(
            r.crossed(all),
            vec![near, middle],
            "case {case}: the disabled body is never seen"
        );
        assert_eq!(
            r.first(all.groups(only(Group::GROUP_2))),
            Some(middle),
            "case {case}"
        );
        assert_eq!(
            r.first(all.exclude_entity(near)),
            Some(middle),
            "case {case}"
        );
        let not_middle = |e: hecs::Entity| e != middle;
        assert_eq!(
            r.crossed(all.predicate(&not_middle)),
            vec![near],
            "case {case}"
        );
        assert_eq!(
            r.first(all.groups(only(Group::GROUP_3))),
            None,
            "case {case}"
        );
    }
}

#[test]
fn groups_predicates_excluded_and_disabled_bodies_are_not_seen_by_point_and_overlap_queries() {
    let mut rng = Rng::new(33);
    for case in 0..10 {
        let r = Row::new(&mut rng);
        let (q, near, middle) = (&r.queries, r.near, r.middle);
        let all = SoftQueryFilter::new();
        let p = r.centres[1];
        assert_eq!(
            q.contains_point(p, all).unwrap().map(|v| v.entity),
            Some(near),
            "case {case}"
        );
        assert!(
            q.contains_point(p, all.exclude_entity(near))
                .unwrap()
                .is_none(),
            "case {case}"
        );
        assert!(
            q.contains_point(r.centres[3], all).unwrap().is_none(),
            "case {case}: disabled"
        );
        let proj = q
            .project_point(p, f32::MAX, all.groups(only(Group::GROUP_2)))
            .unwrap();
        assert_eq!(proj.map(|p| p.entity), Some(middle), "case {case}");
        let everything = Aabb::new(Vector::splat(-100.0), Vector::splat(100.0));
        let mut two = vec![near, middle];
        two.sort_by_key(|e| e.to_bits());
        assert_eq!(
            q.intersect_aabb(&everything, all).unwrap(),
            two,
            "case {case}"
        );
        let not_middle = |e: hecs::Entity| e != middle;
        let seen = q
            .intersect_aabb(&everything, all.predicate(&not_middle))
            .unwrap();
        assert_eq!(seen, vec![near], "case {case}");
        let ball = Ball::new(0.5 * r.h);
        let at_middle = Pose::from_translation(r.centres[2]);
        assert_eq!(
            q.intersect_shape(&at_middle, &ball, all).unwrap(),
            vec![middle],
            "case {case}"
        );
        let g1_only = all.groups(only(Group::GROUP_1));
        assert!(
            q.intersect_shape(&at_middle, &ball, g1_only)
                .unwrap()
                .is_empty(),
            "case {case}"
        );
    }
}
