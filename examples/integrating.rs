//! An existing rapier game loop gaining soft bodies: the code `docs/guide/integrating.md`
//! walks through.
//!
//! The game keeps its rapier state (`Physics`: rapier's own pipeline and sets) and its loop:
//! a fixed physics step driven by an accumulator, rendering at another rate with the state
//! interpolated between the last two steps. Soft bodies add a hecs world, a [`Coupling`] and
//! one changed line: where the loop called `PhysicsPipeline::step`, it hands the same
//! arguments to [`Coupling::step`] ([`RapierContext::new`]). The mouse picks by ray cast and
//! drags with a [`Grab`]; contact reports come from the coupling (soft) and from rapier's
//! event handler (rigid).
//!
//! Headless, the mouse scripted; prints one line per rendered frame. Run with
//! `cargo run --release --example integrating -- --frames 240`; `-- --help` lists every
//! option (the command line is in `cli/integrating.rs`).

use std::sync::mpsc;
use std::time::{Duration, Instant};

use clap::Parser;
use nalgebra::Vector3;
use rapier3d::prelude::*;
use tetpbd_rapier::prelude::*;
use tetpbd_rapier::DeformationDamping;

#[path = "cli/integrating.rs"]
mod cli;
#[path = "game/picking.rs"]
mod picking;
#[path = "game/render.rs"]
mod render;

/// The game's rapier state as it was before soft bodies came: rapier's own pipeline and
/// sets, each step a call of `PhysicsPipeline::step` with all of them.
struct Physics {
    pipeline: PhysicsPipeline,
    gravity: Vector,
    params: IntegrationParameters,
    islands: IslandManager,
    broad_phase: DefaultBroadPhase,
    narrow_phase: NarrowPhase,
    bodies: RigidBodySet,
    colliders: ColliderSet,
    impulse_joints: ImpulseJointSet,
    multibody_joints: MultibodyJointSet,
    rapier_soft_bodies: SoftBodySet,
    ccd: CCDSolver,
}

impl Physics {
    fn new(dt: f32) -> Physics {
        Physics {
            pipeline: PhysicsPipeline::new(),
            gravity: Vector::new(0.0, -9.81, 0.0),
            params: IntegrationParameters {
                dt,
                ..IntegrationParameters::default()
            },
            islands: IslandManager::new(),
            broad_phase: DefaultBroadPhase::default(),
            narrow_phase: NarrowPhase::new(),
            bodies: RigidBodySet::new(),
            colliders: ColliderSet::new(),
            impulse_joints: ImpulseJointSet::new(),
            multibody_joints: MultibodyJointSet::new(),
            rapier_soft_bodies: SoftBodySet::new(),
            ccd: CCDSolver::new(),
        }
    }

    /// The arguments the loop used to give `PhysicsPipeline::step`, borrowed for the
    /// coupling, which runs rapier's step itself and then the soft bodies.
    fn context<'a>(&'a mut self, events: &'a dyn EventHandler) -> RapierContext<'a> {
        RapierContext::new(
            &mut self.pipeline,
            self.gravity,
            &self.params,
            &mut self.islands,
            &mut self.broad_phase,
            &mut self.narrow_phase,
            &mut self.bodies,
            &mut self.colliders,
            &mut self.impulse_joints,
            &mut self.multibody_joints,
            &mut self.rapier_soft_bodies,
            &mut self.ccd,
        )
        .with_events(events)
    }
}

/// The scene: ground, a crate and a ball (rigid, with collision events), and a jelly cube.
fn build_scene(
    physics: &mut Physics,
    soft: &mut hecs::World,
) -> Result<hecs::Entity, Box<dyn std::error::Error>> {
    let ground = physics
        .bodies
        .insert(RigidBodyBuilder::fixed().translation(Vector::new(0.0, -0.5, 0.0)));
    physics.colliders.insert_with_parent(
        ColliderBuilder::cuboid(5.0, 0.5, 5.0),
        ground,
        &mut physics.bodies,
    );
    for (at, collider) in [
        (
            Vector::new(0.7, 0.2, 0.0),
            ColliderBuilder::cuboid(0.2, 0.2, 0.2),
        ),
        (Vector::new(-0.6, 1.0, 0.1), ColliderBuilder::ball(0.1)),
    ] {
        let body = physics
            .bodies
            .insert(RigidBodyBuilder::dynamic().translation(at));
        let collider = collider.active_events(ActiveEvents::COLLISION_EVENTS);
        physics
            .colliders
            .insert_with_parent(collider, body, &mut physics.bodies);
    }
    let mesh = generators::box_grid(Vector3::repeat(0.4), [4, 4, 4], generators::CellSplit::Six)?;
    let jelly = TetBodyBuilder::new(mesh)
        .density(300.0)
        .edges(1e-5)
        .volume(1e-10)
        .translation(Vector3::new(0.0, 0.45, 0.0))
        .build()?
        .spawn(soft);
    soft.insert(
        jelly,
        (
            SoftColliderBuilder::new().friction(0.6).build()?,
            DeformationDamping::new(5.0)?,
        ),
    )?;
    Ok(jelly)
}

