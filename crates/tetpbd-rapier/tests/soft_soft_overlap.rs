//! Bodies created overlapping by half their size separate over a few frames, never faster
//! than the documented bound `max_separation_speed`.

mod soft_soft_common;

use nalgebra::Vector3;
use soft_soft_common::{penetration, pinned_slab, soft_box, Scene};

#[test]
fn half_overlap_separates_with_bounded_speed() {
    let mut s = Scene::new(10);
    s.solver.settings.gravity = Vector3::zeros();
    let bound = s.contacts.settings().max_separation_speed;
    let size = 0.4;
    let a = soft_box(
        &mut s.world,
        Vector3::repeat(size),
        [3, 3, 3],
        Vector3::zeros(),
        0.0,
    );
    let b = soft_box(
        &mut s.world,
        Vector3::repeat(size),
        [3, 3, 3],
        Vector3::new(0.5 * size, 0.013, -0.007),
        0.0,
    );
    let dt = s.solver.settings.dt;
    let mut peak = 0.0f32;
    let mut peak_rate = 0.0f32;
    let mut clamps = 0;
    let mut separated_at = None;
    let mut gap = (s.particles(b).center_of_mass() - s.particles(a).center_of_mass()).norm();
    for f in 0..120 {
        let (_, c) = s.step();
        clamps += c.clamps;
        peak = peak.max(s.max_speed());
        let g = (s.particles(b).center_of_mass() - s.particles(a).center_of_mass()).norm();
        peak_rate = peak_rate.max((g - gap) / dt);
        gap = g;
        let inside = penetration(&s.world, a, b).0 + penetration(&s.world, b, a).0;
        if f % 10 == 9 {
            println!(
                "frame {}: max|v| {:.3} m/s, centre gap {:.4} m, particles inside {inside}, deep {}, clamps {}",
                f + 1,
                s.max_speed(),
                g,
                c.deep,
                c.clamps
            );
        }
        if inside == 0 && separated_at.is_none() {
            separated_at = Some(f + 1);
        }
    }
    println!(
        "separated after {separated_at:?} frames; peak |v| {peak:.3} m/s, peak separation rate {peak_rate:.3} m/s \
         (bound {bound} m/s), clamps {clamps}"
    );
    let frames = separated_at.expect("never separated");
    assert!(frames <= 30, "took {frames} frames");
    assert!(
        clamps > 0,
        "the bound never acted: the test does not test it"
    );
    assert!(
        peak < bound,
        "peak particle speed {peak} m/s above the bound {bound} m/s"
    );
    assert!(peak_rate < bound, "centres separated at {peak_rate} m/s");
    // Apart and still: no interpenetration at the end, and no fling.
    assert_eq!(
        penetration(&s.world, a, b).0 + penetration(&s.world, b, a).0,
        0
    );
    assert!(
        s.max_speed() < 0.1 * bound,
        "still moving at {} m/s",
        s.max_speed()
    );
}

#[test]
fn cube_created_half_inside_a_pinned_slab_rises_out_and_rests() {
    let mut s = Scene::new(10);
    let bound = s.contacts.settings().max_separation_speed;
    let slab = pinned_slab(&mut s.world, Vector3::new(1.6, 0.3, 1.6), [4, 1, 4], 0.0);
    let cube = soft_box(
        &mut s.world,
        Vector3::repeat(0.4),
        [3, 3, 3],
        Vector3::new(0.03, 0.0, -0.02),
        0.0,
    );
    let dt = s.solver.settings.dt;
    let mut y = s.particles(cube).center_of_mass().y;
    let mut peak_rise = 0.0f32;
    let mut peak = 0.0f32;
    let mut out_at = None;
    for f in 0..120 {
        s.step();
        let y1 = s.particles(cube).center_of_mass().y;
        peak_rise = peak_rise.max((y1 - y) / dt);
        y = y1;
        peak = peak.max(s.max_speed());
        if out_at.is_none()
            && penetration(&s.world, cube, slab).0 + penetration(&s.world, slab, cube).0 == 0
        {
            out_at = Some(f + 1);
        }
    }
    let v = s.max_speed();
    println!(
        "out after {out_at:?} frames; peak rise {peak_rise:.3} m/s (bound {bound}), peak |v| {peak:.3} m/s, \
         final centre {y:.4} m, final max|v| {v:.4} m/s"
    );
    assert!(out_at.expect("never came out") <= 15);
    assert!(peak_rise < bound, "rose at {peak_rise} m/s");
    assert!(peak < bound, "peak particle speed {peak} m/s");
    assert!(
        (y - 0.2).abs() < 0.02,
        "not resting on the slab: centre at {y} m"
    );
    assert!(v < 0.02, "still moving at {v} m/s");
}
