//! A soft body riding a kinematic platform that moves back and forth, stepped through the
//! integrator's own rapier state (`RapierContext`) rather than the convenience world.
//!
//! Headless; prints one line of statistics per frame. Run with
//! `cargo run --release --example kinematic_platform -- [FRAMES] [--export DIR] [--strip FILE] …`;
//! `-- --help` lists every option with its unit and default (the command line is in
//! `cli/kinematic_platform.rs`).

use std::time::Instant;

use clap::Parser;

use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{
    BroadPhaseBvh, CCDSolver, ColliderBuilder, ColliderSet, ImpulseJointSet, IntegrationParameters,
    IslandManager, MultibodyJointSet, NarrowPhase, PhysicsPipeline, RigidBodyBuilder, RigidBodySet,
    SoftBodySet,
};
use tetpbd::generators::{self, CellSplit};
use tetpbd::{Particles, SoftBodyBuilder, SolverSettings};
use tetpbd_rapier::{Coupling, CouplingSettings, RapierContext, SoftColliderBuilder};

#[path = "cli/kinematic_platform.rs"]
mod cli;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let cli = cli::Cli::parse();
    let mut viz = tetpbd_viz::Viz::from_options(cli.viz)?;
    let frames = cli.frames;
    // The integrator's rapier state.
    let mut pipeline = PhysicsPipeline::new();
    let params = IntegrationParameters::default();
    let mut islands = IslandManager::new();
    let mut broad_phase = BroadPhaseBvh::new();
    let mut narrow_phase = NarrowPhase::new();
    let mut bodies = RigidBodySet::new();
    let mut colliders = ColliderSet::new();
    let mut impulse_joints = ImpulseJointSet::new();
    let mut multibody_joints = MultibodyJointSet::new();
    let mut rapier_soft = SoftBodySet::new();
    let mut ccd = CCDSolver::new();
    let gravity = Vector::new(0.0, -9.81, 0.0);

    let platform = bodies.insert(
        RigidBodyBuilder::kinematic_position_based().translation(Vector::new(0.0, -0.05, 0.0)),
    );
    colliders.insert_with_parent(
        ColliderBuilder::cuboid(0.6, 0.05, 0.6),
        platform,
        &mut bodies,
    );

    let mut world = hecs::World::new();
    let mesh = generators::box_grid(Vector3::new(0.3, 0.2, 0.3), [3, 2, 3], CellSplit::Six)?;
    let soft = SoftBodyBuilder::new(mesh)
        .density(400.0)
        .edges(1e-6)
        .volume(0.0)
        .translation(Vector3::new(0.0, 0.1025, 0.0))
        .build()?
        .spawn(&mut world);
    world.insert_one(soft, SoftColliderBuilder::new().friction(0.9).build()?)?;

    let solver = SolverSettings {
        substeps: 10,
        diagnostics: tetpbd::DiagnosticSettings {
            measure_error: true,
            ..Default::default()
        },
        ..SolverSettings::default()
    };
    let mut coupling = Coupling::new(solver, CouplingSettings::default())?;

    println!("frame contacts max_penetration_m edge_error_m platform_x_m soft_x_m ms_per_frame");
    for frame in 0..frames {
        let t_sim = frame as f32 * params.dt;
        let x = 0.4 * (1.5 * t_sim).sin();
        bodies[platform].set_next_kinematic_translation(Vector::new(x, -0.05, 0.0));
        let t = Instant::now();
        let stats = coupling.step(
            &mut world,
            RapierContext {
                pipeline: &mut pipeline,
                gravity,
                integration_parameters: &params,
                islands: &mut islands,
                broad_phase: &mut broad_phase,
                narrow_phase: &mut narrow_phase,
                bodies: &mut bodies,
                colliders: &mut colliders,
                impulse_joints: &mut impulse_joints,
                multibody_joints: &mut multibody_joints,
                soft_bodies: &mut rapier_soft,
                ccd_solver: &mut ccd,
                hooks: &(),
                events: &(),
            },
        )?;
        let ms = t.elapsed().as_secs_f64() * 1e3;
        viz.frame(&(&world, &bodies, &colliders))?;
        let edge = stats.soft.edge.after.map_or(0.0, |e| e.max);
        let soft_x = world.get::<&Particles>(soft)?.center_of_mass().x;
        println!(
            "{frame} {} {:.6} {edge:.6} {:.4} {soft_x:.4} {ms:.3}",
            stats.contacts,
            stats.max_penetration,
            bodies[platform].translation().x
        );
    }
    viz.finish()?;
    Ok(())
}
