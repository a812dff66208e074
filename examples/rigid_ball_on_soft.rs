//! A rigid ball dropped onto a row of soft cubes lying on fixed ground.
//!
//! Headless; prints one line of statistics per frame. Run with
//! `cargo run --release --example rigid_ball_on_soft -- [FRAMES] [--export DIR] [--strip FILE] …`;
//! `-- --help` lists every option with its unit and default (the command line is in
//! `cli/rigid_ball_on_soft.rs`).

use std::time::Instant;

use clap::Parser;

use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder};
use tetpbd::generators::{self, CellSplit};
use tetpbd::{SoftBodyBuilder, SolverSettings};
use tetpbd_rapier::{CoupledWorld, CouplingSettings, DeformationDamping};

#[path = "cli/rigid_ball_on_soft.rs"]
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
    for k in 0..3 {
        let mesh = generators::box_grid(Vector3::repeat(0.3), [3, 3, 3], CellSplit::Six)?;
        let e = SoftBodyBuilder::new(mesh)
            .density(500.0)
            .edges(1e-5)
            .volume(1e-10)
            .translation(Vector3::new(-0.35 + 0.35 * k as f32, 0.1525, 0.0))
            .build()?
            .spawn(&mut scene.soft);
        scene.soft.insert_one(e, DeformationDamping::new(5.0)?)?;
    }
    let (ball, _) = scene.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vector::new(0.05, 1.2, 0.02)),
        ColliderBuilder::ball(0.12).density(2000.0),
    );

    println!("frame contacts max_penetration_m edge_error_m ball_y_m ball_vy_m_s ms_per_frame");
    for frame in 0..frames {
        let t = Instant::now();
        let stats = scene.step()?;
        viz.frame(&scene)?;
        let ms = t.elapsed().as_secs_f64() * 1e3;
        let edge = stats.soft.edge.after.map_or(0.0, |e| e.max);
        let b = &scene.physics.bodies[ball];
        println!(
            "{frame} {} {:.6} {edge:.6} {:.4} {:.4} {ms:.3}",
            stats.contacts,
            stats.max_penetration,
            b.translation().y,
            b.linvel().y
        );
    }
    viz.finish()?;
    Ok(())
}
