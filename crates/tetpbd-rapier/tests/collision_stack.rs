//! A soft body on a stack of rigid boxes: the soft load goes through rapier's solver and
//! does not squash the stack.

mod coupling_common;

use coupling_common::{particles, run, scene, soft_box_with_density};
use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder};
use tetpbd_rapier::SoftCollider;

#[test]
fn soft_body_on_a_box_stack() {
    let mut s = scene(10);
    s.physics.insert(
        RigidBodyBuilder::fixed().translation(Vector::new(0.0, -0.5, 0.0)),
        ColliderBuilder::cuboid(5.0, 0.5, 5.0),
    );
    let mut boxes = Vec::new();
    for k in 0..3 {
        let (h, _) = s.physics.insert(
            RigidBodyBuilder::dynamic().translation(Vector::new(0.0, 0.15 + 0.3 * k as f32, 0.0)),
            ColliderBuilder::cuboid(0.3, 0.15, 0.3).density(500.0),
        );
        boxes.push(h);
    }
    // Let the stack settle, then note where its top is.
    run(&mut s, 30, 1);
    let rest = s.physics.bodies[boxes[2]].translation().y;
    // A 19 kg soft cube (the boxes weigh 13.5 kg each) lands on top.
    let e = soft_box_with_density(
        &mut s,
        Vector3::repeat(0.4),
        [2, 2, 2],
        Vector3::new(0.05, 1.3, 0.0),
        300.0,
        SoftCollider::default(),
    );
    let pen = run(&mut s, 150, 30);
    let top = s.physics.bodies[boxes[2]].translation().y;
    let p = particles(&s, e);
    println!(
        "top box at {top:.4} m (alone {rest:.4} m), soft body lowest {:.4} m, max |v| {:.4} m/s, \
         penetration {pen:.5} m",
        p.aabb().0.y,
        p.max_speed()
    );
    assert!(rest - top < 0.005, "stack squashed by {} m", rest - top);
    // The box reacts to the soft load one rapier step later; the soft cube keeps a small
    // rocking motion (about 0.05 m/s at its top corners) rather than coming fully to rest.
    assert!(
        p.max_speed() < 0.1,
        "soft body moving at {} m/s",
        p.max_speed()
    );
    assert!(
        p.aabb().0.y > top + 0.15 - 0.002,
        "soft body sank into the top box"
    );
    assert!(pen < 0.002);
    for h in &boxes {
        let x = s.physics.bodies[*h].translation();
        assert!(
            x.x.abs() < 0.01 && x.z.abs() < 0.01,
            "the stack toppled: {x:?}"
        );
    }
}
