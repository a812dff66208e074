//! Two-way momentum exchange: a soft ball thrown at a free rigid box in zero gravity.

mod coupling_common;

use coupling_common::{particles, scene, soft_ball};
use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder};
use tetpbd_rapier::SoftCollider;

#[test]
fn total_linear_momentum_is_conserved() {
    let mut s = scene(10);
    s.physics.gravity = Vector::ZERO;
    let (boxh, _) = s.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vector::new(0.5, 0.0, 0.0)),
        ColliderBuilder::cuboid(0.25, 0.25, 0.25)
            .density(1000.0)
            .friction(0.5),
    );
    let ball = soft_ball(
        &mut s,
        0.2,
        2,
        Vector3::new(-0.5, 0.05, 0.0),
        Vector3::new(3.0, 0.0, 0.0),
        1000.0,
        SoftCollider::default(),
    );
    let momentum = |s: &tetpbd_rapier::CoupledWorld| {
        let b = &s.physics.bodies[boxh];
        particles(s, ball).linear_momentum() + Vector3::from(b.linvel()) * b.mass()
    };
    let p0 = momentum(&s);
    let mut touched = false;
    for _ in 0..60 {
        let stats = s.step().expect("step");
        touched |= stats.contacts > 0;
    }
    let p1 = momentum(&s);
    let vbox = Vector3::from(s.physics.bodies[boxh].linvel());
    let err = (p1 - p0).norm() / p0.norm();
    println!(
        "momentum before {p0:?}, after {p1:?}: relative error {err:.2e}; box velocity {vbox:?}"
    );
    assert!(touched, "the ball never reached the box");
    assert!(err < 0.01, "momentum changed by {err}");
    assert!(vbox.x > 0.3, "the box did not move off: {vbox:?}");
    assert!(
        particles(&s, ball).center_of_mass().x < s.physics.bodies[boxh].translation().x,
        "the ball passed through the box"
    );
}
