//! A coupling context built from the sets an integrator keeps ([`RapierContext::new`]) steps
//! a scene exactly as one borrowed from rapier's `PhysicsWorld` bundle does.

use nalgebra::Vector3;
use rapier3d::prelude::*;
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{Particles, SoftBodyBuilder};
use tetpbd_rapier::{Coupling, RapierContext};

fn spawn_cube(soft: &mut hecs::World, height: f32) -> hecs::Entity {
    let mesh = box_grid(Vector3::repeat(0.3), [2, 2, 2], CellSplit::Six).unwrap();
    SoftBodyBuilder::new(mesh)
        .edges(1e-6)
        .volume(0.0)
        .translation(Vector3::new(0.05, height, 0.0))
        .build()
        .unwrap()
        .spawn(soft)
}

#[test]
fn context_from_separate_sets_steps_like_the_physics_world_bundle() {
    for (frames, height) in [(20, 0.3), (45, 0.6)] {
        // The bundle.
        let mut world = PhysicsWorld::new();
        world.insert(
            RigidBodyBuilder::fixed(),
            ColliderBuilder::cuboid(2.0, 0.1, 2.0),
        );
        let ball = world.insert(
            RigidBodyBuilder::dynamic().translation(Vector::new(0.0, 1.0, 0.0)),
            ColliderBuilder::ball(0.1),
        );
        let mut soft_a = hecs::World::new();
        let a = spawn_cube(&mut soft_a, height);
        let mut coupling_a = Coupling::new(Default::default(), Default::default()).unwrap();

        // The same scene in an integrator's own sets.
        let mut pipeline = PhysicsPipeline::new();
        let params = IntegrationParameters::default();
        let mut islands = IslandManager::new();
        let mut broad_phase = DefaultBroadPhase::default();
        let mut narrow_phase = NarrowPhase::new();
        let mut bodies = RigidBodySet::new();
        let mut colliders = ColliderSet::new();
        let (mut impulse_joints, mut multibody_joints) =
            (ImpulseJointSet::new(), MultibodyJointSet::new());
        let (mut soft_bodies, mut ccd) = (SoftBodySet::new(), CCDSolver::new());
        let ground = bodies.insert(RigidBodyBuilder::fixed());
        colliders.insert_with_parent(ColliderBuilder::cuboid(2.0, 0.1, 2.0), ground, &mut bodies);
        let ball_b =
            bodies.insert(RigidBodyBuilder::dynamic().translation(Vector::new(0.0, 1.0, 0.0)));
        colliders.insert_with_parent(ColliderBuilder::ball(0.1), ball_b, &mut bodies);
        let mut soft_b = hecs::World::new();
        let b = spawn_cube(&mut soft_b, height);
        let mut coupling_b = Coupling::new(Default::default(), Default::default()).unwrap();
        let events = ();

        for _ in 0..frames {
            coupling_a
                .step(&mut soft_a, RapierContext::from(&mut world))
                .unwrap();
            let ctx = RapierContext::new(
                &mut pipeline,
                Vector::new(0.0, -9.81, 0.0),
                &params,
                &mut islands,
                &mut broad_phase,
                &mut narrow_phase,
                &mut bodies,
                &mut colliders,
                &mut impulse_joints,
                &mut multibody_joints,
                &mut soft_bodies,
                &mut ccd,
            )
            .with_hooks(&())
            .with_events(&events);
            coupling_b.step(&mut soft_b, ctx).unwrap();
        }
        let pa = soft_a.get::<&Particles>(a).unwrap();
        let pb = soft_b.get::<&Particles>(b).unwrap();
        assert_eq!(
            pa.positions(),
            pb.positions(),
            "{frames} frames from {height} m"
        );
        assert_eq!(
            world.bodies[ball.0].translation(),
            bodies[ball_b].translation(),
            "{frames} frames from {height} m"
        );
        assert!(!coupling_b.contacts().is_empty(), "the cube landed");
    }
}
