//! Attachments: soft particles held to rigid bodies (two-way) and to kinematic targets.

mod coupling_common;

use coupling_common::{particles, scene};
use hecs::Entity;
use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{ColliderBuilder, RevoluteJointBuilder, RigidBodyBuilder, RigidBodyHandle};
use tetpbd::generators::{self, CellSplit};
use tetpbd::{Particles, SoftBodyBuilder, SolverSettings};
use tetpbd_rapier::{Attachments, CoupledWorld, CouplingError, CouplingSettings};

/// A 0.6 m beam along +x from `root`, 6×1×1 cells, 0.1 m wide, `density` kg/m³, its root
/// face attached to `body` with compliance 0.
fn beam_on(
    s: &mut CoupledWorld,
    root: Vector3<f32>,
    body: RigidBodyHandle,
    density: f32,
) -> Entity {
    let mesh = generators::beam(0.6, 0.1, 6, 1, CellSplit::Six).expect("mesh");
    let roots = generators::beam_root(&mesh);
    let b = SoftBodyBuilder::new(mesh)
        .density(density)
        .edges(0.0)
        .volume(0.0)
        .translation(root)
        .build()
        .expect("body");
    let mut att = Attachments::new();
    for &i in &roots {
        att.attach_to_body(&b.particles, i, &s.physics.bodies, body, 0.0)
            .expect("attach");
    }
    let e = b.spawn(&mut s.soft);
    s.soft.insert_one(e, att).expect("entity");
    e
}

/// A beam attached to a fixed body by its root face hangs still: the attachments hold, the
/// root does not move and the beam does not creep.
#[test]
fn hangs_from_a_fixed_body_without_drift() {
    // Velocity damping lets both beams settle instead of ringing.
    let solver = SolverSettings {
        damping: 3.0,
        ..SolverSettings::default()
    };
    let mut s = CoupledWorld::new(solver, CouplingSettings::default()).expect("settings");
    let anchor = s.physics.bodies.insert(RigidBodyBuilder::fixed());
    let e = beam_on(&mut s, Vector3::zeros(), anchor, 1000.0);
    let roots =
        generators::beam_root(&generators::beam(0.6, 0.1, 6, 1, CellSplit::Six).expect("mesh"));
    let root0: Vec<Vector3<f32>> = roots
        .iter()
        .map(|&i| particles(&s, e).positions()[i as usize])
        .collect();
    let mut worst = 0.0f32;
    let mut at_2s = Vector3::zeros();
    for f in 0..180 {
        let stats = s.step().expect("step");
        // A sleeping beam's attachments take no part (and cannot drift).
        let asleep = stats.soft.bodies_asleep == 1;
        assert_eq!(stats.attachments, if asleep { 0 } else { 4 });
        worst = worst.max(stats.max_attachment_error);
        if f == 119 {
            at_2s = particles(&s, e).center_of_mass();
        }
    }
    let p = particles(&s, e);
    let drift = (p.center_of_mass() - at_2s).norm();
    let root_drift = roots
        .iter()
        .zip(&root0)
        .map(|(&i, x0)| (p.positions()[i as usize] - x0).norm())
        .fold(0.0f32, f32::max);
    println!(
        "largest attachment error {worst:.2e} m, root drift {root_drift:.2e} m, centre drift from 2 s to 3 s \
         {drift:.2e} m, tip at y = {:.4} m",
        p.aabb().0.y
    );
    assert!(worst < 1e-4, "attachment error {worst} m");
    assert!(root_drift < 1e-4, "root drifted {root_drift} m");
    assert!(drift < 1e-3, "drifted {drift} m");
}

#[test]
fn swings_a_hinged_dynamic_body() {
    let mut s = scene(10);
    let anchor = s.physics.bodies.insert(RigidBodyBuilder::fixed());
    // A 10 kg wheel on a hinge about z through its centre, a 1.2 kg beam on its +x face.
    let (wheel, _) = s.physics.insert(
        RigidBodyBuilder::dynamic(),
        ColliderBuilder::cuboid(0.05, 0.05, 0.05).mass(10.0),
    );
    let joint = RevoluteJointBuilder::new(Vector::Z);
    s.physics.impulse_joints.insert(anchor, wheel, joint, true);
    let e = beam_on(&mut s, Vector3::new(0.05, 0.0, 0.0), wheel, 200.0);
    let mut worst = 0.0f32;
    for _ in 0..30 {
        let stats = s.step().expect("step");
        worst = worst.max(stats.max_attachment_error);
    }
    let w = Vector3::from(s.physics.bodies[wheel].angvel());
    let angle = s.physics.bodies[wheel].rotation().to_scaled_axis().z;
    let tip = particles(&s, e).aabb().0.y;
    println!("after 0.5 s: hinge angle {angle:.3} rad, ω {w:?}, attachment error {worst:.2e} m, beam low {tip:.3} m");
    assert!(angle < -0.3, "the beam did not swing the body: {angle} rad");
    assert!(w.z < -0.5, "the body does not turn: {w:?}");
    assert!(
        w.x.abs().max(w.y.abs()) < 0.1 * w.z.abs(),
        "turning off the hinge axis: {w:?}"
    );
    assert!(worst < 0.01, "attachment error {worst} m");
}

