//! With the `serde` feature, a snapshot of every component restored into a fresh world
//! continues bit-identically: a moving body, and a world saved right after a tear (every
//! piece, the tear's energy bound included), further tears included.
#![cfg(feature = "serde")]

mod common;

use common::tearing::{pinned_bar, pull_ends};
use hecs::{Entity, World};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use tetpbd::generators::{ball, CellSplit};
use tetpbd::{
    Activation, EdgeConstraints, Particles, SoftBodyBuilder, Solver, SolverSettings, Surface,
    TearRelaxation, Tearing, TearingSettings, Tetrahedra, Untangle, VertexFaceConstraints,
    VolumeConstraints,
};

/// One body's components, as an application would store them.
#[derive(Serialize, Deserialize)]
struct Snapshot {
    particles: Particles,
    tetrahedra: Tetrahedra,
    surface: Surface,
    edges: Option<EdgeConstraints>,
    vertex_face: Option<VertexFaceConstraints>,
    volume: Option<VolumeConstraints>,
    activation: Option<Activation>,
    untangle: Option<Untangle>,
    tearing: Option<Tearing>,
    relaxation: Option<TearRelaxation>,
}

fn cloned<T: hecs::Component + Clone>(world: &World, e: Entity) -> Option<T> {
    world.get::<&T>(e).ok().map(|c| (*c).clone())
}

fn take(world: &World, e: Entity) -> Snapshot {
    Snapshot {
        particles: cloned(world, e).unwrap(),
        tetrahedra: cloned(world, e).unwrap(),
        surface: cloned(world, e).unwrap(),
        edges: cloned(world, e),
        vertex_face: cloned(world, e),
        volume: cloned(world, e),
        activation: cloned(world, e),
        untangle: cloned(world, e),
        tearing: cloned(world, e),
        relaxation: cloned(world, e),
    }
}

/// Adds the component a snapshot holds, if it holds one.
fn add<T: hecs::Component>(b: &mut hecs::EntityBuilder, c: Option<T>) {
    if let Some(c) = c {
        b.add(c);
    }
}

fn restore(s: Snapshot, world: &mut World) -> Entity {
    let mut b = hecs::EntityBuilder::new();
    b.add(s.particles).add(s.tetrahedra).add(s.surface);
    add(&mut b, s.edges);
    add(&mut b, s.vertex_face);
    add(&mut b, s.volume);
    add(&mut b, s.activation);
    add(&mut b, s.untangle);
    add(&mut b, s.tearing);
    add(&mut b, s.relaxation);
    world.spawn(b.build())
}

#[test]
fn snapshot_restored_into_a_fresh_world_continues_bit_identically() {
    let mut world = World::new();
    let e = SoftBodyBuilder::new(ball(0.5, 3, CellSplit::Five).unwrap())
        .edges(1e-5)
        .volume(0.0)
        .vertex_face(1e-4)
        .pinned([0])
        .velocity(Vector3::new(0.3, 1.0, -0.2))
        .build()
        .unwrap()
        .spawn(&mut world);
    let settings = SolverSettings {
        damping: 0.1,
        ..Default::default()
    };
    let mut solver = Solver::new(settings.clone()).unwrap();
    for _ in 0..30 {
        solver.step(&mut world).unwrap();
    }
    let json = serde_json::to_string(&(take(&world, e), &settings)).unwrap();

    let mut fresh = World::new();
    let (snapshot, settings2): (Snapshot, SolverSettings) = serde_json::from_str(&json).unwrap();
    let e2 = restore(snapshot, &mut fresh);
    assert_eq!(
        *fresh.get::<&Particles>(e2).unwrap(),
        *world.get::<&Particles>(e).unwrap(),
        "the restored state equals the original (the working copy is scratch, not compared)"
    );
    let mut solver2 = Solver::new(settings2).unwrap();
    for _ in 0..60 {
        solver.step(&mut world).unwrap();
        solver2.step(&mut fresh).unwrap();
    }
    let a = world.get::<&Particles>(e).unwrap();
    let b = fresh.get::<&Particles>(e2).unwrap();
    for (x, y) in a.positions().iter().zip(b.positions()) {
        assert_eq!(x.map(f32::to_bits), y.map(f32::to_bits));
    }
    for (x, y) in a.velocities().iter().zip(b.velocities()) {
        assert_eq!(x.map(f32::to_bits), y.map(f32::to_bits));
    }
    assert!(
        a.max_speed() > 0.1,
        "the body is moving, so the comparison means something"
    );
}

