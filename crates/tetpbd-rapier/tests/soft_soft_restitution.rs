//! Restitution between soft bodies comes from their `SoftCollider`s: two soft cubes meeting
//! head-on without gravity separate at `e` times their approach speed, never faster.

mod soft_soft_common;

use hecs::Entity;
use nalgebra::Vector3;
use soft_soft_common::{soft_box, Scene};
use tetpbd::{DeformationDamping, Particles, Solver, SolverSettings};
use tetpbd_rapier::SoftColliderBuilder;

/// Velocity of a body's centre of mass, m/s.
fn com_velocity(s: &Scene, e: Entity) -> Vector3<f32> {
    let p = s.world.get::<&Particles>(e).expect("body");
    p.free_velocity().expect("free mass").0
}

/// Two cubes of 0.4 m (damped 5/s, so their own elastic recoil is small) approaching each
/// other at `approach` m/s with restitution `e` on both; returns the separation speed of
/// their centres of mass after the impact, m/s.
fn separation_speed(e: f32, approach: f32, substeps: u32) -> f32 {
    let mut s = Scene::new(substeps);
    s.solver = Solver::new(SolverSettings {
        substeps,
        gravity: Vector3::zeros(),
        ..SolverSettings::default()
    })
    .expect("settings");
    let collider = SoftColliderBuilder::new()
        .restitution(e)
        .build()
        .expect("collider");
    let size = Vector3::repeat(0.4);
    let mut bodies = Vec::new();
    for (x, v) in [(-0.25f32, 0.5 * approach), (0.25, -0.5 * approach)] {
        let b = soft_box(
            &mut s.world,
            size,
            [2, 2, 2],
            Vector3::new(x, 0.0, 0.0),
            0.0,
        );
        let damping = DeformationDamping::new(5.0).expect("damping");
        s.world.insert(b, (collider, damping)).expect("entity");
        let mut p = s.world.get::<&mut Particles>(b).expect("body");
        for vel in p.velocities_mut() {
            *vel = Vector3::new(v, 0.0, 0.0);
        }
        drop(p);
        bodies.push(b);
    }
    // The 0.1 m gap closes after 0.1 / approach s; run well past the impact.
    let frames = (60.0 * (0.1 / approach + 0.5)).ceil() as u32;
    for _ in 0..frames {
        s.step();
    }
    let (va, vb) = (com_velocity(&s, bodies[0]), com_velocity(&s, bodies[1]));
    (vb - va).x
}

#[test]
fn soft_bodies_separate_at_their_restitution_times_the_approach_speed() {
    for &approach in &[0.5f32, 1.0, 4.0] {
        for &substeps in &[10u32, 20] {
            for &e in &[0.0f32, 0.5, 1.0] {
                let out = separation_speed(e, approach, substeps);
                println!(
                    "approach {approach} m/s, {substeps} substeps, e {e}: separation {out:.3} m/s"
                );
                assert!(out.is_finite());
                // Never faster than e times the approach (no energy from the contact), and
                // with e = 0 the bodies stay together.
                assert!(
                    out <= e * approach + 0.02 * approach,
                    "e {e}, approach {approach}: separating at {out} m/s"
                );
                // The bounce is there at moderate speeds; a fast impact between stiff bodies
                // loses part of it (SoftContacts limits).
                if approach <= 1.0 {
                    assert!(
                        out >= 0.8 * e * approach - 0.02 * approach,
                        "e {e}, approach {approach}: separating at only {out} m/s"
                    );
                }
            }
        }
    }
}
