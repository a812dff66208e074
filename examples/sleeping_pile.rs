//! Headless sleeping pile: soft cubes (0.5 m, 4×4×4 cells, 1000 kg/m³) dropped onto rigid
//! ground fall asleep as one island; a rigid ball thrown at them wakes them. Or, with
//! `field`, cubes resting apart fall asleep and one more cube is dropped among them, to
//! compare the cost of the sleeping bodies with that of the awake one.
//!
//! ```text
//! cargo run --release --example sleeping_pile -- [pile|field] [CUBES] …
//! ```
//!
//! Prints per frame the awake soft bodies and the frame's cost (ms), then the median cost
//! of the resting pile awake (the last 30 frames before it fell asleep) and asleep (the
//! first 30 after). `-- --help` lists every option.

use clap::Parser;
use hecs::Entity;
use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder};
use tetpbd::generators::{self, CellSplit};
use tetpbd::{is_sleeping, SoftBodyBuilder, SolverSettings};
use tetpbd_rapier::{CoupledWorld, CouplingSettings};

#[path = "cli/sleeping_pile.rs"]
mod cli;

const SIZE: f32 = 0.5;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let cli = cli::Cli::parse();
    let mut viz = tetpbd_viz::Viz::from_options(cli.viz.clone())?;
    let mut scene = CoupledWorld::new(SolverSettings::default(), CouplingSettings::default())?;
    scene.physics.insert(
        RigidBodyBuilder::fixed().translation(Vector::new(0.0, -0.5, 0.0)),
        ColliderBuilder::cuboid(50.0, 0.5, 50.0),
    );
    let n = cli.cubes as usize;
    let at: Vec<Vector3<f32>> = match cli.scene {
        cli::Scene::Pile => (0..n).map(pile_position).collect(),
        cli::Scene::Field => (0..n).map(|i| field_position(i, n)).collect(),
    };
    let mut bodies = Vec::with_capacity(n + 1);
    for p in at {
        bodies.push(spawn_cube(&mut scene, p)?);
    }
    println!("frame  awake  ms/frame");
    let mut costs = Vec::new();
    let max = cli.max_seconds * 60;
    let mut slept = None;
    for f in 0..max {
        let (awake, ms) = frame(&mut scene, &bodies)?;
        viz.frame(&scene)?;
        costs.push(ms);
        if cli.every_frame || f % 30 == 0 || awake == 0 {
            println!("{f:>5} {awake:>6} {ms:>9.3}");
        }
        if awake == 0 {
            slept = Some(f);
            break;
        }
    }
    let Some(slept) = slept else {
        println!("not asleep after {} s", cli.max_seconds);
        viz.finish()?;
        return Ok(());
    };
    println!("asleep after {:.2} s", (slept + 1) as f32 / 60.0);
    for _ in 0..30 {
        let (_, ms) = frame(&mut scene, &bodies)?;
        costs.push(ms);
    }
    let awake_ms = median(&costs[costs.len().saturating_sub(60)..costs.len() - 30]);
    let asleep_ms = median(&costs[costs.len() - 30..]);
    match cli.scene {
        cli::Scene::Pile => {
            let from = Vector::new(-3.0, 0.4, 0.0);
            scene.physics.insert(
                RigidBodyBuilder::dynamic()
                    .translation(from)
                    .linvel(Vector::new(cli.throw_speed, 0.0, 0.0)),
                ColliderBuilder::ball(0.15).density(2000.0),
            );
            println!("ball thrown at {} m/s", cli.throw_speed);
        }
        cli::Scene::Field => {
            bodies.push(spawn_cube(&mut scene, Vector3::new(0.0, 1.0, -4.0))?);
            println!("one cube dropped among the sleeping ones");
        }
    }
    let mut after = Vec::new();
    for f in 0..cli.frames_after {
        let (awake, ms) = frame(&mut scene, &bodies)?;
        viz.frame(&scene)?;
        after.push(ms);
        println!("{:>5} {awake:>6} {ms:>9.3}", slept + 31 + f);
    }
    println!(
        "resting pile: {awake_ms:.3} ms/frame awake, {asleep_ms:.3} ms/frame asleep ({:.1} %); \
         after the wake-up: median {:.3} ms/frame",
        100.0 * asleep_ms / awake_ms.max(1e-9),
        median(&after)
    );
    viz.finish()?;
    Ok(())
}

/// One frame: the awake soft bodies after it, and its cost (ms).
fn frame(
    scene: &mut CoupledWorld,
    bodies: &[Entity],
) -> Result<(usize, f64), Box<dyn std::error::Error>> {
    let t = std::time::Instant::now();
    scene.step()?;
    let ms = t.elapsed().as_secs_f64() * 1e3;
    let awake = bodies
        .iter()
        .filter(|&&e| !is_sleeping(&scene.soft, e))
        .count();
    Ok((awake, ms))
}

fn spawn_cube(
    scene: &mut CoupledWorld,
    at: Vector3<f32>,
) -> Result<Entity, Box<dyn std::error::Error>> {
    let cube = generators::box_grid(Vector3::repeat(SIZE), [4, 4, 4], CellSplit::Six)?;
    Ok(SoftBodyBuilder::new(cube)
        .density(1000.0)
        .edges(0.0)
        .volume(0.0)
        .translation(at)
        .build()?
        .spawn(&mut scene.soft))
}

/// Layers of 3 × 3 cubes, 5 cm apart, each layer turned a little and shifted by a quarter
/// cube so that upper cubes rest across lower ones.
fn pile_position(i: usize) -> Vector3<f32> {
    let (layer, k) = (i / 9, i % 9);
    let shift = if layer % 2 == 1 { 0.25 * SIZE } else { 0.0 };
    let pitch = SIZE + 0.05;
    Vector3::new(
        (k % 3) as f32 * pitch - pitch + shift,
        0.5 * SIZE + 0.01 + layer as f32 * (SIZE + 0.1),
        (k / 3) as f32 * pitch - pitch + shift,
    )
}

/// A square grid of cubes 1.5 m apart, resting on the ground.
fn field_position(i: usize, n: usize) -> Vector3<f32> {
    let side = (n as f32).sqrt().ceil() as usize;
    let pitch = 1.5;
    Vector3::new(
        (i % side) as f32 * pitch,
        0.5 * SIZE + 0.005,
        (i / side) as f32 * pitch,
    )
}

fn median(xs: &[f64]) -> f64 {
    if xs.is_empty() {
        return 0.0;
    }
    let mut v = xs.to_vec();
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}