/// A stiff bar along x with its end cross-sections pinned, tearing past a strain of 0.2.
fn spawn_bar(world: &mut World) {
    let settings = TearingSettings {
        strain: Some(0.2),
        smoothing_time: 0.02,
        ..Default::default()
    };
    let size = Vector3::new(2.0, 0.3, 0.3);
    pinned_bar(world, size, [8, 1, 1], settings, |b| {
        b.edges(0.0).volume(0.0)
    });
}

/// Every body's positions, as bits, sorted (entities are not compared: a restored world
/// numbers them afresh).
fn state(world: &World) -> Vec<Vec<[u32; 3]>> {
    let mut bodies: Vec<Vec<[u32; 3]>> = world
        .query::<&Particles>()
        .iter()
        .map(|p| {
            p.positions()
                .iter()
                .chain(p.velocities())
                .map(|x| [x.x.to_bits(), x.y.to_bits(), x.z.to_bits()])
                .collect()
        })
        .collect();
    bodies.sort();
    bodies
}

/// Steps `frames` frames, pulling the ends at 2 m/s; returns how many tears happened.
fn run(world: &mut World, solver: &mut Solver, frames: u32) -> usize {
    let mut tears = 0;
    for _ in 0..frames {
        pull_ends(world, 2.0 / 60.0);
        solver.step(world).unwrap();
        tears += solver.tear_events().len();
    }
    tears
}

fn saved_after_first_tear(with_relaxation: bool) -> (World, World, Solver, Solver) {
    let settings = SolverSettings {
        gravity: Vector3::new(0.0, -9.81, 0.0),
        ..Default::default()
    };
    let mut world = World::new();
    spawn_bar(&mut world);
    let mut solver = Solver::new(settings.clone()).unwrap();
    let mut frames = 0;
    while world.len() < 2 {
        run(&mut world, &mut solver, 1);
        frames += 1;
        assert!(frames < 120, "the bar never split");
    }
    let mut entities: Vec<Entity> = world
        .query::<(Entity, &Particles)>()
        .iter()
        .map(|(e, _)| e)
        .collect();
    entities.sort();
    let snapshots: Vec<Snapshot> = entities.iter().map(|&e| take(&world, e)).collect();
    assert!(
        snapshots.iter().any(|s| s.relaxation.is_some()),
        "the pieces carry the tear's energy bound"
    );
    let json = serde_json::to_string(&snapshots).unwrap();
    let mut fresh = World::new();
    for mut s in serde_json::from_str::<Vec<Snapshot>>(&json).unwrap() {
        if !with_relaxation {
            s.relaxation = None;
        }
        restore(s, &mut fresh);
    }
    let solver2 = Solver::new(settings).unwrap();
    (world, fresh, solver, solver2)
}

#[test]
fn torn_pieces_restored_from_a_snapshot_continue_bit_identically() {
    let (mut world, mut fresh, mut solver, mut solver2) = saved_after_first_tear(true);
    assert_eq!(state(&world), state(&fresh));
    let (mut tears, mut tears2) = (0, 0);
    for _ in 0..40 {
        tears += run(&mut world, &mut solver, 1);
        tears2 += run(&mut fresh, &mut solver2, 1);
        assert_eq!(state(&world), state(&fresh));
    }
    assert_eq!(tears, tears2);
}

/// The control: the bound is state. Restored without it, the pieces move differently.
#[test]
fn torn_pieces_restored_without_their_energy_bound_diverge() {
    let (mut world, mut fresh, mut solver, mut solver2) = saved_after_first_tear(false);
    run(&mut world, &mut solver, 15);
    run(&mut fresh, &mut solver2, 15);
    assert_ne!(state(&world), state(&fresh));
}
