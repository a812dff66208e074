//! Rigid bodies landing on soft slabs: a ball rests on the slab and the slab recovers once
//! it is lifted away; a small cube landing corner-first does not slip between the particles
//! of a coarse slab.

mod coupling_common;

use coupling_common::{ground, min_y, particles, run, scene, spawn_with, volume_ratio};
use nalgebra::Vector3;
use rapier3d::math::{Pose, Rotation, Vector};
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder, RigidBodyType, SharedShape};
use tetpbd::generators::{self, CellSplit};
use tetpbd::{SoftBodyBuilder, Surface};
use tetpbd_rapier::{CoupledWorld, DeformationDamping, SoftColliderBuilder, SoftFeature};

/// A slab lying on the ground; with `glued` its bottom particles are pinned where they are.
fn slab(
    s: &mut CoupledWorld,
    size: Vector3<f32>,
    cells: [u32; 3],
    (edges, volume): (f32, f32),
    triangles: bool,
    glued: bool,
) -> hecs::Entity {
    let mesh = generators::box_grid(size, cells, CellSplit::Six).expect("mesh");
    let bottom: Vec<u32> = (0..mesh.vertices.len() as u32)
        .filter(|&i| glued && mesh.vertices[i as usize].y < -size.y / 2.0 + 1e-6)
        .collect();
    let body = SoftBodyBuilder::new(mesh)
        .pinned(bottom)
        .density(1000.0)
        .edges(edges)
        .volume(volume)
        .translation(Vector3::new(0.0, size.y / 2.0 + 0.0025, 0.0));
    spawn_with(
        s,
        body,
        SoftColliderBuilder::new().triangle_collisions(triangles),
    )
}

/// A rigid ball dropped on a soft slab whose bottom is glued to the ground (so that ground
/// friction cannot lock in a shear) rests on it, dents it, and the dent springs back once
/// the ball is lifted away.
#[test]
fn ball_rests_on_slab_and_slab_recovers() {
    let mut s = scene(10);
    ground(&mut s);
    let e = slab(
        &mut s,
        Vector3::new(1.0, 0.2, 1.0),
        [4, 2, 4],
        (3e-4, 3e-9),
        true,
        true,
    );
    // An elastic slab with a ball on it rings for a long time; damp its deformation.
    let damping = DeformationDamping::new(10.0).expect("damping");
    s.soft.insert_one(e, damping).expect("entity");
    let r = 0.15;
    // Held above the slab while the slab settles under its own weight. A ball rolling on a
    // stiff flat slab has no rolling resistance; angular damping stands in for it.
    let (ball, _) = s.physics.insert(
        RigidBodyBuilder::fixed()
            .translation(Vector::new(0.125, 0.2 + r + 0.3, 0.125))
            .angular_damping(5.0),
        ColliderBuilder::ball(r).density(1000.0),
    );
    run(&mut s, 30, 1);
    let alone = volume_ratio(&s, e);
    let rest = particles(&s, e);
    // Largest vertical particle displacement from the pre-ball shape (the dent).
    let moved = |s: &CoupledWorld| {
        particles(s, e)
            .positions()
            .iter()
            .zip(rest.positions())
            .map(|(a, b)| (a.y - b.y).abs())
            .fold(0.0f32, f32::max)
    };
    s.physics.bodies[ball].set_body_type(RigidBodyType::Dynamic, true);
    let pen = run(&mut s, 150, 30);
    let b = &s.physics.bodies[ball];
    let bottom = b.translation().y - r;
    let speed = b.linvel().length();
    let squeezed = volume_ratio(&s, e);
    let dent = moved(&s);
    println!(
        "ball bottom {bottom:.4} m (slab top 0.2 m), |v| {speed:.4} m/s, slab particle \
         penetration {pen:.5} m, slab volume ratio {alone:.5} alone, {squeezed:.5} under the \
         ball, dent {dent:.5} m"
    );
    assert!(speed < 0.01, "ball still moving at {speed} m/s");
    assert!(bottom > 0.15, "ball sank into the slab to {bottom} m");
    assert!(bottom < 0.21, "ball not resting on the slab ({bottom} m)");
    assert!(pen < 0.01 * 0.25, "slab particles {pen} m inside the ball");
    assert!(dent > 1e-3, "the ball did not dent the slab ({dent} m)");

    let b = &mut s.physics.bodies[ball];
    b.set_body_type(RigidBodyType::Fixed, true);
    b.set_translation(Vector::new(0.0, 5.0, 0.0), true);
    run(&mut s, 60, 1);
    let recovered = volume_ratio(&s, e);
    let left = moved(&s);
    let v = particles(&s, e).max_speed();
    println!(
        "after lifting the ball: volume ratio {recovered:.5}, dent left {left:.5} m, max |v| {v:.4} m/s"
    );
    assert!(
        (recovered - alone).abs() < 5e-4,
        "volume ratio {recovered} vs {alone}"
    );
    assert!(left < 0.1 * dent, "shape not recovered: {left} m");
    assert!(v < 0.05);
}

