//! The coupling chained with soft–soft contacts: two soft cubes stacked on rigid ground.

mod coupling_common;

use coupling_common::{ground, particles, scene, soft_box};
use nalgebra::Vector3;
use tetpbd_rapier::{SoftCollider, SoftContactSettings, SoftContacts};

#[test]
fn soft_cube_rests_on_soft_cube_on_rigid_ground() {
    let mut s = scene(10);
    ground(&mut s);
    let lower = soft_box(
        &mut s,
        Vector3::repeat(0.2),
        [2, 2, 2],
        Vector3::new(0.0, 0.1025, 0.0),
        SoftCollider::default(),
    );
    let upper = soft_box(
        &mut s,
        Vector3::repeat(0.2),
        [2, 2, 2],
        Vector3::new(0.03, 0.35, 0.0),
        SoftCollider::default(),
    );
    let mut contacts = SoftContacts::new(SoftContactSettings::default()).expect("settings");
    for _ in 0..150 {
        let stats = s.step_with(&mut contacts).expect("step");
        assert_eq!(stats.soft.non_finite_resets, 0);
    }
    let (a, b) = (particles(&s, lower), particles(&s, upper));
    println!(
        "lower cube {:.4}..{:.4} m, upper cube from {:.4} m, max |v| {:.4} / {:.4} m/s",
        a.aabb().0.y,
        a.aabb().1.y,
        b.aabb().0.y,
        a.max_speed(),
        b.max_speed()
    );
    assert!(a.aabb().0.y > 0.0, "lower cube in the ground");
    assert!(
        b.aabb().0.y > a.aabb().1.y - 0.005,
        "upper cube sank into the lower one"
    );
    assert!(
        b.aabb().0.y < a.aabb().1.y + 0.02,
        "upper cube not resting on the lower one"
    );
    // How still the pile comes to rest is the soft–soft contact model's business (its own
    // tests); here both cubes must be settled on each other, not sliding or falling.
    assert!(a.max_speed() < 0.2 && b.max_speed() < 0.2);
}
