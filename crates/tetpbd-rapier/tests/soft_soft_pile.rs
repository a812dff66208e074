//! Nine soft cubes (4×4×4 cells) dropped in the layout of rapier's `fem_bench` "jelly pile"
//! settle without interpenetrating or flying apart.
//!
//! The ground here is a pinned soft slab (the rigid-ground version is `soft_soft_pile_rigid`) (every particle of its bottom and sides pinned).
//! Solver: 60 Hz, 20 substeps, linear damping 1/s (the cubes are undamped elastic XPBD
//! bodies otherwise; rapier's jelly has material damping too).

mod soft_soft_common;

use nalgebra::Vector3;
use soft_soft_common::{pinned_slab, soft_box, Scene};

#[test]
fn nine_cubes_settle_on_a_pinned_slab() {
    let mut s = Scene::new(20);
    s.solver.settings.damping = 1.0;
    let slab = pinned_slab(&mut s.world, Vector3::new(8.0, 0.2, 8.0), [16, 1, 16], 0.0);
    let mut bodies = vec![slab];
    // fem_bench: 1 m cubes on a 3 × 3 grid of 1 m pitch (touching), cube i at height
    // 0.55 + 1.05 i (centre), so they land one after another side by side.
    for i in 0..9 {
        let x = (i % 3) as f32 - 1.0;
        let z = (i / 3) as f32 - 1.0;
        let at = Vector3::new(x, 0.55 + i as f32 * 1.05, z);
        bodies.push(soft_box(
            &mut s.world,
            Vector3::repeat(1.0),
            [4, 4, 4],
            at,
            0.0,
        ));
    }
    let mut tail_speed = 0.0f32;
    let mut peak_speed = 0.0f32;
    let mut worst_pen = 0.0f32;
    let mut clamps = 0;
    for f in 0..300 {
        let (_, c) = s.step();
        clamps += c.clamps;
        if f % 15 == 14 {
            worst_pen = worst_pen.max(s.max_interpenetration(&bodies));
        }
        let v = s.max_speed();
        if f >= 270 {
            tail_speed = tail_speed.max(v);
        }
        for &e in &bodies[1..] {
            let p = s.particles(e);
            peak_speed = peak_speed.max((p.linear_momentum() / p.total_mass()).norm());
        }
        if f % 60 == 59 {
            println!(
                "t {} s: max|v| {v:.4} m/s, contacts {}, pairs {}, deep {}, max penetration {:.5} m",
                (f + 1) / 60,
                c.contacts,
                c.body_pairs,
                c.deep,
                c.max_penetration
            );
        }
    }
    let pen = s.max_interpenetration(&bodies);
    println!(
        "after 5 s: max|v| over the last 0.5 s {tail_speed:.4} m/s, peak centre speed {peak_speed:.3} m/s, \
         interpenetration {pen:.5} m (worst sampled {worst_pen:.5} m), clamps {clamps}"
    );
    // At rest: max |v| < 0.05 m/s after 5 s.
    assert!(tail_speed < 0.05, "still moving at {tail_speed} m/s");
    // The highest cube hits at √(2 g 9 m) ≈ 13.3 m/s; no cube may move faster than that.
    assert!(peak_speed < 13.5, "a cube was flung at {peak_speed} m/s");
    assert!(pen < 0.002, "interpenetration {pen} m");
    assert!(
        worst_pen < 0.1,
        "interpenetration during the drop {worst_pen} m"
    );
    for &e in &bodies[1..] {
        let c = s.particles(e).center_of_mass();
        assert!(c.y > 0.4 && c.y < 1.7, "cube off the pile: centre {c:?}");
        assert!(
            c.x.abs() < 3.5 && c.z.abs() < 3.5,
            "cube off the slab: {c:?}"
        );
    }
}
