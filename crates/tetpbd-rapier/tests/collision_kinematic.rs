//! Kinematic platforms carry soft bodies; sensors and filtered groups are passed through.

mod coupling_common;

use coupling_common::{min_y, particles, run, scene, soft_box};
use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{
    ColliderBuilder, Group, InteractionGroups, InteractionTestMode, RigidBodyBuilder,
};
use tetpbd_rapier::{CoupledWorld, SoftCollider, SoftColliderBuilder};

const SPEED: f32 = 0.5;

#[test]
fn kinematic_platform_carries_a_soft_body() {
    let mut s = scene(10);
    let (platform, _) = s.physics.insert(
        RigidBodyBuilder::kinematic_velocity_based()
            .translation(Vector::new(0.0, -0.05, 0.0))
            .linvel(Vector::new(SPEED, 0.0, 0.0)),
        ColliderBuilder::cuboid(3.0, 0.05, 1.0),
    );
    let collider = SoftColliderBuilder::new()
        .friction(0.8)
        .build()
        .expect("collider");
    let e = soft_box(
        &mut s,
        Vector3::repeat(0.2),
        [2, 2, 2],
        Vector3::new(0.0, 0.1 + 0.0025, 0.0),
        collider,
    );
    // 1.5 s: the body is brought up to the platform's speed and then rides along.
    for _ in 0..90 {
        s.step().expect("step");
    }
    let p = particles(&s, e);
    let v = p.linear_momentum() / p.total_mass();
    let px = s.physics.bodies[platform].translation().x;
    let offset = p.center_of_mass().x - px;
    println!("soft velocity {v:?}, platform at {px:.3} m, soft centre {offset:.4} m from it");
    assert!(
        (v.x - SPEED).abs() < 0.02 * SPEED,
        "soft body moves at {} m/s",
        v.x
    );
    assert!(v.y.abs() < 0.01);
    assert!(
        offset.abs() < 0.05,
        "slipped {offset} m relative to the platform"
    );
    assert!(min_y(&s, e) > -0.001, "sank into the platform");
}

/// A soft cube dropped onto a ground built by `make`; returns its lowest point after 1 s.
fn drop_on(make: impl FnOnce(&mut CoupledWorld), collider: SoftCollider) -> f32 {
    let mut s = scene(10);
    make(&mut s);
    let e = soft_box(
        &mut s,
        Vector3::repeat(0.2),
        [2, 2, 2],
        Vector3::new(0.0, 0.2, 0.0),
        collider,
    );
    run(&mut s, 60, 1);
    min_y(&s, e)
}

fn ground_with(builder: ColliderBuilder) -> impl FnOnce(&mut CoupledWorld) {
    move |s: &mut CoupledWorld| {
        s.physics.insert(
            RigidBodyBuilder::fixed().translation(Vector::new(0.0, -0.5, 0.0)),
            builder,
        );
    }
}

#[test]
fn sensor_is_passed_through() {
    let ground = ColliderBuilder::cuboid(2.0, 0.5, 2.0);
    let solid = drop_on(ground_with(ground.clone()), SoftCollider::default());
    let sensor = drop_on(ground_with(ground.sensor(true)), SoftCollider::default());
    println!("lowest point after 1 s: solid ground {solid:.3} m, sensor ground {sensor:.3} m");
    assert!(solid > -0.001, "did not land on the solid ground");
    assert!(
        sensor < -2.0,
        "did not fall through the sensor ({sensor} m)"
    );
}

#[test]
fn filtered_collision_group_is_passed_through() {
    let only_two = InteractionGroups::new(Group::GROUP_2, Group::GROUP_2, InteractionTestMode::And);
    let ground = ColliderBuilder::cuboid(2.0, 0.5, 2.0).collision_groups(only_two);
    let default_soft = drop_on(ground_with(ground.clone()), SoftCollider::default());
    let member = SoftColliderBuilder::new()
        .collision_groups(InteractionGroups::new(
            Group::GROUP_2,
            Group::ALL,
            InteractionTestMode::And,
        ))
        .build()
        .expect("collider");
    let in_group = drop_on(ground_with(ground), member);
    println!("lowest point: soft in group 1 {default_soft:.3} m, soft in group 2 {in_group:.3} m");
    assert!(
        default_soft < -2.0,
        "group 1 soft body was not filtered out"
    );
    assert!(in_group > -0.001, "group 2 soft body did not land");
}

#[test]
fn solver_groups_report_without_solving() {
    let none = InteractionGroups::new(Group::GROUP_2, Group::GROUP_2, InteractionTestMode::And);
    let mut s = scene(10);
    let (_, g) = s.physics.insert(
        RigidBodyBuilder::fixed().translation(Vector::new(0.0, -0.5, 0.0)),
        ColliderBuilder::cuboid(2.0, 0.5, 2.0).solver_groups(none),
    );
    let e = soft_box(
        &mut s,
        Vector3::repeat(0.2),
        [2, 2, 2],
        Vector3::new(0.0, 0.2, 0.0),
        SoftCollider::default(),
    );
    let mut reported = 0;
    for _ in 0..40 {
        s.step().expect("step");
        reported += s
            .coupling
            .contacts()
            .iter()
            .filter(|c| c.collider == g && !c.solved)
            .count();
        assert!(s
            .coupling
            .contacts()
            .iter()
            .all(|c| c.impulse == Vector3::zeros()));
    }
    println!(
        "unsolved contacts reported: {reported}; lowest {:.3} m",
        min_y(&s, e)
    );
    assert!(reported > 0, "the unsolved contacts were not reported");
    assert!(min_y(&s, e) < -0.3, "the soft body was stopped");
}
