//! Tearing and cutting: a soft slab pulled apart by two rigid bodies tears into pieces, a soft
//! cube is cut in two by a blade, and the same slab is pulled apart with rapier 0.36's own soft
//! body for comparison.
//!
//! Headless; prints every tear as it happens. Run with
//! `cargo run --release --example tearing -- [--speed M_PER_S] [--export DIR] …`;
//! `-- --help` lists every option with its unit and default (the command line is in
//! `cli/tearing.rs`). The slab's scene, in either engine, is `tetpbd_bench::SlabPull`.

use clap::Parser;
use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder};
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{Blade, Particles, SoftBodyBuilder, SolverSettings, TearEvent, TearingSettings};
use tetpbd_bench::{Fragment, SlabPull, TearEngine, TearSummary};
use tetpbd_rapier::{follow_pieces, CoupledWorld, CouplingSettings, SoftCollider};
use tetpbd_viz::Viz;

#[path = "cli/tearing.rs"]
mod cli;

/// What one engine's pull measured.
struct Pulled {
    events: usize,
    pieces: usize,
    fastest: f32,
    median_ms: f64,
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let cli = cli::Cli::parse();
    let mut viz = Viz::from_options(cli.viz)?;
    println!("== tetpbd: a slab pulled apart at {} m/s", cli.speed);
    let ours = pull(
        TearEngine::Tetpbd,
        cli.speed,
        cli.settle_frames,
        &mut viz,
        true,
    )?;
    println!("== tetpbd: a soft cube cut by a blade");
    cut_cube(&mut viz)?;
    viz.finish()?;
    let mut rows = vec![("tetpbd", ours)];
    if !cli.no_rapier {
        println!("== rapier 0.36: the same slab pulled apart");
        let mut off = Viz::from_options(Default::default())?;
        let theirs = pull(
            TearEngine::Rapier,
            cli.speed,
            cli.settle_frames,
            &mut off,
            false,
        )?;
        rows.push(("rapier", theirs));
    }
    println!("== side by side at {} m/s", cli.speed);
    println!("engine tear_events pieces fastest_fragment_m_s median_ms_per_frame");
    for (name, r) in rows {
        println!(
            "{name} {} {} {:.2} {:.3}",
            r.events, r.pieces, r.fastest, r.median_ms
        );
    }
    Ok(())
}

/// Pulls the slab apart in `engine` and lets it settle, printing each tear (and, with
/// `every_frame`, one line per frame); `viz` records each frame.
fn pull(
    engine: TearEngine,
    speed: f32,
    settle: usize,
    viz: &mut Viz,
    every_frame: bool,
) -> Result<Pulled, Box<dyn std::error::Error>> {
    let mut scene = SlabPull::new(engine, speed, SlabPull::stiff)?;
    let frames = scene.pull_frames() + settle;
    let mut ms = Vec::with_capacity(frames);
    let mut events = 0;
    let mut fastest = 0.0f32;
    if every_frame {
        println!("frame pieces fastest_fragment_m_s ms_per_frame");
    }
    for frame in 0..frames {
        let (tears, t) = scene.step_timed()?;
        viz.frame(&scene.world)?;
        ms.push(t);
        events += tears.len();
        for tear in &tears {
            print_tear(frame, tear);
        }
        let pieces = scene.fragments();
        let now = pieces.iter().map(Fragment::speed).fold(0.0, f32::max);
        fastest = fastest.max(now);
        if every_frame {
            println!("{frame} {} {now:.2} {t:.3}", pieces.len());
        }
    }
    ms.sort_by(f64::total_cmp);
    Ok(Pulled {
        events,
        pieces: scene.fragments().len(),
        fastest,
        median_ms: ms.get(ms.len() / 2).copied().unwrap_or(0.0),
    })
}

fn print_tear(frame: usize, tear: &TearSummary) {
    println!(
        "  tear at frame {frame}: body {} → new pieces [{}], {} torn, {} particles copied",
        tear.body,
        tear.new_pieces.join(", "),
        tear.torn,
        tear.particles_copied
    );
}

/// A 0.3 m soft cube (4³ cells) settles on the ground for 20 frames, is cut by a tilted plane
/// through its middle, and its halves fall apart for 40 frames.
fn cut_cube(viz: &mut Viz) -> Result<(), Box<dyn std::error::Error>> {
    let solver = SolverSettings {
        substeps: 10,
        ..SolverSettings::default()
    };
    let mut scene = CoupledWorld::new(solver, CouplingSettings::default())?;
    scene.physics.insert(
        RigidBodyBuilder::fixed().translation(Vector::new(0.0, -0.5, 0.0)),
        ColliderBuilder::cuboid(5.0, 0.5, 5.0),
    );
    let mesh = box_grid(Vector3::repeat(0.3), [4, 4, 4], CellSplit::Six)?;
    let cube = SoftBodyBuilder::new(mesh)
        .edges(1e-6)
        .volume(1e-8)
        .tearing(TearingSettings::default())
        .translation(Vector3::new(0.0, 0.16, 0.0))
        .build()?
        .spawn(&mut scene.soft);
    scene.soft.insert_one(cube, SoftCollider::default())?;
    for _ in 0..20 {
        scene.step()?;
        viz.frame(&scene)?;
    }
    let blade = Blade::Plane {
        point: Vector3::new(0.01, 0.0, 0.0),
        normal: Vector3::new(1.0, 0.2, 0.3),
    };
    let Some(event) = tetpbd::cut(&mut scene.soft, cube, &blade)? else {
        println!("the blade missed the cube");
        return Ok(());
    };
    print_cut(&event);
    // The coupling's components (collider, attachments) follow the pieces.
    follow_pieces(&mut scene.soft, &event);
    for _ in 0..40 {
        scene.step()?;
        viz.frame(&scene)?;
    }
    for (k, piece) in event.pieces.iter().enumerate() {
        let p = scene.soft.get::<&Particles>(piece.entity)?;
        let c = p.center_of_mass();
        println!(
            "  piece {k} ({:?}): {} particles, {:.3} kg, centre ({:.3}, {:.3}, {:.3}) m after 40 frames",
            piece.entity,
            p.len(),
            p.masses().iter().sum::<f32>(),
            c.x,
            c.y,
            c.z
        );
    }
    Ok(())
}

fn print_cut(event: &TearEvent) {
    let new: Vec<String> = event.new_entities().map(|e| format!("{e:?}")).collect();
    println!(
        "  cut: body {:?} → new pieces [{}], {} faces cut, {} particles copied ({} before)",
        event.body,
        new.join(", "),
        event.faces_torn,
        event.particles_added(),
        event.particles_before
    );
}
