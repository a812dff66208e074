//! Rest at default settings: a soft cube held by static friction on a 20° incline (μ = 0.5)
//! does not creep, and falls asleep there; a sleeping cube on the incline stays exactly put.

mod coupling_common;

use coupling_common::{particles, scene, spawn_with};
use nalgebra::{Rotation3, Vector3};
use rapier3d::math::{Pose, Rotation, Vector};
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder};
use tetpbd::generators::{self, CellSplit};
use tetpbd::{is_sleeping, Activation, SoftBodyBuilder};
use tetpbd_rapier::{CoupledWorld, SoftColliderBuilder};

/// A fixed incline at `theta` (rad) with friction `mu` and a soft cube of edge `size` (m,
/// 4³ cells, friction `mu`) resting on it. Returns the scene, the cube and the downhill unit
/// vector.
fn incline(theta: f32, mu: f32, size: f32) -> (CoupledWorld, hecs::Entity, Vector3<f32>) {
    let mut s = scene(10);
    let rot = Rotation3::from_axis_angle(&Vector3::z_axis(), theta);
    let normal = rot * Vector3::y();
    let downhill = -(rot * Vector3::x());
    let centre = rot * Vector3::new(0.0, -0.5, 0.0);
    s.physics.insert(
        RigidBodyBuilder::fixed().pose(Pose::from_parts(
            Vector::new(centre.x, centre.y, centre.z),
            Rotation::from_rotation_z(theta),
        )),
        ColliderBuilder::cuboid(4.0, 0.5, 1.0).friction(mu),
    );
    let mut mesh =
        generators::box_grid(Vector3::repeat(size), [4, 4, 4], CellSplit::Six).expect("mesh");
    let start = normal * (size / 2.0 + 0.0025);
    for v in &mut mesh.vertices {
        *v = rot * *v + start;
    }
    let body = SoftBodyBuilder::new(mesh)
        .density(1000.0)
        .edges(0.0)
        .volume(0.0);
    let e = spawn_with(&mut s, body, SoftColliderBuilder::new().friction(mu));
    (s, e, downhill)
}

/// Downhill travel of the centre of mass from second 2 to second 12 (m), and whether the
/// cube was asleep at the end.
fn creep(theta_deg: f32, mu: f32, size: f32, can_sleep: bool) -> (f32, bool) {
    let (mut s, e, d) = incline(theta_deg.to_radians(), mu, size);
    if !can_sleep {
        *s.soft.get::<&mut Activation>(e).expect("body") = Activation::never_sleeps();
    }
    for _ in 0..120 {
        s.step().expect("step");
    }
    let x0 = particles(&s, e).center_of_mass();
    for _ in 0..600 {
        s.step().expect("step");
    }
    let x1 = particles(&s, e).center_of_mass();
    ((x1 - x0).dot(&d), is_sleeping(&s.soft, e))
}

#[test]
fn static_friction_holds_a_soft_cube_on_a_20_degree_incline() {
    for size in [0.2, 0.5] {
        let (moved, asleep) = creep(20.0, 0.5, size, true);
        let (awake_moved, _) = creep(20.0, 0.5, size, false);
        println!(
            "{size} m cube, 20°, μ 0.5: crept {:.3} mm in 10 s (sleeping on: asleep {asleep}), \
             {:.3} mm never sleeping",
            moved * 1e3,
            awake_moved * 1e3
        );
        assert!(moved.abs() < 1e-3, "{size} m: crept {moved} m");
        // Awake, the hold is friction's alone (sleeping would freeze a slow creep).
        assert!(
            awake_moved.abs() < 1e-3,
            "{size} m: crept {awake_moved} m never sleeping"
        );
        assert!(asleep, "{size} m: held by friction, the cube falls asleep");
    }
}
