//! Restitution: a soft ball bounces off rigid ground according to its setting.

mod coupling_common;

use coupling_common::{ground, min_y, scene, soft_ball};
use nalgebra::Vector3;
use tetpbd_rapier::{SoftCollider, SoftColliderBuilder};

const DROP: f32 = 1.0;

/// Drops a 0.2 m soft ball whose bottom starts `DROP` m above the ground, with restitution
/// `e` on both ball and ground. Returns the highest bottom height after the first impact,
/// above the height it rests at (the contact thickness).
fn rebound(e: f32) -> f32 {
    let mut s = scene(10);
    let (_, g) = ground(&mut s);
    s.physics.colliders[g].set_restitution(e);
    let collider = SoftColliderBuilder::new()
        .restitution(e)
        .build()
        .expect("collider");
    let r = 0.2;
    let ball = soft_ball(
        &mut s,
        r,
        2,
        Vector3::new(0.0, DROP + r, 0.0),
        Vector3::zeros(),
        1000.0,
        collider,
    );
    let mut hit = false;
    let mut best = 0.0f32;
    for _ in 0..150 {
        let stats = s.step().expect("step");
        if stats.contacts > 0 {
            hit = true;
        }
        if hit {
            best = best.max(min_y(&s, ball));
        }
    }
    assert!(hit, "never reached the ground");
    best - SoftCollider::DEFAULT_THICKNESS
}

#[test]
fn no_bounce_without_restitution() {
    let h = rebound(0.0);
    println!("e = 0: rebound {h:.5} m of {DROP} m");
    assert!(h < 0.01 * DROP, "bounced to {h} m");
}

#[test]
fn rebound_height_follows_restitution() {
    for e in [0.5f32, 0.8] {
        let h = rebound(e);
        let ideal = e * e * DROP;
        println!("e = {e}: rebound {h:.4} m, ideal e²·h = {ideal:.4} m");
        assert!(
            (h - ideal).abs() < 0.1 * ideal,
            "e = {e}: rebound {h} m vs {ideal} m"
        );
    }
}
