//! Extreme mass ratios between soft and rigid bodies.

mod coupling_common;

use coupling_common::{
    ground, inverted, particles, run, scene, scene_with, soft_box, soft_box_with_density,
};
use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder};
use tetpbd_rapier::SoftCollider;

/// A 1000 kg rigid box resting on a 1 kg soft slab lying on the ground. Gauss–Seidel needs
/// a few iterations per substep to carry a mass ratio of 1000 through the slab.
#[test]
fn heavy_box_on_light_slab() {
    let mut s = scene_with(20, 5);
    // Particles squeezed between the box and the ground get large position corrections;
    // the core's safety net keeps those from turning into velocity spikes.
    s.coupling.solver_mut().settings.max_correction_speed = Some(1.0);
    ground(&mut s);
    let size = Vector3::new(0.6, 0.1, 0.6);
    // 1 kg slab: density 1 kg / 0.036 m³.
    let volume = size.x * size.y * size.z;
    let slab = soft_box_with_density(
        &mut s,
        size,
        [3, 1, 3],
        Vector3::new(0.0, 0.05 + 0.003, 0.0),
        1.0 / volume,
        SoftCollider::default(),
    );
    assert!((particles(&s, slab).total_mass() - 1.0).abs() < 1e-3);
    let half = 0.2;
    let (boxh, _) = s.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vector::new(0.0, 0.1 + half + 0.01, 0.0)),
        ColliderBuilder::cuboid(half, half, half).mass(1000.0),
    );
    let mut violent = 0.0f32;
    for f in 0..120 {
        s.step().expect("step");
        if f >= 60 {
            violent = violent.max(particles(&s, slab).max_speed());
        }
    }
    let y = s.physics.bodies[boxh].translation().y;
    let p = particles(&s, slab);
    println!(
        "box bottom at {:.4} m (slab top at rest 0.1 m), slab max |v| over the last second \
         {violent:.4} m/s, inverted {}",
        y - half,
        inverted(&s, slab)
    );
    assert!(
        y - half > 0.08,
        "the box sank into the slab to {}",
        y - half
    );
    assert!(
        p.positions().iter().all(|x| x.norm() < 2.0),
        "slab exploded"
    );
    assert!(violent < 1.0, "slab violent: {violent} m/s");
    let (lo, hi) = p.aabb();
    assert!(
        lo.x > -0.35 && lo.z > -0.35 && hi.x < 0.35 && hi.z < 0.35 && lo.y > -0.005 && hi.y < 0.11,
        "slab out of place: {lo:?} .. {hi:?}"
    );
    let vbox = s.physics.bodies[boxh].linvel().length();
    assert!(vbox < 0.3, "box moving at {vbox} m/s");
    assert_eq!(inverted(&s, slab), 0, "inverted tetrahedra");
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