#[test]
fn momentum_is_shared_with_a_free_body() {
    let mut s = scene(10);
    s.physics.gravity = Vector::ZERO;
    let (free, _) = s.physics.insert(
        RigidBodyBuilder::dynamic(),
        ColliderBuilder::cuboid(0.05, 0.05, 0.05).density(1000.0),
    );
    let e = beam_on(&mut s, Vector3::new(0.05, 0.0, 0.0), free, 1000.0);
    {
        let mut p = s.soft.get::<&mut Particles>(e).expect("soft body");
        for i in 0..p.len() {
            p.set_velocity(i, Vector3::new(0.0, 1.0, 0.0))
                .expect("velocity");
        }
    }
    let momentum = |s: &CoupledWorld| {
        let b = &s.physics.bodies[free];
        particles(s, e).linear_momentum() + Vector3::from(b.linvel()) * b.mass()
    };
    let p0 = momentum(&s);
    for _ in 0..60 {
        s.step().expect("step");
    }
    let p1 = momentum(&s);
    let vb = Vector3::from(s.physics.bodies[free].linvel());
    let err = (p1 - p0).norm() / p0.norm();
    println!("momentum {p0:?} -> {p1:?} (relative error {err:.2e}), body velocity {vb:?}");
    assert!(err < 0.01);
    assert!(vb.y > 0.1, "the body was not pulled along");
}

#[test]
fn follows_a_kinematic_target() {
    let mut s = scene(10);
    s.physics.gravity = Vector::ZERO;
    let mesh = generators::box_grid(Vector3::repeat(0.2), [1, 1, 1], CellSplit::Six).expect("mesh");
    let b = SoftBodyBuilder::new(mesh)
        .edges(0.0)
        .volume(0.0)
        .build()
        .expect("body");
    let mut att = Attachments::new();
    let start = b.particles.positions()[0];
    let k = att
        .attach_to_point(&b.particles, 0, start, 0.0)
        .expect("attach");
    let e = b.spawn(&mut s.soft);
    s.soft.insert_one(e, att).expect("entity");
    let dt = s.physics.integration_parameters.dt;
    let mut worst = 0.0f32;
    for f in 1..=60 {
        let t = f as f32 * dt;
        let target = start + Vector3::new(0.3 * t, 0.1 * (3.0 * t).sin(), 0.0);
        s.soft
            .get::<&mut Attachments>(e)
            .expect("attachments")
            .set_target(k, target)
            .expect("target");
        s.step().expect("step");
        worst = worst.max((particles(&s, e).positions()[0] - target).norm());
    }
    println!("largest distance to the moving target {worst:.2e} m");
    assert!(worst < 1e-3);
}

#[test]
fn bad_attachments_are_rejected_or_counted() {
    let mut s = scene(10);
    let mesh = generators::box_grid(Vector3::repeat(0.2), [1, 1, 1], CellSplit::Six).expect("mesh");
    let b = SoftBodyBuilder::new(mesh).edges(0.0).build().expect("body");
    let body = s.physics.bodies.insert(RigidBodyBuilder::dynamic());
    let mut att = Attachments::new();
    assert_eq!(
        att.attach_to_body(&b.particles, 99, &s.physics.bodies, body, 0.0),
        Err(CouplingError::ParticleOutOfRange { index: 99, len: 8 })
    );
    assert!(matches!(
        att.attach_to_body(&b.particles, 0, &s.physics.bodies, body, -1.0),
        Err(CouplingError::BadCoefficient { .. })
    ));
    assert!(matches!(
        att.attach_to_point(&b.particles, 0, Vector3::new(f32::NAN, 0.0, 0.0), 0.0),
        Err(CouplingError::NonFinite { .. })
    ));
    let k = att
        .attach_to_body(&b.particles, 0, &s.physics.bodies, body, 0.0)
        .expect("attach");
    assert_eq!(
        att.set_target(k, Vector3::zeros()),
        Err(CouplingError::NotAPointTarget { index: k })
    );
    let e = b.spawn(&mut s.soft);
    s.soft.insert_one(e, att).expect("entity");
    s.step().expect("step");
    let p = &mut s.physics;
    p.bodies.remove(
        body,
        &mut p.islands,
        &mut p.colliders,
        &mut p.impulse_joints,
        &mut p.multibody_joints,
        &mut p.soft_bodies,
        true,
    );
    let removed = s.physics.bodies.insert(RigidBodyBuilder::fixed());
    let stats = s.step().expect("step");
    println!(
        "skipped attachments after removing the body: {}",
        stats.skipped_attachments
    );
    assert_eq!(stats.skipped_attachments, 1);
    assert_eq!(stats.attachments, 0);
    let mut att2 = Attachments::new();
    let p2 = particles(&s, e);
    s.physics.bodies.remove(
        removed,
        &mut s.physics.islands,
        &mut s.physics.colliders,
        &mut s.physics.impulse_joints,
        &mut s.physics.multibody_joints,
        &mut s.physics.soft_bodies,
        true,
    );
    assert_eq!(
        att2.attach_to_body(&p2, 0, &s.physics.bodies, removed, 0.0),
        Err(CouplingError::BodyNotFound { handle: removed })
    );
    assert!(p2
        .positions()
        .iter()
        .all(|x| x.iter().all(|c| c.is_finite())));
}
