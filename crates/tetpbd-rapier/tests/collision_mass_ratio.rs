//! Extreme mass ratios between soft and rigid bodies.

mod coupling_common;

use coupling_common::{
    ground, inverted, particles, run, scene, soft_box, soft_box_of, soft_box_with_density, Families,
};
use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder};
use tetpbd_rapier::SoftCollider;

/// The constraint configurations of the stability matrix: a label and the families.
const CONFIGS: [(&str, Families); 6] = [
    ("edges+volume, α=0", (Some(0.0), None, Some(0.0))),
    ("edges+volume, soft", (Some(1e-6), None, Some(1e-9))),
    ("vertex-face, α=0", (None, Some(0.0), None)),
    ("vertex-face, soft", (None, Some(1e-6), None)),
    ("vertex-face+edges, α=0", (Some(0.0), Some(0.0), None)),
    ("vertex-face+edges, soft", (Some(1e-6), Some(1e-6), None)),
];

/// A 1000 kg rigid box dropped from 7 mm onto a 1 kg soft slab (0.6 × 0.1 × 0.6 m, one
/// cell thick) lying on the ground, at the default settings (10 substeps × 1 iteration, no
/// safety net), under every constraint configuration. One Gauss–Seidel iteration alone
/// lets the box crush the slab; the coupling's stacking pass (`StackingSettings::
/// mass_ratio`) carries it.
#[test]
fn heavy_box_on_light_slab() {
    for (label, families) in CONFIGS {
        let mut s = scene(10);
        ground(&mut s);
        let size = Vector3::new(0.6, 0.1, 0.6);
        // 1 kg slab: density 1 kg / 0.036 m³, its lower surface 3 mm above the ground.
        let slab = soft_box_of(
            &mut s,
            (size, [3, 1, 3]),
            Vector3::new(0.0, 0.05 + 0.003, 0.0),
            1.0 / (size.x * size.y * size.z),
            families,
            SoftCollider::default(),
        );
        assert!((particles(&s, slab).total_mass() - 1.0).abs() < 1e-3);
        let half = 0.2;
        let (boxh, _) = s.physics.insert(
            RigidBodyBuilder::dynamic().translation(Vector::new(0.0, 0.103 + half + 0.007, 0.0)),
            ColliderBuilder::cuboid(half, half, half).mass(1000.0),
        );
        let (mut peak, mut late, mut lowest, mut passes) = (0.0f32, 0.0f32, f32::INFINITY, 0);
        for f in 0..120 {
            let stats = s.step().expect("step");
            assert_eq!(stats.soft.non_finite_resets, 0, "{label}");
            passes += stats.stacking_passes;
            let p = particles(&s, slab);
            peak = peak.max(p.max_speed());
            if f >= 60 {
                late = late.max(p.max_speed());
            }
            lowest = lowest.min(s.physics.bodies[boxh].translation().y - half);
        }
        let bottom = s.physics.bodies[boxh].translation().y - half;
        let vbox = s.physics.bodies[boxh].linvel().length();
        let p = particles(&s, slab);
        let (lo, hi) = p.aabb();
        println!(
            "{label}: box bottom {bottom:.4} m (lowest {lowest:.4}; slab top at rest 0.103 m), \
             box |v| {vbox:.4} m/s, slab peak |v| {peak:.3} m/s, over the last second \
             {late:.4} m/s, slab y {:.4}..{:.4}, inverted {}, stacking passes {passes}",
            lo.y,
            hi.y,
            inverted(&s, slab)
        );
        // Not sunk: the box stays on the slab, which is barely compressed (its lower surface
        // is at 3 mm, its top at 0.103 m; 1 cm of tolerance).
        assert!(
            lowest > 0.09,
            "{label}: the box sank into the slab to {lowest}"
        );
        // Not thrown off or exploded.
        assert!(bottom < 0.12, "{label}: the box was thrown up to {bottom}");
        assert!(peak < 0.5, "{label}: slab peak speed {peak} m/s");
        assert!(late < 0.01, "{label}: slab still moving at {late} m/s");
        assert!(vbox < 0.01, "{label}: box moving at {vbox} m/s");
        assert!(
            lo.x > -0.35
                && lo.z > -0.35
                && hi.x < 0.35
                && hi.z < 0.35
                && lo.y > -0.001
                && hi.y < 0.11,
            "{label}: slab out of place: {lo:?} .. {hi:?}"
        );
        assert_eq!(inverted(&s, slab), 0, "{label}: inverted tetrahedra");
        assert!(passes > 0, "{label}: the stacking pass never ran");
    }
}

/// The same scene with the stacking pass turned off (`stacking: None`): one
/// iteration per substep does not carry the box, which crushes the slab. Shows that the
/// pass, not the scene, holds the box in `heavy_box_on_light_slab`.
#[test]
fn without_the_stacking_pass_the_box_sinks() {
    let mut s = scene(10);
    s.coupling.settings_mut().stacking = None;
    ground(&mut s);
    let size = Vector3::new(0.6, 0.1, 0.6);
    let slab = soft_box_with_density(
        &mut s,
        size,
        [3, 1, 3],
        Vector3::new(0.0, 0.05 + 0.003, 0.0),
        1.0 / (size.x * size.y * size.z),
        SoftCollider::default(),
    );
    let half = 0.2;
    let (boxh, _) = s.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vector::new(0.0, 0.103 + half + 0.007, 0.0)),
        ColliderBuilder::cuboid(half, half, half).mass(1000.0),
    );
    let mut passes = 0;
    for _ in 0..120 {
        passes += s.step().expect("step").stacking_passes;
    }
    let bottom = s.physics.bodies[boxh].translation().y - half;
    println!("without the pass: box bottom {bottom:.4} m");
    assert_eq!(passes, 0);
    // Well below where the pass holds it (above 0.09 m, `heavy_box_on_light_slab`): the
    // slab is crushed to about half its thickness.
    assert!(
        bottom < 0.07,
        "the box stayed up at {bottom} without the pass"
    );
    let _ = particles(&s, slab);
}

/// A 1 kg soft cube resting on a free 1000 kg plank lying on the ground.
#[test]
fn light_soft_on_heavy_plank() {
    let mut s = scene(10);
    ground(&mut s);
    let (plank, _) = s.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vector::new(0.0, 0.05, 0.0)),
        ColliderBuilder::cuboid(1.0, 0.05, 0.5).mass(1000.0),
    );
    let e = soft_box(
        &mut s,
        Vector3::repeat(0.1),
        [2, 2, 2],
        Vector3::new(0.0, 0.1 + 0.05 + 0.01, 0.0),
        SoftCollider::default(),
    );
    assert!((particles(&s, e).total_mass() - 1.0).abs() < 1e-3);
    let pen = run(&mut s, 180, 30);
    let p = particles(&s, e);
    let plank_y = s.physics.bodies[plank].translation().y;
    println!(
        "soft |v| {:.5} m/s, lowest {:.4} m, penetration {pen:.6} m, plank at {plank_y:.4} m",
        p.max_speed(),
        p.aabb().0.y
    );
    assert!(p.max_speed() < 0.01);
    assert!(pen < 0.01 * 0.05);
    assert!((plank_y - 0.05).abs() < 0.005, "plank moved to {plank_y}");
    assert!(p.aabb().0.y > 0.095, "soft body sank into the plank");
}
