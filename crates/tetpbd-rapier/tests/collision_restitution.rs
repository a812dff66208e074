//! Restitution: a soft ball bounces off rigid ground according to its setting.

mod coupling_common;

use coupling_common::{ground, min_y, scene, soft_ball, spawn_with};
use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder};
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

/// A rigid ball (restitution `e` on ball and slab) dropped from `DROP_RIGID` m onto a soft
/// slab whose bottom is glued to the ground. Returns the ball's highest rebound above its
/// resting height.
fn rigid_rebound(e: f32) -> f32 {
    let mut s = scene(10);
    ground(&mut s);
    let mesh = tetpbd::generators::box_grid(
        Vector3::new(1.0, 0.2, 1.0),
        [4, 2, 4],
        tetpbd::generators::CellSplit::Six,
    )
    .expect("mesh");
    let bottom: Vec<u32> = (0..mesh.vertices.len() as u32)
        .filter(|&i| mesh.vertices[i as usize].y < -0.1 + 1e-6)
        .collect();
    let body = tetpbd::SoftBodyBuilder::new(mesh)
        .density(1000.0)
        .edges(0.0)
        .volume(0.0)
        .pinned(bottom)
        .translation(Vector3::new(0.0, 0.1, 0.0));
    spawn_with(&mut s, body, SoftColliderBuilder::new().restitution(e));
    let r = 0.15;
    let rest = 0.2 + r + SoftCollider::DEFAULT_THICKNESS;
    let (ball, _) = s.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vector::new(0.125, rest + DROP_RIGID, 0.125)),
        ColliderBuilder::ball(r).density(1000.0).restitution(e),
    );
    let mut hit = false;
    let mut best = f32::NEG_INFINITY;
    for _ in 0..120 {
        let stats = s.step().expect("step");
        hit |= stats.contacts > 0;
        if hit {
            best = best.max(s.physics.bodies[ball].translation().y - rest);
        }
    }
    assert!(hit, "the ball never reached the slab");
    best
}

const DROP_RIGID: f32 = 0.5;

#[test]
fn rigid_ball_on_soft_slab_follows_restitution() {
    let dead = rigid_rebound(0.0);
    let e = 0.8;
    let live = rigid_rebound(e);
    let ideal = e * e * DROP_RIGID;
    println!("rigid ball on a soft slab: rebound {dead:.4} m with e = 0, {live:.4} m with e = {e} (ideal {ideal:.4} m)");
    assert!(dead < 0.02 * DROP_RIGID, "bounced {dead} m with e = 0");
    assert!(
        (live - ideal).abs() < 0.1 * ideal,
        "rebound {live} m vs {ideal} m"
    );
}
