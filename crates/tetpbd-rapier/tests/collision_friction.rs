//! Coulomb friction of a soft cube on a fixed 30° incline.

mod coupling_common;

use coupling_common::{particles, scene, spawn_with};
use nalgebra::{Rotation3, Vector3};
use rapier3d::math::{Pose, Rotation, Vector};
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder};
use tetpbd::generators::{self, CellSplit};
use tetpbd::SoftBodyBuilder;
use tetpbd_rapier::{CoupledWorld, SoftColliderBuilder};

const THETA: f32 = std::f32::consts::PI / 6.0;
const G: f32 = 9.81;

/// A 4 m-long incline at 30° with friction `mu` and a 0.2 m soft cube (friction `mu`) on
/// its upper end, resting on the surface. Returns the scene, the cube and the downhill unit
/// vector.
fn incline(mu: f32) -> (CoupledWorld, hecs::Entity, Vector3<f32>) {
    let mut s = scene(10);
    let rot = Rotation3::from_axis_angle(&Vector3::z_axis(), THETA);
    let normal = rot * Vector3::y();
    let downhill = -(rot * Vector3::x());
    let centre = rot * Vector3::new(0.0, -0.5, 0.0);
    s.physics.insert(
        RigidBodyBuilder::fixed().pose(Pose::from_parts(
            Vector::new(centre.x, centre.y, centre.z),
            Rotation::from_rotation_z(THETA),
        )),
        ColliderBuilder::cuboid(4.0, 0.5, 1.0).friction(mu),
    );
    let size = 0.2;
    let mut mesh =
        generators::box_grid(Vector3::repeat(size), [2, 2, 2], CellSplit::Six).expect("mesh");
    let start = -downhill * 3.0 + normal * (size / 2.0 + 0.0025);
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

fn downhill_velocity(s: &CoupledWorld, e: hecs::Entity, d: &Vector3<f32>) -> f32 {
    let p = particles(s, e);
    p.linear_momentum().dot(d) / p.total_mass()
}

#[test]
fn sticks_with_high_friction() {
    let (mut s, e, d) = incline(0.8);
    let x0 = particles(&s, e).center_of_mass();
    for _ in 0..120 {
        s.step().expect("step");
    }
    let moved = (particles(&s, e).center_of_mass() - x0).dot(&d);
    let v = downhill_velocity(&s, e, &d);
    println!("mu 0.8: moved {moved:.5} m downhill in 2 s, v {v:.5} m/s");
    assert!(moved.abs() < 0.01, "slid {moved} m");
    assert!(v.abs() < 0.01, "sliding at {v} m/s");
}

#[test]
fn slides_with_coulomb_acceleration() {
    let mu = 0.1;
    let (mut s, e, d) = incline(mu);
    let dt = s.physics.integration_parameters.dt;
    for _ in 0..30 {
        s.step().expect("step");
    }
    let v1 = downhill_velocity(&s, e, &d);
    for _ in 0..60 {
        s.step().expect("step");
    }
    let v2 = downhill_velocity(&s, e, &d);
    let a = (v2 - v1) / (60.0 * dt);
    let expected = G * (THETA.sin() - mu * THETA.cos());
    println!("mu 0.1: a = {a:.4} m/s², expected {expected:.4} m/s²");
    assert!(
        (a - expected).abs() < 0.1 * expected,
        "acceleration {a} vs {expected}"
    );
}
