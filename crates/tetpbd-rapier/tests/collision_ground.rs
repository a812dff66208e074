//! A soft cube dropped on fixed colliders of every common shape comes to rest on them.

mod coupling_common;

use coupling_common::{inverted, particles, run, scene, soft_box};
use nalgebra::Vector3;
use rapier3d::geometry::Array2;
use rapier3d::math::{Pose, Vector};
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder, SharedShape, TriMeshFlags};
use tetpbd::Activation;
use tetpbd_rapier::SoftCollider;

const CELL: f32 = 0.2;

/// Drops a 2×2×2-cell soft cube (0.4 m) from `drop` m above `top` (the collider's highest
/// point under the cube) and checks rest after 3 s: max |v| < 0.01 m/s, penetration < 1 % of
/// the cell size, no inverted tetrahedra, and the cube actually on the collider. The cube
/// never sleeps: the rest measured is the solver's (sleeping would zero its velocities).
fn drop_and_rest(collider: ColliderBuilder, top: f32, name: &str) {
    let mut s = scene(10);
    s.physics.insert(RigidBodyBuilder::fixed(), collider);
    let e = soft_box(
        &mut s,
        Vector3::repeat(2.0 * CELL),
        [2, 2, 2],
        Vector3::new(0.0, top + 2.0 * CELL / 2.0 + 0.3, 0.0),
        SoftCollider::default(),
    );
    *s.soft.get::<&mut Activation>(e).expect("body") = Activation::never_sleeps();
    let pen = run(&mut s, 150, 1);
    // Penetration at rest: end-of-step (after the projections) and the deepest predicted
    // penetration the contacts saw within the substeps, over the last 0.5 s.
    let mut pen = pen;
    let mut depth = 0.0f32;
    for _ in 0..30 {
        pen = pen.max(s.step().expect("step").max_penetration);
        depth = s
            .coupling
            .contacts()
            .iter()
            .map(|c| c.depth)
            .fold(depth, f32::max);
    }
    let p = particles(&s, e);
    let v = p.max_speed();
    let low = p.aabb().0.y;
    println!(
        "{name}: max|v| {v:.5} m/s, penetration {pen:.6} m, deepest within substeps \
         {depth:.6} m, lowest {low:.4} m"
    );
    assert!(
        depth < 0.01 * CELL,
        "{name}: penetration within substeps {depth} m"
    );
    assert!(v < 0.01, "{name}: still moving at {v} m/s");
    assert!(pen < 0.01 * CELL, "{name}: penetration {pen} m");
    assert_eq!(inverted(&s, e), 0, "{name}: inverted tetrahedra");
    assert!(low > top - 0.3, "{name}: fell off or through ({low} m)");
    assert!(p.center_of_mass().y > top, "{name}: not on top");
}

#[test]
fn rests_on_cuboid() {
    drop_and_rest(
        ColliderBuilder::cuboid(2.0, 0.5, 2.0).translation(Vector::new(0.0, -0.5, 0.0)),
        0.0,
        "cuboid",
    );
}

#[test]
fn rests_on_ball() {
    drop_and_rest(
        ColliderBuilder::ball(1.0).translation(Vector::new(0.0, -1.0, 0.0)),
        0.0,
        "ball",
    );
}

#[test]
fn rests_on_capsule() {
    drop_and_rest(
        ColliderBuilder::capsule_z(1.0, 0.5).translation(Vector::new(0.0, -0.5, 0.0)),
        0.0,
        "capsule",
    );
}

#[test]
fn rests_on_convex_hull() {
    let pts = [
        Vector::new(-1.0, -0.5, -1.0),
        Vector::new(1.0, -0.5, -1.0),
        Vector::new(1.0, -0.5, 1.0),
        Vector::new(-1.0, -0.5, 1.0),
        Vector::new(-0.8, 0.0, -0.8),
        Vector::new(0.8, 0.0, -0.8),
        Vector::new(0.8, 0.0, 0.8),
        Vector::new(-0.8, 0.0, 0.8),
    ];
    drop_and_rest(
        ColliderBuilder::convex_hull(&pts).expect("hull"),
        0.0,
        "convex hull",
    );
}

#[test]
fn rests_on_trimesh() {
    let v = vec![
        Vector::new(-2.0, 0.0, -2.0),
        Vector::new(2.0, 0.0, -2.0),
        Vector::new(2.0, 0.0, 2.0),
        Vector::new(-2.0, 0.0, 2.0),
    ];
    // Counter-clockwise seen from above: normals point up.
    let idx = vec![[0, 2, 1], [0, 3, 2]];
    let mesh = ColliderBuilder::trimesh_with_flags(v, idx, TriMeshFlags::empty()).expect("mesh");
    drop_and_rest(mesh, 0.0, "trimesh");
}

#[test]
fn rests_on_heightfield() {
    let heights = Array2::repeat(9, 9, 0.0f32);
    drop_and_rest(
        ColliderBuilder::heightfield(heights, Vector::new(4.0, 1.0, 4.0)),
        0.0,
        "heightfield",
    );
}

#[test]
fn rests_on_cylinder() {
    drop_and_rest(
        ColliderBuilder::cylinder(0.5, 1.0).translation(Vector::new(0.0, -0.5, 0.0)),
        0.0,
        "cylinder",
    );
}

#[test]
fn rests_on_round_cuboid() {
    drop_and_rest(
        ColliderBuilder::round_cuboid(1.0, 0.4, 1.0, 0.1).translation(Vector::new(0.0, -0.5, 0.0)),
        0.0,
        "round cuboid",
    );
}

#[test]
fn rests_on_compound() {
    let parts = vec![
        (
            Pose::translation(-0.6, -0.5, 0.0),
            SharedShape::cuboid(0.6, 0.5, 1.0),
        ),
        (
            Pose::translation(0.6, -0.5, 0.0),
            SharedShape::cuboid(0.6, 0.5, 1.0),
        ),
    ];
    drop_and_rest(ColliderBuilder::compound(parts), 0.0, "compound");
}
