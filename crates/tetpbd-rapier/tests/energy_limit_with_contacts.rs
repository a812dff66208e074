//! With `SafetySettings::limit_correction_energy` on, a contact's push counts as external
//! work: bodies resting on ground shapes come to rest and slide at Coulomb's rate, across
//! sizes and substep counts.

mod coupling_common;

use coupling_common::{ground, particles, soft_box, spawn_with};
use nalgebra::{Rotation3, Vector3};
use rapier3d::math::{Pose, Rotation, Vector};
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder};
use tetpbd::generators::{self, CellSplit};
use tetpbd::{SoftBodyBuilder, SolverSettings};
use tetpbd_rapier::{CoupledWorld, CouplingSettings, SoftCollider, SoftColliderBuilder};

fn limited_scene(substeps: u32) -> CoupledWorld {
    let solver = SolverSettings {
        substeps,
        safety: tetpbd::SafetySettings {
            limit_correction_energy: true,
            ..Default::default()
        },
        ..SolverSettings::default()
    };
    CoupledWorld::new(solver, CouplingSettings::default()).expect("valid settings")
}

#[test]
fn bodies_resting_on_the_ground_are_still_with_the_energy_limit_on() {
    for &substeps in &[5u32, 10, 20] {
        for &size in &[0.2f32, 0.5, 1.0] {
            let mut s = limited_scene(substeps);
            ground(&mut s);
            let e = soft_box(
                &mut s,
                Vector3::repeat(size),
                [2, 2, 2],
                Vector3::new(0.0, size / 2.0 + 0.05, 0.0),
                SoftCollider::default(),
            );
            // Watched awake: sleeping would zero the motion this test measures.
            s.soft
                .insert_one(e, tetpbd::Activation::never_sleeps())
                .expect("entity");
            let mut limited = 0;
            for _ in 0..150 {
                limited += s.step().expect("step").soft.energy_limited;
            }
            let v = particles(&s, e).max_speed();
            println!("{substeps} substeps, {size} m: max|v| {v:.5} m/s, limited {limited}");
            assert!(v < 0.01, "{substeps} substeps, {size} m: moving at {v} m/s");
        }
    }
}

/// A 0.2 m soft cube on a fixed 30° incline with friction `mu`; returns its downhill
/// acceleration over frames 30–90, m/s².
fn incline_acceleration(mu: f32, substeps: u32) -> f32 {
    let theta = std::f32::consts::PI / 6.0;
    let mut s = limited_scene(substeps);
    let rot = Rotation3::from_axis_angle(&Vector3::z_axis(), theta);
    let (normal, downhill) = (rot * Vector3::y(), -(rot * Vector3::x()));
    let centre = rot * Vector3::new(0.0, -0.5, 0.0);
    s.physics.insert(
        RigidBodyBuilder::fixed().pose(Pose::from_parts(
            Vector::new(centre.x, centre.y, centre.z),
            Rotation::from_rotation_z(theta),
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
    let velocity = |s: &CoupledWorld| {
        let p = particles(s, e);
        p.linear_momentum().dot(&downhill) / p.total_mass()
    };
    for _ in 0..30 {
        s.step().expect("step");
    }
    let v1 = velocity(&s);
    for _ in 0..60 {
        s.step().expect("step");
    }
    (velocity(&s) - v1) / (60.0 * s.physics.integration_parameters.dt)
}

#[test]
fn bodies_slide_at_coulombs_rate_with_the_energy_limit_on() {
    let theta = std::f32::consts::PI / 6.0;
    for &substeps in &[5u32, 10, 20] {
        for &mu in &[0.1f32, 0.3] {
            let a = incline_acceleration(mu, substeps);
            let expected = 9.81 * (theta.sin() - mu * theta.cos());
            println!("{substeps} substeps, mu {mu}: a {a:.3} m/s², expected {expected:.3}");
            assert!(
                (a - expected).abs() < 0.1 * expected,
                "{substeps} substeps, mu {mu}: a {a} m/s², expected {expected}"
            );
        }
    }
}
