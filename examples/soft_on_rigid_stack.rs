//! A soft cube lands on a stack of three dynamic rigid boxes standing on fixed ground.
//!
//! Headless; prints one line of statistics per frame. Run with
//! `cargo run --release --example soft_on_rigid_stack -- [FRAMES] [--export DIR] [--strip FILE] …`;
//! `-- --help` lists every option with its unit and default (the command line is in
//! `cli/soft_on_rigid_stack.rs`).

use std::time::Instant;

use clap::Parser;

use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder};
use tetpbd::generators::{self, CellSplit};
use tetpbd::{SoftBodyBuilder, SolverSettings};
use tetpbd_rapier::{CoupledWorld, CouplingSettings, SoftColliderBuilder};

#[path = "cli/soft_on_rigid_stack.rs"]
mod cli;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let cli = cli::Cli::parse();
    let mut viz = tetpbd_viz::Viz::from_options(cli.viz)?;
    let frames = cli.frames;
    let solver = SolverSettings {
        substeps: 10,
        diagnostics: tetpbd::DiagnosticSettings {
            measure_error: true,
            ..Default::default()
        },
        ..SolverSettings::default()
    };
    let mut scene = CoupledWorld::new(solver, CouplingSettings::default())?;
    scene.physics.insert(
        RigidBodyBuilder::fixed().translation(Vector::new(0.0, -0.5, 0.0)),
        ColliderBuilder::cuboid(5.0, 0.5, 5.0),
    );
    let mut boxes = Vec::new();
    for k in 0..3 {
        let (h, _) = scene.physics.insert(
            RigidBodyBuilder::dynamic().translation(Vector::new(0.0, 0.15 + 0.3 * k as f32, 0.0)),
            ColliderBuilder::cuboid(0.3, 0.15, 0.3).density(500.0),
        );
        boxes.push(h);
    }
    let mesh = generators::box_grid(Vector3::repeat(0.4), [3, 3, 3], CellSplit::Six)?;
    let cube = SoftBodyBuilder::new(mesh)
        .density(300.0)
        .edges(1e-6)
        .volume(0.0)
        .translation(Vector3::new(0.05, 1.6, 0.0))
        .build()?
        .spawn(&mut scene.soft);
    scene
        .soft
        .insert_one(cube, SoftColliderBuilder::new().friction(0.6).build()?)?;

    println!("frame contacts max_penetration_m edge_error_m top_box_y_m soft_min_y_m ms_per_frame");
    for frame in 0..frames {
        let t = Instant::now();
        let stats = scene.step()?;
        viz.frame(&scene)?;
        let ms = t.elapsed().as_secs_f64() * 1e3;
        let edge = stats.soft.edge.after.map_or(0.0, |e| e.max);
        let top = scene.physics.bodies[boxes[2]].translation().y;
        let low = scene.soft.get::<&tetpbd::Particles>(cube)?.aabb().0.y;
        println!(
            "{frame} {} {:.6} {edge:.6} {top:.4} {low:.4} {ms:.3}",
            stats.contacts, stats.max_penetration
        );
    }
    viz.finish()?;
    Ok(())
}
