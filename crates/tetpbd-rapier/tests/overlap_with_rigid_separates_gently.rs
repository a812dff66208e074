//! A soft body created half inside a rigid body separates at a bounded speed: pre-existing
//! penetration is pushed out at most `CouplingSettings::max_depenetration_speed` per
//! substep (the whole overlap resolved within one substep would become velocity).

mod coupling_common;

use coupling_common::{particles, scene};
use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder};
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{SoftBodyBuilder, SolverSettings};
use tetpbd_rapier::{CoupledWorld, CouplingError, CouplingSettings, SoftCollider};

/// Peak particle speed and final lowest particle of a 1 m cube created half inside a 4 m
/// thick ground, with the given depenetration speed.
fn half_buried(max_depenetration_speed: f32) -> (f32, f32) {
    let mut s = scene(10);
    s.coupling.settings_mut().max_depenetration_speed = max_depenetration_speed;
    s.physics.insert(
        RigidBodyBuilder::fixed().translation(Vector::new(0.0, -2.0, 0.0)),
        ColliderBuilder::cuboid(20.0, 2.0, 20.0),
    );
    let mesh = box_grid(Vector3::repeat(1.0), [3, 3, 3], CellSplit::Six).unwrap();
    let e = SoftBodyBuilder::new(mesh)
        .edges(0.0)
        .volume(0.0)
        .build()
        .unwrap()
        .spawn(&mut s.soft);
    s.soft.insert_one(e, SoftCollider::default()).unwrap();
    let mut peak = 0.0f32;
    for _ in 0..180 {
        let stats = s.step().unwrap();
        assert_eq!(stats.soft.non_finite_resets, 0);
        peak = peak.max(particles(&s, e).max_speed());
    }
    (peak, particles(&s, e).aabb().0.y)
}

#[test]
fn half_buried_cube_separates_at_bounded_speed() {
    let (peak, lowest) = half_buried(2.0);
    assert!(peak < 5.0, "peak speed {peak} m/s");
    assert!(
        lowest > -0.01,
        "still in the ground: lowest particle at {lowest} m"
    );
}

#[test]
fn a_lower_depenetration_speed_separates_more_gently() {
    let (fast, _) = half_buried(4.0);
    let (slow, lowest) = half_buried(0.5);
    assert!(
        slow < fast,
        "0.5 m/s gave a peak of {slow} m/s, 4 m/s gave {fast} m/s"
    );
    assert!(
        lowest > -0.01,
        "3 s at 0.5 m/s pushes 1.5 m: out, lowest particle {lowest} m"
    );
}

#[test]
fn bad_depenetration_speed_is_rejected() {
    for v in [0.0, -1.0, f32::NAN, f32::INFINITY] {
        let settings = CouplingSettings {
            max_depenetration_speed: v,
            ..CouplingSettings::default()
        };
        let r = CoupledWorld::new(SolverSettings::default(), settings);
        assert!(matches!(r, Err(CouplingError::BadSetting { .. })), "{v}");
    }
}
