//! A long soft beam folding onto itself: with [`SelfCollision`] its free half lands on its
//! pinned half; without it, the free half passes through (the control).

mod soft_soft_common;

use hecs::Entity;
use nalgebra::Vector3;
use soft_soft_common::Scene;
use tetpbd::generators::{self, CellSplit};
use tetpbd::SoftBodyBuilder;
use tetpbd_rapier::SelfCollision;

const LENGTH: f32 = 2.0;
const WIDTH: f32 = 0.2;
const DEPTH: f32 = 0.8;

/// A 2 m beam (0.2 m square section, 20×2×2 cells) along x from 0 to 2, its half x < 0.9 m
/// pinned, its free half rotating at `omega` rad/s about the z axis through the hinge's top
/// edge (1, 0.1, ·), so that it folds over onto the pinned half.
fn beam(s: &mut Scene, omega: f32, edge: f32, self_collision: bool) -> Entity {
    let mut mesh = generators::box_grid(
        Vector3::new(LENGTH, WIDTH, DEPTH),
        [20, 2, 4],
        CellSplit::Six,
    )
    .expect("mesh");
    for v in &mut mesh.vertices {
        v.x += LENGTH / 2.0;
    }
    let pinned: Vec<u32> = (0..mesh.vertices.len() as u32)
        .filter(|&i| mesh.vertices[i as usize].x < 0.9 + 1e-4)
        .collect();
    let e = SoftBodyBuilder::new(mesh)
        .density(500.0)
        .edges(edge)
        .volume(0.0)
        .pinned(pinned)
        .build()
        .expect("beam")
        .spawn(&mut s.world);
    {
        let mut p = s.world.get::<&mut tetpbd::Particles>(e).expect("particles");
        let hinge = Vector3::new(1.0, WIDTH / 2.0, 0.0);
        let w = Vector3::new(0.0, 0.0, omega);
        for i in 0..p.len() {
            let x = p.positions()[i];
            if x.x > 0.9 + 1e-4 {
                let v = w.cross(&(x - hinge));
                p.set_velocity(i, v).expect("velocity");
            }
        }
    }
    if self_collision {
        s.world.insert_one(e, SelfCollision).expect("entity");
    }
    e
}

/// Runs `frames` frames; returns the deepest a free particle got into the pinned block
/// (x ∈ [0, 0.85], |y| < 0.1, |z| < 0.4), m, and the number of frame-contacts.
fn fold(self_collision: bool, frames: usize) -> (f32, usize) {
    let mut s = Scene::new(10);
    let e = beam(&mut s, 14.0, 3e-4, self_collision);
    let h = WIDTH / 2.0;
    let mut depth = 0.0f32;
    let mut touched = 0;
    for f in 0..frames {
        let (_, c) = s.step();
        touched += c.contacts;
        let p = s.particles(e);
        for i in 0..p.len() {
            if p.inv_masses()[i] == 0.0 {
                continue;
            }
            let x = p.positions()[i];
            if x.x >= 0.0 && x.x <= 0.85 && x.y.abs() < h && x.z.abs() < DEPTH / 2.0 {
                depth = depth.max((h - x.y).min(x.y + h));
            }
        }
        if f % 15 == 14 {
            println!(
                "self {self_collision}: t {:.2} s, max|v| {:.3} m/s, candidates {}, contacts {}, depth so far {depth:.4} m",
                (f + 1) as f32 / 60.0,
                p.max_speed(),
                c.candidates,
                c.contacts
            );
        }
    }
    (depth, touched)
}

#[test]
fn folding_beam_does_not_pass_through_itself() {
    let (depth, touched) = fold(true, 120);
    println!(
        "with self collision: deepest {depth:.5} m into the pinned half, {touched} frame-contacts"
    );
    assert!(touched > 0, "the fold never reached the pinned half");
    assert!(depth < 0.005, "went {depth} m into itself");
}

#[test]
fn control_without_self_collision_the_beam_passes_through() {
    // Same hook, no `SelfCollision` component: the body pays nothing and passes through.
    let (depth, touched) = fold(false, 120);
    println!("without: deepest {depth:.5} m into the pinned half, {touched} frame-contacts");
    assert_eq!(touched, 0);
    assert!(
        depth > 0.05,
        "only {depth} m: the control does not fold through"
    );
}
