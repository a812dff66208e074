//! One query over rapier's colliders and the soft bodies: the nearer of a rigid cuboid and
//! a soft cube wins.

mod queries_common;

use hecs::World;
use nalgebra::{Isometry3, Vector3};
use queries_common::{glam, spawn_cube, Rng};
use rapier3d::geometry::Ray;
use rapier3d::prelude::{ColliderBuilder, PhysicsWorld, QueryFilter, RigidBodyBuilder};
use tetpbd_rapier::{ScenePointProjection, SceneRayHit, SoftQueries, SoftQueryFilter};

#[test]
fn the_nearer_of_a_rigid_cuboid_and_a_soft_cube_is_hit_first() {
    let mut rng = Rng::new(41);
    let (mut rigid_wins, mut soft_wins) = (0, 0);
    for case in 0..40 {
        // Along a random direction from a random origin: a soft cube and a rigid cuboid at
        // random distances, one behind the other, both facing the ray.
        let rot = rng.rotation();
        let x = rot * Vector3::x();
        let origin = rng.cube() * 3.0;
        let (hs, hr) = (rng.range(0.1, 1.0), rng.range(0.1, 1.0));
        let (ds, dr) = (rng.range(0.2, 6.0), rng.range(0.2, 6.0));
        let (soft_at, rigid_at) = if ds < dr {
            (ds, ds + 2.0 * hs + dr)
        } else {
            (dr + 2.0 * hr + ds, dr)
        };
        let soft_centre = origin + x * (soft_at + hs);
        let rigid_centre = origin + x * (rigid_at + hr);
        let mut world = World::new();
        let soft = spawn_cube(
            &mut world,
            hs,
            2,
            Isometry3::from_parts(soft_centre.into(), rot),
        );
        let mut queries = SoftQueries::new();
        queries.update(&world);
        let mut physics = PhysicsWorld::new();
        let q = rot.quaternion();
        let pose = rapier3d::math::Pose::from_parts(
            glam(&rigid_centre),
            rapier3d::math::Rotation::from_xyzw(q.i, q.j, q.k, q.w),
        );
        let (_, collider) = physics.insert(
            RigidBodyBuilder::fixed().pose(pose),
            ColliderBuilder::cuboid(hr, hr, hr),
        );
        physics.step();
        let ray = Ray::new(glam(&origin), glam(&x));
        let rigid = physics.query_pipeline();
        let all = SoftQueryFilter::new();
        let hit = queries
            .cast_ray_scene(&rigid, &ray, f32::MAX, true, all)
            .unwrap()
            .expect("a hit");
        let tol = 2e-4 * (1.0 + soft_at + rigid_at);
        match hit {
            SceneRayHit::Soft(h) => {
                soft_wins += 1;
                assert!(soft_at < rigid_at, "case {case}");
                assert_eq!(h.entity, soft);
                assert!((h.time_of_impact - soft_at).abs() < tol, "case {case}");
            }
            SceneRayHit::Rigid {
                collider: c,
                intersection,
            } => {
                rigid_wins += 1;
                assert!(rigid_at < soft_at, "case {case}");
                assert_eq!(c, collider);
                assert!(
                    (intersection.time_of_impact - rigid_at).abs() < tol,
                    "case {case}"
                );
            }
        }
        assert!((hit.time_of_impact() - soft_at.min(rigid_at)).abs() < tol);
        assert!(
            (hit.normal() + glam(&x)).length() < 1e-3,
            "case {case}: facing the ray"
        );
        // Excluding the nearer one on its side shows the other.
        let far = soft_at.max(rigid_at);
        let next = match hit {
            SceneRayHit::Soft(_) => {
                queries.cast_ray_scene(&rigid, &ray, f32::MAX, true, all.exclude_entity(soft))
            }
            SceneRayHit::Rigid { .. } => {
                let rigid = physics
                    .query_pipeline_with_filter(QueryFilter::new().exclude_collider(collider));
                queries.cast_ray_scene(&rigid, &ray, f32::MAX, true, all)
            }
        };
        let next = next.unwrap().expect("the farther one");
        assert!(
            (next.time_of_impact() - far).abs() < tol,
            "case {case}: {next:?}, far {far}, soft {soft_at}, rigid {rigid_at}"
        );
        // A max time of impact short of both: nothing.
        let none = queries
            .cast_ray_scene(&rigid, &ray, 0.9 * soft_at.min(rigid_at), true, all)
            .unwrap();
        assert!(none.is_none(), "case {case}");
        // The nearest surface point from the ray origin: the nearer body's facing face.
        let p = queries
            .project_point_scene(&rigid, glam(&origin), f32::MAX, all)
            .unwrap()
            .expect("a point");
        let d = (p.point() - glam(&origin)).length();
        assert!(d <= soft_at.min(rigid_at) + tol, "case {case}");
        assert!(!p.is_inside());
        match p {
            ScenePointProjection::Soft(s) => assert_eq!(s.entity, soft),
            ScenePointProjection::Rigid { collider: c, .. } => assert_eq!(c, collider),
        }
    }
    assert!(
        rigid_wins > 5 && soft_wins > 5,
        "{rigid_wins} rigid, {soft_wins} soft"
    );
}

#[test]
fn a_coupled_world_answers_for_its_current_state_after_steps_and_writes() {
    use tetpbd_rapier::CoupledWorld;
    let mut scene = CoupledWorld::new(Default::default(), Default::default()).unwrap();
    scene.physics.insert(
        RigidBodyBuilder::fixed().translation(rapier3d::math::Vector::new(0.0, -0.5, 0.0)),
        ColliderBuilder::cuboid(3.0, 0.5, 3.0),
    );
    let cube = spawn_cube(
        &mut scene.soft,
        0.2,
        2,
        Isometry3::translation(0.0, 0.25, 0.0),
    );
    let ray = Ray::new(
        rapier3d::math::Vector::new(0.0, 3.0, 0.0),
        -rapier3d::math::Vector::Y,
    );
    let all = SoftQueryFilter::new();
    for frame in 0..30 {
        scene.step().unwrap();
        let top = {
            let p = scene.soft.get::<&tetpbd::Particles>(cube).unwrap();
            p.positions().iter().map(|x| x.y).fold(f32::MIN, f32::max)
        };
        let (soft, rigid) = scene.queries();
        let hit = soft
            .cast_ray_scene(&rigid, &ray, f32::MAX, true, all)
            .unwrap();
        let Some(SceneRayHit::Soft(h)) = hit else {
            panic!("frame {frame}: {hit:?}");
        };
        assert_eq!(h.entity, cube);
        // The top face is where the particles are now (it sags a little under gravity).
        assert!(
            (h.time_of_impact - (3.0 - top)).abs() < 0.02,
            "frame {frame}: {} vs top {top}",
            h.time_of_impact
        );
    }
    // The user lifts the cube by 1 m: the next call sees it.
    for x in scene
        .soft
        .get::<&mut tetpbd::Particles>(cube)
        .unwrap()
        .positions_mut()
    {
        x.y += 1.0;
    }
    let (soft, _) = scene.queries();
    let h = soft.cast_ray(&ray, f32::MAX, true, all).unwrap().unwrap();
    assert!(h.time_of_impact < 3.0 - 1.0, "{}", h.time_of_impact);
}
