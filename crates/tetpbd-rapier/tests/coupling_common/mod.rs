//! Shared helpers of the coupling integration tests (`tests/collision_*.rs`,
//! `tests/coupling_*.rs`).
#![allow(dead_code)]

use hecs::Entity;
use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{ColliderBuilder, ColliderHandle, RigidBodyBuilder, RigidBodyHandle};
use tetpbd::generators::{self, CellSplit};
use tetpbd::{Particles, SoftBodyBuilder, SolverSettings, Tetrahedra};
use tetpbd_rapier::{
    CoupledWorld, CouplingSettings, CouplingStats, SoftCollider, SoftColliderBuilder,
};

/// Compliances of (edges, vertex–face, volume), `None` for a family the body does not have.
pub type Families = (Option<f32>, Option<f32>, Option<f32>);

/// A scene at 60 Hz with `substeps` soft substeps.
pub fn scene(substeps: u32) -> CoupledWorld {
    scene_with(substeps, 1)
}

/// A scene at 60 Hz with `substeps` soft substeps of `iterations` iterations.
pub fn scene_with(substeps: u32, iterations: u32) -> CoupledWorld {
    let solver = SolverSettings {
        substeps,
        iterations,
        ..SolverSettings::default()
    };
    CoupledWorld::new(solver, CouplingSettings::default()).expect("valid settings")
}

/// A fixed ground cuboid whose top face is at y = 0.
pub fn ground(scene: &mut CoupledWorld) -> (RigidBodyHandle, ColliderHandle) {
    scene.physics.insert(
        RigidBodyBuilder::fixed().translation(Vector::new(0.0, -0.5, 0.0)),
        ColliderBuilder::cuboid(5.0, 0.5, 5.0),
    )
}

/// Builds `body` into the scene's soft world with the soft collider `collider`.
pub fn spawn_with(
    scene: &mut CoupledWorld,
    body: SoftBodyBuilder,
    collider: SoftColliderBuilder,
) -> Entity {
    let e = body.build().expect("body").spawn(&mut scene.soft);
    let collider = collider.build().expect("collider");
    scene.soft.insert_one(e, collider).expect("entity");
    e
}

/// A soft box of `size` (m) with `cells` cells per axis, centred at `at`, stiff edges and
/// volume, density 1000 kg/m³.
pub fn soft_box(
    scene: &mut CoupledWorld,
    size: Vector3<f32>,
    cells: [u32; 3],
    at: Vector3<f32>,
    collider: SoftCollider,
) -> Entity {
    soft_box_with_density(scene, size, cells, at, 1000.0, collider)
}

/// [`soft_box`] with a density in kg/m³.
pub fn soft_box_with_density(
    scene: &mut CoupledWorld,
    size: Vector3<f32>,
    cells: [u32; 3],
    at: Vector3<f32>,
    density: f32,
    collider: SoftCollider,
) -> Entity {
    let hard = (Some(0.0), None, Some(0.0));
    soft_box_of(scene, (size, cells), at, density, hard, collider)
}

/// [`soft_box_with_density`] with the constraint `families`; `(size, cells)` as in
/// [`soft_box`].
pub fn soft_box_of(
    scene: &mut CoupledWorld,
    (size, cells): (Vector3<f32>, [u32; 3]),
    at: Vector3<f32>,
    density: f32,
    (edges, vertex_face, volume): Families,
    collider: SoftCollider,
) -> Entity {
    let mesh = generators::box_grid(size, cells, CellSplit::Six).expect("mesh");
    let mut b = SoftBodyBuilder::new(mesh).density(density).translation(at);
    if let Some(a) = edges {
        b = b.edges(a);
    }
    if let Some(a) = vertex_face {
        b = b.vertex_face(a);
    }
    if let Some(a) = volume {
        b = b.volume(a);
    }
    let e = b.build().expect("body").spawn(&mut scene.soft);
    scene.soft.insert_one(e, collider).expect("entity");
    e
}

/// A soft ball of `radius` (m).
pub fn soft_ball(
    scene: &mut CoupledWorld,
    radius: f32,
    cells: u32,
    at: Vector3<f32>,
    velocity: Vector3<f32>,
    density: f32,
    collider: SoftCollider,
) -> Entity {
    let mesh = generators::ball(radius, cells, CellSplit::Six).expect("mesh");
    let body = SoftBodyBuilder::new(mesh)
        .density(density)
        .edges(0.0)
        .volume(0.0)
        .translation(at)
        .velocity(velocity)
        .build()
        .expect("body");
    let e = body.spawn(&mut scene.soft);
    scene.soft.insert_one(e, collider).expect("entity");
    e
}

/// Steps `frames` frames; returns the largest end-of-step penetration seen over the last
/// `tail` frames.
pub fn run(scene: &mut CoupledWorld, frames: usize, tail: usize) -> f32 {
    let mut pen = 0.0f32;
    for f in 0..frames {
        let stats = scene.step().expect("step");
        assert_eq!(stats.soft.non_finite_resets, 0);
        if f + tail >= frames {
            pen = pen.max(stats.max_penetration);
        }
    }
    pen
}

/// Steps one frame of `scene` (frame number `frame`, for the messages), asserting that no
/// particle state was reset for being non-finite and that soft body `e` moves at a finite
/// speed; returns the frame's statistics and `e`'s largest particle speed, m/s.
pub fn step_checked(scene: &mut CoupledWorld, e: Entity, frame: usize) -> (CouplingStats, f32) {
    let stats = scene.step().expect("step");
    assert_eq!(
        stats.soft.non_finite_resets, 0,
        "frame {frame}: non-finite reset"
    );
    let v = scene
        .soft
        .get::<&Particles>(e)
        .expect("soft body")
        .max_speed();
    assert!(v.is_finite(), "frame {frame}: non-finite particle speed");
    (stats, v)
}

/// Particles of a soft body (cloned).
pub fn particles(scene: &CoupledWorld, e: Entity) -> Particles {
    (*scene.soft.get::<&Particles>(e).expect("soft body")).clone()
}

/// Inverted tetrahedra of a soft body.
pub fn inverted(scene: &CoupledWorld, e: Entity) -> usize {
    let p = scene.soft.get::<&Particles>(e).expect("soft body");
    let t = scene.soft.get::<&Tetrahedra>(e).expect("soft body");
    t.count_inverted(p.positions())
}

/// Volume ratio of a soft body (1 at rest).
pub fn volume_ratio(scene: &CoupledWorld, e: Entity) -> f32 {
    let p = scene.soft.get::<&Particles>(e).expect("soft body");
    let t = scene.soft.get::<&Tetrahedra>(e).expect("soft body");
    t.volume_ratio(p.positions())
}

/// Lowest particle height, m.
pub fn min_y(scene: &CoupledWorld, e: Entity) -> f32 {
    particles(scene, e).aabb().0.y
}
