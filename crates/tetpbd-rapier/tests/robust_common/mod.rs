//! Shared helpers of the coupling's robustness tests (bad state, trimesh windings,
//! projectiles, loads and joints).
#![allow(dead_code)]

use hecs::Entity;
use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{
    ColliderBuilder, ColliderHandle, GenericJoint, RevoluteJointBuilder, RigidBodyBuilder,
    RigidBodyHandle, SphericalJointBuilder,
};
use tetpbd::generators::{self, CellSplit};
use tetpbd::{Particles, SoftBodyBuilder, SolverSettings};
use tetpbd_rapier::{CoupledWorld, CouplingSettings, SoftCollider};

/// A scene at 60 Hz with default solver and coupling settings.
pub fn scene() -> CoupledWorld {
    CoupledWorld::new(SolverSettings::default(), CouplingSettings::default()).expect("settings")
}

/// A scene at 60 Hz with `substeps` soft substeps, other settings default.
pub fn scene_substeps(substeps: u32) -> CoupledWorld {
    let solver = SolverSettings {
        substeps,
        ..SolverSettings::default()
    };
    CoupledWorld::new(solver, CouplingSettings::default()).expect("settings")
}

/// A fixed ground cuboid whose top face is at y = 0.
pub fn ground(scene: &mut CoupledWorld) -> (RigidBodyHandle, ColliderHandle) {
    scene.physics.insert(
        RigidBodyBuilder::fixed().translation(Vector::new(0.0, -0.5, 0.0)),
        ColliderBuilder::cuboid(5.0, 0.5, 5.0),
    )
}

/// A soft box of `size` (m) with `cells` cells per axis centred at `at`, hard edges and
/// volume, `density` kg/m³, moving at `velocity` m/s, with the default collider.
pub fn soft_box(
    scene: &mut CoupledWorld,
    size: Vector3<f32>,
    cells: [u32; 3],
    at: Vector3<f32>,
    velocity: Vector3<f32>,
    density: f32,
) -> Entity {
    let mesh = generators::box_grid(size, cells, CellSplit::Six).expect("mesh");
    let e = SoftBodyBuilder::new(mesh)
        .density(density)
        .edges(0.0)
        .volume(0.0)
        .translation(at)
        .velocity(velocity)
        .build()
        .expect("body")
        .spawn(&mut scene.soft);
    scene
        .soft
        .insert_one(e, SoftCollider::default())
        .expect("entity");
    e
}

/// Particles of a soft body (cloned).
pub fn particles(scene: &CoupledWorld, e: Entity) -> Particles {
    (*scene.soft.get::<&Particles>(e).expect("soft body")).clone()
}

/// Centre of mass (m) and its velocity (m/s) of a soft body.
pub fn com(scene: &CoupledWorld, e: Entity) -> (Vector3<f32>, Vector3<f32>) {
    let p = scene.soft.get::<&Particles>(e).expect("soft body");
    (p.center_of_mass(), p.linear_momentum() / p.total_mass())
}

/// A 2 kg box of 0.2 m, its centre at (0, 0.8, 0), on `joint` (impulse or multibody) from a
/// fixed body at (0, 1, 0).
pub fn hanging_box(s: &mut CoupledWorld, joint: GenericJoint, multibody: bool) -> RigidBodyHandle {
    let anchor = s
        .physics
        .bodies
        .insert(RigidBodyBuilder::fixed().translation(Vector::new(0.0, 1.0, 0.0)));
    let (bx, _) = s.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vector::new(0.0, 0.8, 0.0)),
        ColliderBuilder::cuboid(0.1, 0.1, 0.1).mass(2.0),
    );
    if multibody {
        s.physics.multibody_joints.insert(anchor, bx, joint, true);
    } else {
        s.physics.impulse_joints.insert(anchor, bx, joint, true);
    }
    bx
}

/// A revolute joint about z from the anchor at (0, 1, 0) to the top of the box.
pub fn hinge() -> (GenericJoint, [bool; 3]) {
    let joint = RevoluteJointBuilder::new(Vector::Z)
        .local_anchor2(Vector::new(0.0, 0.2, 0.0))
        .build()
        .into();
    (joint, [true; 3])
}

/// A spherical joint from the anchor at (0, 1, 0) to the top of the box.
pub fn ball() -> (GenericJoint, [bool; 3]) {
    let joint = SphericalJointBuilder::new()
        .local_anchor2(Vector::new(0.0, 0.2, 0.0))
        .build()
        .into();
    (joint, [true; 3])
}

/// A hard soft beam of `mass` kg (0.6 m along x, 6 × 1 × 1 cells) whose root face is
/// attached to the +x side of the box `bx` of [`hanging_box`].
pub fn attach_beam(s: &mut CoupledWorld, bx: RigidBodyHandle, mass: f32) -> Entity {
    let mesh = generators::beam(0.6, 0.1, 6, 1, CellSplit::Six).expect("mesh");
    let roots = generators::beam_root(&mesh);
    let body = SoftBodyBuilder::new(mesh)
        .density(mass / 0.006)
        .edges(0.0)
        .volume(0.0)
        .translation(Vector3::new(0.1, 0.75, -0.05))
        .build()
        .expect("beam");
    let mut att = tetpbd_rapier::Attachments::new();
    for &i in &roots {
        att.attach_to_body(&body.particles, i, &s.physics.bodies, bx, 0.0)
            .expect("attach");
    }
    let e = body.spawn(&mut s.soft);
    s.soft.insert_one(e, att).expect("entity");
    e
}

/// A hard soft cube (0.2 m, 3³ cells) of `ratio` × the 2 kg of the box of [`hanging_box`],
/// resting on its top: edges + vertex–face for `vertex_face`, else edges + volume.
pub fn cube_on_box(s: &mut CoupledWorld, ratio: f32, vertex_face: bool) -> Entity {
    let mesh = generators::box_grid(Vector3::repeat(0.2), [3; 3], CellSplit::Six).expect("mesh");
    let b = SoftBodyBuilder::new(mesh)
        .density(2.0 * ratio / 0.008)
        .translation(Vector3::new(0.0, 1.003, 0.0));
    let b = if vertex_face {
        b.vertex_face(0.0).edges(0.0)
    } else {
        b.edges(0.0).volume(0.0)
    };
    b.build().expect("cube").spawn(&mut s.soft)
}

/// A small seeded generator (xorshift) for the tests' sweeps.
pub struct Draws(pub u64);

impl Draws {
    /// A uniform draw in `[lo, hi)`.
    pub fn between(&mut self, lo: f32, hi: f32) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        lo + (hi - lo) * ((self.0 >> 40) as f32 / (1u64 << 24) as f32)
    }
}

/// Kinetic plus gravitational energy (g = 9.81 m/s² along −y, zero at y = 0), J.
pub fn mechanical_energy(p: &Particles) -> f32 {
    let potential: f32 = p
        .positions()
        .iter()
        .zip(p.masses())
        .map(|(x, m)| m * 9.81 * x.y)
        .sum();
    p.kinetic_energy() + potential
}

/// Case `case` of the hard-cube sweeps: edge length (m), substeps, cells per axis, split.
pub fn cube_sweep_case(case: usize) -> (f32, u32, u32, CellSplit) {
    let size = [0.5, 1.0, 2.0][case % 3];
    let substeps = [5, 10, 20][(case / 3) % 3];
    let cells = 3 + (case % 2) as u32;
    let split = if case % 4 < 2 {
        CellSplit::Six
    } else {
        CellSplit::Five
    };
    (size, substeps, cells, split)
}
