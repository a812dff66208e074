//! A heavy soft body thrown at a light dynamic box on the ground never leaves the scene with
//! more energy than it brought: whatever the speed, the angle, the mass ratio, the family or
//! the substep count, the soft body's and the box's kinetic plus gravitational energy never
//! rise above their start.
//!
//! What it guards: a box standing on the ground is as heavy as the ground for the soft bodies
//! on it only while it is at rest (`contacts::support` module docs, *Only a body at rest is
//! immovable*): squeezed out from under the body, spinning with a corner on the ground, it
//! used to keep "standing" and push the body's surface away at its own speed (a 47.5 kg body
//! thrown at 58.6 m/s onto a 0.47 kg box left at 82 m/s, +38 kJ). And a box corner found deep
//! behind a soft triangle leaves it at the depenetration speed in every substep, not only in
//! the first (`contacts::corner` module docs): crushed over a box, a 51.6 kg body thrown at
//! 40 m/s left at 109 m/s.

mod robust_common;

use nalgebra::{UnitQuaternion, Vector3};
use rapier3d::math::Vector;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder};
use robust_common::{ground, mechanical_energy, particles, scene_substeps, Draws};
use tetpbd::generators::{self, CellSplit};
use tetpbd::SoftBodyBuilder;
use tetpbd_rapier::SoftCollider;

/// One throw: returns the largest rise of the total mechanical energy over its start, as a
/// fraction of the start's kinetic energy, and a description.
fn throw(d: &mut Draws, substeps: u32) -> (f32, String) {
    let mut s = scene_substeps(substeps);
    ground(&mut s);
    let half = d.between(0.1, 0.3);
    let box_mass = d.between(0.2, 1.0);
    let (bx, _) = s.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vector::new(0.0, half, 0.0)),
        ColliderBuilder::cuboid(half, half, half).mass(box_mass),
    );
    let size = d.between(0.4, 0.8);
    let density = d.between(100.0, 1000.0);
    let speed = d.between(10.0, 60.0);
    let dir = Vector3::new(d.between(-0.6, 0.6), -1.0, d.between(-0.6, 0.6)).normalize();
    let hard_vertex_face = d.between(0.0, 1.0) < 0.5;
    let mesh =
        generators::box_grid(Vector3::repeat(size), [2, 2, 2], CellSplit::Five).expect("mesh");
    let b = SoftBodyBuilder::new(mesh)
        .density(density)
        .translation(Vector3::new(
            d.between(-0.1, 0.1),
            2.0 * half + 0.05 + 0.9 * size,
            d.between(-0.1, 0.1),
        ))
        .rotation(UnitQuaternion::from_euler_angles(
            d.between(-3.0, 3.0),
            d.between(-3.0, 3.0),
            d.between(-3.0, 3.0),
        ))
        .velocity(dir * speed);
    let b = if hard_vertex_face {
        b.edges(0.0).vertex_face(0.0)
    } else {
        b.edges(0.0).volume(0.0)
    };
    let e = b.build().expect("body").spawn(&mut s.soft);
    s.soft
        .insert_one(e, SoftCollider::default())
        .expect("entity");
    let total = |s: &tetpbd_rapier::CoupledWorld| {
        let rb = &s.physics.bodies[bx];
        mechanical_energy(&particles(s, e))
            + rb.kinetic_energy()
            + rb.mass() * 9.81 * rb.center_of_mass().y
    };
    let start = total(&s);
    let kinetic = particles(&s, e).kinetic_energy();
    let mut rise = 0.0f32;
    for _ in 0..60 {
        s.step().expect("step");
        rise = rise.max(total(&s) - start);
    }
    let what = format!(
        "{substeps} substeps, {size:.2} m body of {:.1} kg ({}) at {speed:.1} m/s onto a \
         {box_mass:.2} kg box of half {half:.2} m",
        particles(&s, e).total_mass(),
        if hard_vertex_face {
            "edges + vertex–face"
        } else {
            "edges + volume"
        }
    );
    (rise / kinetic, what)
}

/// Runs `throws` throws drawn from `seed`, cycling through `substeps`; each may raise the
/// energy by at most 2 % of the thrown kinetic energy, the throws in `known` (indices) by at
/// most 50 % (a known limit, below).
fn sweep(seed: u64, throws: usize, substeps: &[u32], known: &[usize]) {
    let mut d = Draws(seed);
    let mut gained = Vec::new();
    for i in 0..throws {
        let n = substeps[i % substeps.len()];
        let (rise, what) = throw(&mut d, n);
        println!("throw {i}, {what}: energy rise {rise:.2e} of the kinetic energy");
        let limit = if known.contains(&i) { 0.5 } else { 0.02 };
        if rise.is_nan() || rise > limit {
            gained.push(format!("throw {i}, {what}: +{:.1} %", 100.0 * rise));
        }
    }
    assert!(gained.is_empty(), "gained energy: {gained:#?}");
}

/// Eight throws at 5 and 20 substeps (before the corner and resting rules, two of them
/// gained 110 % and 622 %).
#[test]
fn heavy_soft_bodies_thrown_at_light_boxes_gain_no_energy() {
    sweep(0x9E37_79B9_7F4A_7C15, 8, &[5, 20], &[]);
}

/// Forty throws at 5 to 40 substeps (before, four gained 66–637 %). Known limit: throw 22
/// (20 substeps, a 137 kg body with hard edges + vertex–face at 14 m/s onto a 0.68 kg box)
/// gains about 38 %: the box, wedged spinning under the body, keeps pushing its triangles
/// out and the body's own constraints give the energy back (`docs/decisions/
/// only-a-body-at-rest-is-immovable.md`, left open).
#[test]
#[ignore = "40 throws, about 20 s in release"]
fn heavy_soft_bodies_thrown_at_light_boxes_never_gain_energy() {
    sweep(0xD1B5_4A32_D192_ED03, 40, &[5, 10, 20, 40], &[22]);
}