/// A 1 kg, 0.1 m rigid cube falls corner-first onto the middle of a surface triangle of a
/// 2-cell-thick slab with 0.4 m cells: no slab particle is anywhere near the corner.
/// Returns the height of the cube's lowest corner after 1.5 s.
fn corner_drop(triangles: bool, compound: bool) -> f32 {
    let mut s = scene(10);
    ground(&mut s);
    let top = 0.4;
    let e = slab(
        &mut s,
        Vector3::new(0.8, top, 0.8),
        [2, 2, 2],
        (0.0, 0.0),
        triangles,
        false,
    );
    let h = 0.05;
    let corner_down = Rotation::from_rotation_arc(Vector::ONE.normalize(), -Vector::Y);
    let (cube, cube_collider) = s.physics.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(0.2, top + 0.3, 0.05))
            .rotation(corner_down.to_scaled_axis()),
        if compound {
            let part = (Pose::IDENTITY, SharedShape::cuboid(h, h, h));
            ColliderBuilder::compound(vec![part]).density(1000.0)
        } else {
            ColliderBuilder::cuboid(h, h, h).density(1000.0)
        },
    );
    run(&mut s, 150, 1);
    if triangles {
        // The slab holds the cube up through triangle contacts, reported as such; all the
        // cube's contacts together carry its weight.
        let on_triangles: Vec<_> = s
            .coupling
            .contacts()
            .iter()
            .filter(|c| {
                c.collider == cube_collider && matches!(c.feature, SoftFeature::Triangle(_))
            })
            .collect();
        let push: f32 = s
            .coupling
            .contacts()
            .iter()
            .filter(|c| c.collider == cube_collider)
            .map(|c| c.impulse.y)
            .sum();
        let weight_dt = s.physics.bodies[cube].mass() * 9.81 * s.physics.integration_parameters.dt;
        println!(
            "{} triangle contacts, impulse of the cube on the slab {push:.5} N·s, cube weight × \
             dt {weight_dt:.5} N·s",
            on_triangles.len()
        );
        assert!(!on_triangles.is_empty(), "no triangle contact reported");
        assert!(on_triangles
            .iter()
            .all(|c| c.normal.y < -0.9 && c.entity == e));
        assert!(
            (push + weight_dt).abs() < 0.01 * weight_dt,
            "impulse {push} N·s"
        );
    }
    let b = &s.physics.bodies[cube];
    let lowest = (0..8)
        .map(|k| {
            let c = Vector::new(
                if k & 1 == 0 { -h } else { h },
                if k & 2 == 0 { -h } else { h },
                if k & 4 == 0 { -h } else { h },
            );
            b.position().transform_point(c).y
        })
        .fold(f32::INFINITY, f32::min);
    println!(
        "triangle collisions {triangles}: lowest cube corner {lowest:.4} m, slab top {:.4} m",
        min_y(&s, e) + top
    );
    lowest
}

#[test]
fn compound_corner_does_not_slip_between_particles() {
    let caught = corner_drop(true, true);
    assert!(caught > 0.4 - 0.01, "compound corner sank to {caught} m");
}

#[test]
fn rigid_corner_does_not_slip_between_particles() {
    let caught = corner_drop(true, false);
    assert!(caught > 0.4 - 0.01, "corner sank to {caught} m");
    let missed = corner_drop(false, false);
    assert!(
        missed < 0.4 - 0.05,
        "control: without triangle tests the corner should sink"
    );
}

/// A soft cube (0.2 m cells) dropped onto the apex of a fixed cone, the apex under the
/// middle of a bottom triangle. Returns how deep the apex got inside the cube.
fn cone_drop(triangles: bool) -> f32 {
    let mut s = scene(10);
    let apex = 0.5;
    s.physics.insert(
        RigidBodyBuilder::fixed().translation(Vector::new(0.0, apex - 0.25, 0.0)),
        ColliderBuilder::cone(0.25, 0.1),
    );
    let mesh = generators::box_grid(Vector3::repeat(0.4), [2, 2, 2], CellSplit::Six).expect("mesh");
    let body = SoftBodyBuilder::new(mesh)
        .density(200.0)
        .edges(0.0)
        .volume(0.0)
        .translation(Vector3::new(0.07, apex + 0.2 + 0.02, 0.13));
    let e = spawn_with(
        &mut s,
        body,
        SoftColliderBuilder::new().triangle_collisions(triangles),
    );
    // How deep the apex gets inside the (still convex) cube during 0.5 s: its distance
    // behind the nearest boundary face plane, negative when outside.
    let tip = Vector3::new(0.0, apex, 0.0);
    let mut deepest = f32::NEG_INFINITY;
    for _ in 0..30 {
        s.step().expect("step");
        let p = particles(&s, e);
        let surface = s.soft.get::<&Surface>(e).expect("surface");
        let depth = surface
            .triangles()
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| p.positions()[i as usize]);
                let n = (b - a).cross(&(c - a)).normalize();
                (a - tip).dot(&n)
            })
            .fold(f32::INFINITY, f32::min);
        deepest = deepest.max(depth);
    }
    println!("triangle collisions {triangles}: apex at most {deepest:.4} m inside the cube");
    deepest
}

#[test]
fn cone_apex_does_not_pierce_a_coarse_soft_body() {
    let missed = cone_drop(false);
    let caught = cone_drop(true);
    assert!(caught < 0.005, "pierced by {caught} m");
    assert!(
        missed > 0.05,
        "control: without triangle tests the apex should pierce"
    );
}
