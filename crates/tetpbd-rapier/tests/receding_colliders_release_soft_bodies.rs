//! A collider moving away from a soft body it touches lets go of it: a kinematic lid lifted
//! off a soft cube resting on the ground leaves the cube on the ground, a platform sinking
//! under a soft cube lets the cube fall after it, and a pusher that stops lets the cube it
//! pushed slide on, at speeds of 0.05–2 m/s and 5–20 substeps.
//!
//! What it guards: the coupling caps a soft body's separating velocity at a contact that is
//! no impact (`response::restitution`), so that its elastic recoil never throws it off; a cap
//! on the velocity relative to a receding collider would instead drag the body along with
//! it for as long as its particles stay within the contact's thickness, which they then do
//! for ever.

mod robust_common;

use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder};
use robust_common::{com, ground, scene_substeps};
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::SoftBodyBuilder;
use tetpbd_rapier::CoupledWorld;

/// A hard 0.4 m soft cube (3³ cells) resting with its bottom at `bottom` (m).
fn cube(s: &mut CoupledWorld, bottom: f32) -> hecs::Entity {
    let mesh = box_grid(Vector3::repeat(0.4), [3; 3], CellSplit::Six).expect("mesh");
    SoftBodyBuilder::new(mesh)
        .density(500.0)
        .edges(0.0)
        .volume(0.0)
        .translation(Vector3::new(0.0, bottom + 0.2, 0.0))
        .build()
        .expect("cube")
        .spawn(&mut s.soft)
}

const SPEEDS: [f32; 3] = [0.05, 0.5, 2.0];
const SUBSTEPS: [u32; 3] = [5, 10, 20];

#[test]
fn a_lid_lifted_off_a_resting_soft_cube_leaves_it_on_the_ground() {
    for substeps in SUBSTEPS {
        for speed in SPEEDS {
            let mut s = scene_substeps(substeps);
            ground(&mut s);
            let e = cube(&mut s, 0.001);
            // The lid rests on the cube for 0.5 s, then rises.
            let (lid, _) = s.physics.insert(
                RigidBodyBuilder::kinematic_velocity_based().translation(Vector::new(
                    0.0,
                    0.402 + 0.05,
                    0.0,
                )),
                ColliderBuilder::cuboid(0.5, 0.05, 0.5),
            );
            for _ in 0..30 {
                s.step().expect("step");
            }
            s.physics.bodies[lid].set_linvel(Vector::new(0.0, speed, 0.0), true);
            let mut highest = f32::NEG_INFINITY;
            for _ in 0..60 {
                s.step().expect("step");
                highest = highest.max(com(&s, e).0.y);
            }
            let (c, v) = com(&s, e);
            println!(
                "{substeps} substeps, lid at {speed} m/s: cube centre highest {highest:.4} m, \
                 at the end {:.4} m, {:.4} m/s",
                c.y, v.y
            );
            assert!(
                highest < 0.2 + 0.01,
                "{substeps} substeps, {speed} m/s: the lid carried the cube up to {highest} m"
            );
        }
    }
}

#[test]
fn a_sinking_platform_lets_a_soft_cube_fall_after_it() {
    for substeps in SUBSTEPS {
        for speed in SPEEDS {
            let mut s = scene_substeps(substeps);
            let (platform, _) = s.physics.insert(
                RigidBodyBuilder::kinematic_velocity_based()
                    .translation(Vector::new(0.0, -0.05, 0.0)),
                ColliderBuilder::cuboid(1.0, 0.05, 1.0),
            );
            let e = cube(&mut s, 0.001);
            for _ in 0..30 {
                s.step().expect("step");
            }
            s.physics.bodies[platform].set_linvel(Vector::new(0.0, -speed, 0.0), true);
            for _ in 0..30 {
                s.step().expect("step");
            }
            let (c, v) = com(&s, e);
            let top = s.physics.bodies[platform].translation().y + 0.05;
            // Falling after a platform slower than gravity would bring it, the cube rides on it;
            // the cube never lags above it by more than a free fall from rest would.
            let gap = c.y - 0.2 - top;
            println!(
                "{substeps} substeps, platform at {speed} m/s: cube {gap:.4} m above it, \
                 falling at {:.3} m/s",
                -v.y
            );
            assert!(
                gap < 0.02,
                "{substeps} substeps, {speed} m/s: cube held {gap} m up"
            );
            assert!(
                v.y < 0.0,
                "{substeps} substeps, {speed} m/s: the cube does not fall"
            );
        }
    }
}

/// A kinematic wall pushes the cube along the ground for 0.5 s, then stops.
#[test]
fn a_pusher_that_stops_lets_the_soft_cube_slide_on() {
    for substeps in SUBSTEPS {
        for speed in [0.5f32, 1.0, 2.0] {
            let mut s = scene_substeps(substeps);
            ground(&mut s);
            let e = cube(&mut s, 0.001);
            let (pusher, _) = s.physics.insert(
                RigidBodyBuilder::kinematic_velocity_based()
                    .translation(Vector::new(-0.2 - 0.05 - 0.001, 0.25, 0.0))
                    .linvel(Vector::new(speed, 0.0, 0.0)),
                ColliderBuilder::cuboid(0.05, 0.25, 0.5),
            );
            for _ in 0..30 {
                s.step().expect("step");
            }
            let (c0, v0) = com(&s, e);
            s.physics.bodies[pusher].set_linvel(Vector::new(0.0, 0.0, 0.0), true);
            for _ in 0..60 {
                s.step().expect("step");
            }
            let (c, _) = com(&s, e);
            let slid = c.x - c0.x;
            // Sliding on under friction 0.5 from v0: v0² / (2 · 0.5 g).
            let free = v0.x * v0.x / 9.81;
            println!(
                "{substeps} substeps, {speed} m/s: cube at {:.3} m/s when the pusher stopped, \
                 slid {slid:.4} m after (friction alone: {free:.4} m)",
                v0.x
            );
            assert!(
                slid > 0.5 * free,
                "{substeps} substeps, {speed} m/s: held back by the pusher ({slid} m of {free} m)"
            );
        }
    }
}
