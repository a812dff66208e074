//! One query over rapier's colliders and the soft bodies: the nearer of a rigid cuboid and
//! a soft cube wins.

mod queries_common;

use hecs::World;
use nalgebra::{Isometry3, Vector3};
use queries_common::{glam, spawn_cube, Rng};
use rapier3d::geometry::{ColliderHandle, Ray};
use rapier3d::prelude::{ColliderBuilder, PhysicsWorld, QueryFilter, RigidBodyBuilder};
use tetpbd_rapier::{ScenePointProjection, SceneRayHit, SoftQueries, SoftQueryFilter};

/// A soft cube and a rigid cuboid one behind the other along a ray, both facing it.
struct Case {
    queries: SoftQueries,
    physics: PhysicsWorld,
    soft: hecs::Entity,
    collider: ColliderHandle,
    ray: Ray,
    /// Distances along the ray to the two bodies' facing faces, m.
    soft_at: f32,
    rigid_at: f32,
}

impl Case {
    /// Along a random direction from a random origin, at random sizes and distances.
    fn new(rng: &mut Rng) -> Case {
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
        let soft_pose = Isometry3::from_parts(soft_centre.into(), rot);
        let soft = spawn_cube(&mut world, hs, 2, soft_pose);
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
        Case {
            queries,
            physics,
            soft,
            collider,
            ray,
            soft_at,
            rigid_at,
        }
    }

    fn tol(&self) -> f32 {
        2e-4 * (1.0 + self.soft_at + self.rigid_at)
    }

    /// Checks that the nearer body is hit first, and returns whether it was the soft one.
    fn check_first_hit(&self, case: usize) -> bool {
        let rigid = self.physics.query_pipeline();
        let all = SoftQueryFilter::new();
        let hit = self
            .queries
            .cast_ray_scene(&rigid, &self.ray, f32::MAX, true, all);
        let hit = hit.unwrap().expect("a hit");
        let near = self.soft_at.min(self.rigid_at);
        assert!(
            (hit.time_of_impact() - near).abs() < self.tol(),
            "case {case}"
        );
        assert!(
            (hit.normal() + self.ray.dir).length() < 1e-3,
            "case {case}: facing the ray"
        );
        match hit {
            SceneRayHit::Soft(h) => {
                assert!(self.soft_at < self.rigid_at, "case {case}");
                assert_eq!(h.entity, self.soft);
                true
            }
            SceneRayHit::Rigid { collider, .. } => {
                assert!(self.rigid_at < self.soft_at, "case {case}");
                assert_eq!(collider, self.collider);
                false
            }
        }
    }

    /// Excluding the nearer body on its side, the farther one is hit; a max time of impact
    /// short of both hits nothing.
    fn check_farther_and_short(&self, case: usize, soft_nearer: bool) {
        let all = SoftQueryFilter::new();
        let next = if soft_nearer {
            let rigid = self.physics.query_pipeline();
            let no_soft = all.exclude_entity(self.soft);
            self.queries
                .cast_ray_scene(&rigid, &self.ray, f32::MAX, true, no_soft)
        } else {
            let filter = QueryFilter::new().exclude_collider(self.collider);
            let rigid = self.physics.query_pipeline_with_filter(filter);
            self.queries
                .cast_ray_scene(&rigid, &self.ray, f32::MAX, true, all)
        };
        let next = next.unwrap().expect("the farther one");
        let far = self.soft_at.max(self.rigid_at);
        assert!(
            (next.time_of_impact() - far).abs() < self.tol(),
            "case {case}: {next:?}"
        );
        let short = 0.9 * self.soft_at.min(self.rigid_at);
        let rigid = self.physics.query_pipeline();
        let none = self
            .queries
            .cast_ray_scene(&rigid, &self.ray, short, true, all);
        assert!(none.unwrap().is_none(), "case {case}");
    }

    /// The nearest surface point from the ray's origin is the centre of the nearer body's
    /// facing face (the farther body lies wholly beyond its own facing plane).
    fn check_projection(&self, case: usize, soft_nearer: bool) {
        let rigid = self.physics.query_pipeline();
        let origin = self.ray.origin;
        let p = self
            .queries
            .project_point_scene(&rigid, origin, f32::MAX, SoftQueryFilter::new());
        let p = p.unwrap().expect("a point");
        let near = self.soft_at.min(self.rigid_at);
        let expected = origin + self.ray.dir * near;
        assert!((p.point() - expected).length() < self.tol(), "case {case}");
        assert!(!p.is_inside());
        match p {
            ScenePointProjection::Soft(s) => assert!(soft_nearer && s.entity == self.soft),
            ScenePointProjection::Rigid { collider, .. } => {
                assert!(!soft_nearer && collider == self.collider)
            }
        }
    }
}

#[test]
fn the_nearer_of_a_rigid_cuboid_and_a_soft_cube_is_hit_first() {
    let mut rng = Rng::new(41);
    let (mut rigid_wins, mut soft_wins) = (0, 0);
    for case in 0..40 {
        let c = Case::new(&mut rng);
        let soft_nearer = c.check_first_hit(case);
        if soft_nearer {
            soft_wins += 1;
        } else {
            rigid_wins += 1;
        }
        c.check_farther_and_short(case, soft_nearer);
        c.check_projection(case, soft_nearer);
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