/// What one rendered frame's physics did, for the statistics line.
#[derive(Default)]
struct FrameReport {
    steps: u32,
    soft_contacts: usize,
    max_impulse: f32,
    rigid_events: usize,
    physics_time: Duration,
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let cli = cli::Cli::parse();
    let mut viz = tetpbd_viz::Viz::from_options(cli.viz)?;
    let dt = 1.0 / cli.physics_hz;
    let render_dt = 1.0 / cli.render_hz;
    let mut physics = Physics::new(dt);
    let mut soft = hecs::World::new();
    let jelly = build_scene(&mut physics, &mut soft)?;
    let solver = SolverSettings {
        substeps: cli.substeps,
        ..SolverSettings::default()
    };
    let mut coupling = Coupling::new(solver, CouplingSettings::default())?;
    let (collision_send, collision_recv) = mpsc::channel();
    let (force_send, _force_recv) = mpsc::channel();
    let (tear_send, _tear_recv) = mpsc::channel();
    let events = ChannelEventCollector::new(collision_send, force_send, tear_send);
    let mut surfaces = render::Surfaces::new(&soft);
    let mut mouse = picking::ScriptedMouse::new(cli.frames, Vector3::new(0.0, 1.2, 2.5));

    println!("frame steps alpha soft_contacts max_impulse_Ns rigid_events grab_error_m grab_force_N jelly_y_m drawn_y_m physics_ms");
    let mut accumulator = 0.0f32;
    let mut total = FrameReport::default();
    for frame in 0..cli.frames {
        // Input at the display rate: the mouse presses, drags, lets go.
        mouse.update(frame, &mut soft)?;
        accumulator += render_dt;
        let mut report = FrameReport::default();
        while accumulator >= dt && report.steps < cli.max_steps_per_frame {
            let t = Instant::now();
            let stats = coupling.step(&mut soft, physics.context(&events))?;
            report.physics_time += t.elapsed();
            report.steps += 1;
            report.soft_contacts = stats.contacts;
            report.max_impulse = coupling
                .contacts()
                .iter()
                .map(|c| c.impulse.norm())
                .fold(0.0, f32::max);
            report.rigid_events += collision_recv.try_iter().count();
            surfaces.after_step(&soft);
            accumulator -= dt;
        }
        if report.steps == cli.max_steps_per_frame {
            accumulator = accumulator.min(dt); // drop what the frame could not catch up
        }
        let alpha = accumulator / dt;
        surfaces.interpolate(alpha);
        viz.frame(&(&soft, &physics.bodies, &physics.colliders))?;
        print_frame(frame, alpha, &report, &soft, jelly, &surfaces);
        total.steps += report.steps;
        total.physics_time += report.physics_time;
        total.rigid_events += report.rigid_events;
    }
    viz.finish()?;
    println!(
        "done: {} rendered frames, {} physics steps ({:.3} ms each), {} rigid collision events, {}",
        cli.frames,
        total.steps,
        total.physics_time.as_secs_f64() * 1e3 / f64::from(total.steps.max(1)),
        total.rigid_events,
        mouse.summary()
    );
    Ok(())
}

fn print_frame(
    frame: usize,
    alpha: f32,
    r: &FrameReport,
    soft: &hecs::World,
    jelly: hecs::Entity,
    surfaces: &render::Surfaces,
) {
    let p = soft
        .get::<&Particles>(jelly)
        .expect("the jelly is in the world");
    let (grab_error, grab_force) = match soft.get::<&Grab>(jelly) {
        Ok(g) => {
            let t = soft
                .get::<&Tetrahedra>(jelly)
                .expect("a soft body has tetrahedra");
            (g.error(&p, &t).unwrap_or(f32::NAN), g.force().norm())
        }
        Err(_) => (0.0, 0.0),
    };
    println!(
        "{frame} {} {alpha:.3} {} {:.4} {} {grab_error:.4} {grab_force:.1} {:.4} {:.4} {:.3}",
        r.steps,
        r.soft_contacts,
        r.max_impulse,
        r.rigid_events,
        p.center_of_mass().y,
        surfaces.drawn_centre(jelly).map_or(f32::NAN, |c| c.y),
        r.physics_time.as_secs_f64() * 1e3
    );
}
