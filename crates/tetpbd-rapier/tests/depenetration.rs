//! A soft body overlapping a collider is pushed out at most at
//! `CouplingSettings::max_depenetration_speed`, in any frame, and does not keep that speed:
//! it ends resting where it belongs instead of hopping.

mod robust_common;

use nalgebra::Vector3;
use robust_common::{com, ground, particles, scene_substeps, soft_box};
use tetpbd::{Particles, Surface};
use tetpbd_rapier::CoupledWorld;

/// Steps `frames` frames; returns the largest upward speed of `e`'s centre of mass, the
/// highest its lowest particle rose above the ground once out of it (m), and its lowest
/// particle at the end (m).
fn watch(s: &mut CoupledWorld, e: hecs::Entity, frames: usize) -> (f32, f32, f32) {
    let (mut rise, mut hop) = (0.0f32, 0.0f32);
    for f in 0..frames {
        let stats = s.step().expect("step");
        assert_eq!(stats.soft.non_finite_resets, 0, "frame {f}");
        rise = rise.max(com(s, e).1.y);
        hop = hop.max(particles(s, e).aabb().0.y);
    }
    (rise, hop, particles(s, e).aabb().0.y)
}

fn check(what: &str, (rise, hop, lowest): (f32, f32, f32), bound: f32) {
    assert!(
        rise <= bound,
        "{what}: centre of mass rose at {rise} m/s, bound {bound}"
    );
    // Resting height: the 2 mm contact thickness, plus a little.
    assert!(hop < 0.01, "{what}: hopped {hop} m above the ground");
    assert!(lowest > -0.005, "{what}: still {lowest} m in the ground");
}

#[test]
fn bodies_created_inside_the_ground_rise_at_bounded_speed_and_do_not_hop() {
    for depth in [0.005f32, 0.02, 0.05, 0.1, 0.2] {
        for (size, cells) in [(0.3f32, 2u32), (0.5, 3), (1.0, 4)] {
            let mut s = scene_substeps(10);
            ground(&mut s);
            let bound = s.coupling.settings().max_depenetration_speed;
            let at = Vector3::new(0.0, size / 2.0 - depth, 0.0);
            let e = soft_box(
                &mut s,
                Vector3::repeat(size),
                [cells; 3],
                at,
                Vector3::zeros(),
                1000.0,
            );
            let what = format!("{size} m cube, {cells}³ cells, {depth} m deep");
            check(&what, watch(&mut s, e, 120), bound);
        }
    }
}

#[test]
fn the_bound_holds_at_other_substep_counts_and_speeds() {
    for substeps in [4u32, 20, 40] {
        for speed in [0.5f32, 2.0, 8.0] {
            let mut s = scene_substeps(substeps);
            s.coupling.settings_mut().max_depenetration_speed = speed;
            ground(&mut s);
            let at = Vector3::new(0.0, 0.25 - 0.1, 0.0);
            let e = soft_box(
                &mut s,
                Vector3::repeat(0.5),
                [3; 3],
                at,
                Vector3::zeros(),
                1000.0,
            );
            let what = format!("{substeps} substeps, {speed} m/s");
            // 0.1 m at 0.5 m/s takes 0.2 s; 3 s leaves room to settle.
            check(&what, watch(&mut s, e, 180), speed);
        }
    }
}

#[test]
fn a_body_moved_into_the_ground_later_is_pushed_out_at_bounded_speed() {
    for depth in [0.05f32, 0.15] {
        let mut s = scene_substeps(10);
        ground(&mut s);
        let bound = s.coupling.settings().max_depenetration_speed;
        let at = Vector3::new(0.0, 0.252, 0.0);
        let e = soft_box(
            &mut s,
            Vector3::repeat(0.5),
            [3; 3],
            at,
            Vector3::zeros(),
            1000.0,
        );
        watch(&mut s, e, 60);
        {
            let mut p = s.soft.get::<&mut Particles>(e).expect("soft body");
            for i in 0..p.len() {
                let x = p.positions()[i] - Vector3::new(0.0, depth, 0.0);
                p.set_position(i, x).expect("finite");
            }
        }
        check(
            &format!("moved {depth} m down"),
            watch(&mut s, e, 120),
            bound,
        );
    }
}

#[test]
fn a_body_without_surface_is_counted_and_recovers_when_it_gets_it_back() {
    let mut s = scene_substeps(10);
    ground(&mut s);
    let bound = s.coupling.settings().max_depenetration_speed;
    let at = Vector3::new(0.0, 0.252, 0.0);
    let e = soft_box(
        &mut s,
        Vector3::repeat(0.5),
        [3; 3],
        at,
        Vector3::zeros(),
        1000.0,
    );
    watch(&mut s, e, 30);
    let surface = s.soft.remove_one::<Surface>(e).expect("surface");
    for _ in 0..10 {
        let stats = s.step().expect("step");
        assert_eq!(stats.bodies_without_surface, 1, "the fall is counted");
    }
    let lowest = particles(&s, e).aabb().0.y;
    assert!(lowest < -0.05, "without a surface it falls: {lowest}");
    s.soft.insert_one(e, surface).expect("entity");
    let stats = s.step().expect("step");
    assert_eq!(stats.bodies_without_surface, 0);
    check("surface given back", watch(&mut s, e, 120), bound);
}
