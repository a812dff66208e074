//! Two soft cubes stacked on a pinned soft slab come to rest without interpenetrating.
//!
//! 20 substeps: with 10 substeps of one iteration the stiff cubes themselves keep a
//! ~0.03 m/s wobble when stacked (under-converged elasticity, not the contacts).

mod soft_soft_common;

use nalgebra::Vector3;
use soft_soft_common::{pinned_slab, soft_box, Scene};

#[test]
fn two_cubes_rest_on_a_soft_slab() {
    let mut s = Scene::new(20);
    let slab = pinned_slab(&mut s.world, Vector3::new(1.6, 0.2, 1.6), [4, 1, 4], 0.0);
    let size = 0.4;
    let low = soft_box(
        &mut s.world,
        Vector3::repeat(size),
        [3, 3, 3],
        Vector3::new(0.0, 0.25, 0.0),
        0.0,
    );
    let high = soft_box(
        &mut s.world,
        Vector3::repeat(size),
        [3, 3, 3],
        Vector3::new(0.05, 0.75, 0.03),
        0.0,
    );
    let bodies = [slab, low, high];
    let mut worst_pen = 0.0f32;
    let mut stats_pen = 0.0f32;
    let mut tail_speed = 0.0f32;
    for f in 0..180 {
        let (_, c) = s.step();
        if f >= 150 {
            tail_speed = tail_speed.max(s.max_speed());
        }
        worst_pen = worst_pen.max(s.max_interpenetration(&bodies));
        stats_pen = stats_pen.max(c.max_penetration);
        if f % 30 == 29 {
            println!(
                "t {:.1} s: max|v| {:.4} m/s, contacts {}, candidates {}, pairs {}, pen {:.5} m, clamps {}",
                (f + 1) as f32 / 60.0,
                s.max_speed(),
                c.contacts,
                c.candidates,
                c.body_pairs,
                c.max_penetration,
                c.clamps
            );
        }
    }
    let v = tail_speed;
    let y_low = s.particles(low).center_of_mass().y;
    let y_high = s.particles(high).center_of_mass().y;
    println!("rest (max over the last 0.5 s): max|v| {v:.5} m/s, centres {y_low:.4} / {y_high:.4} m, worst interpenetration {worst_pen:.5} m, stats pen {stats_pen:.5} m");
    assert!(v < 0.02, "still moving: {v} m/s");
    assert!(worst_pen < 0.002, "interpenetration {worst_pen} m");
    // Resting on each other (thickness 5 mm): centres one cube size apart, the low cube on
    // the slab.
    assert!((y_low - 0.2).abs() < 0.03, "low cube at {y_low} m");
    assert!(
        (y_high - y_low - size).abs() < 0.03,
        "high cube at {y_high} m"
    );
}
