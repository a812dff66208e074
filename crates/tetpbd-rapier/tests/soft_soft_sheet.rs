//! A soft ball dropped on a pinned soft sheet stays on it, also when thrown at 20 m/s;
//! without the contacts the same ball passes through (the control).

mod soft_soft_common;

use hecs::Entity;
use nalgebra::Vector3;
use soft_soft_common::{penetration, pinned_slab, soft_ball, Scene};

const SHEET: f32 = 0.06;
const RADIUS: f32 = 0.2;

/// Sheet 2 m × 6 cm × 2 m (8×1×8 cells) with its top at y = 0, rim pinned; a ball of
/// radius 0.2 m with its lowest point `gap` m above the sheet, thrown down at `speed` m/s.
fn scene(gap: f32, speed: f32) -> (Scene, Entity, Entity) {
    let mut s = Scene::new(10);
    let sheet = pinned_slab(&mut s.world, Vector3::new(2.0, SHEET, 2.0), [8, 1, 8], 0.0);
    let ball = soft_ball(
        &mut s.world,
        RADIUS,
        3,
        Vector3::new(0.03, RADIUS + gap, -0.02),
        Vector3::new(0.0, -speed, 0.0),
    );
    (s, sheet, ball)
}

/// Runs `frames` frames; returns (the largest end-of-frame depth of a ball particle inside
/// the sheet or of a sheet particle inside the ball, m; the ball's final centre height, m;
/// the smallest height of the ball's centre above the sheet's lowest particle over the run, m).
fn run(
    mut s: Scene,
    sheet: Entity,
    ball: Entity,
    frames: usize,
    contacts: bool,
) -> (f32, f32, f32) {
    let mut pen = 0.0f32;
    let mut above = f32::INFINITY;
    for _ in 0..frames {
        if contacts {
            s.step();
        } else {
            s.step_without_contacts();
        }
        pen = pen.max(penetration(&s.world, ball, sheet).1);
        pen = pen.max(penetration(&s.world, sheet, ball).1);
        let y = s.particles(ball).center_of_mass().y;
        above = above.min(y - s.particles(sheet).aabb().0.y);
    }
    (pen, s.particles(ball).center_of_mass().y, above)
}

#[test]
fn dropped_ball_rests_on_the_sheet() {
    let (s, sheet, ball) = scene(0.3, 0.0);
    let (pen, y, above) = run(s, sheet, ball, 150, true);
    println!("drop: worst penetration {pen:.5} m, ball centre {y:.4} m, closest centre-to-sheet-bottom {above:.4} m");
    assert!(pen < 0.005, "penetration {pen} m");
    assert!(
        above > RADIUS,
        "ball centre came within {above} m of the sheet's bottom"
    );
    assert!(
        y > RADIUS * 0.8 && y < RADIUS * 1.2,
        "ball centre {y} m: not resting on the sheet"
    );
}

#[test]
fn ball_at_20_m_per_s_does_not_pass_through() {
    let (mut s, sheet, ball) = scene(0.02, 20.0);
    let mut pen = 0.0f32;
    let mut above = f32::INFINITY;
    let mut rebound = 0.0f32;
    for _ in 0..30 {
        s.step();
        pen = pen.max(penetration(&s.world, ball, sheet).1);
        pen = pen.max(penetration(&s.world, sheet, ball).1);
        let p = s.particles(ball);
        let c = p.center_of_mass();
        // Over the sheet (the ball may roll off its edge later, which is not passing through).
        if c.x.abs() < 0.8 && c.z.abs() < 0.8 {
            above = above.min(c.y - s.particles(sheet).aabb().0.y);
        }
        rebound = rebound.max(p.linear_momentum().y / p.total_mass());
    }
    println!(
        "20 m/s: worst penetration {pen:.5} m, closest centre-to-sheet-bottom {above:.4} m, \
         largest upward centre speed {rebound:.2} m/s"
    );
    assert!(pen < 0.01, "penetration {pen} m");
    // Passing through takes the centre below the sheet's lowest particle.
    assert!(
        above > 0.5 * RADIUS,
        "ball centre came within {above} m of the sheet's bottom"
    );
    // The bounce is elastic (no restitution control between soft bodies) but gains no
    // energy.
    assert!(rebound < 20.0, "rebound at {rebound} m/s");
}

#[test]
fn control_without_contacts_the_ball_passes_through() {
    let (s, sheet, ball) = scene(0.02, 20.0);
    let (_, y, _) = run(s, sheet, ball, 30, false);
    println!("control: ball centre {y:.4} m");
    assert!(y < -SHEET - RADIUS, "control ball at {y} m");
}
