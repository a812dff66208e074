//! With the `serde` feature, a snapshot of every component restored into a fresh world
//! continues bit-identically.
#![cfg(feature = "serde")]

use hecs::{Entity, World};
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use tetpbd::generators::{ball, CellSplit};
use tetpbd::{
    Activation, EdgeConstraints, Particles, SoftBodyBuilder, Solver, SolverSettings, Surface,
    Tetrahedra, Untangle, VertexFaceConstraints, VolumeConstraints,
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
    settings: SolverSettings,
}

fn take(world: &World, e: Entity, settings: &SolverSettings) -> Snapshot {
    Snapshot {
        particles: (*world.get::<&Particles>(e).unwrap()).clone(),
        tetrahedra: (*world.get::<&Tetrahedra>(e).unwrap()).clone(),
        surface: (*world.get::<&Surface>(e).unwrap()).clone(),
        edges: world.get::<&EdgeConstraints>(e).ok().map(|c| (*c).clone()),
        vertex_face: world
            .get::<&VertexFaceConstraints>(e)
            .ok()
            .map(|c| (*c).clone()),
        volume: world
            .get::<&VolumeConstraints>(e)
            .ok()
            .map(|c| (*c).clone()),
        activation: world.get::<&Activation>(e).ok().map(|a| *a),
        untangle: world.get::<&Untangle>(e).ok().map(|u| (*u).clone()),
        settings: settings.clone(),
    }
}

fn restore(s: Snapshot, world: &mut World) -> (Entity, SolverSettings) {
    let mut b = hecs::EntityBuilder::new();
    b.add(s.particles).add(s.tetrahedra).add(s.surface);
    if let Some(c) = s.edges {
        b.add(c);
    }
    if let Some(c) = s.vertex_face {
        b.add(c);
    }
    if let Some(c) = s.volume {
        b.add(c);
    }
    if let Some(a) = s.activation {
        b.add(a);
    }
    if let Some(u) = s.untangle {
        b.add(u);
    }
    (world.spawn(b.build()), s.settings)
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
    let json = serde_json::to_string(&take(&world, e, &settings)).unwrap();

    let mut fresh = World::new();
    let (e2, settings2) = restore(serde_json::from_str(&json).unwrap(), &mut fresh);
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
