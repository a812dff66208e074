//! Headless soft pile: nine soft cubes (4×4×4 cells, 1 m) dropped in the layout of rapier's
//! `fem_bench` "jelly pile". Soft–soft contacts are [`SoftContacts`]; the ground is rigid
//! (rapier, through the coupling, with the contacts as its extra hook) or, with `soft`, a
//! pinned soft slab with the contacts as the core solver's hook. Prints, per second of
//! simulated time, the largest particle speed and the largest penetrations of that second.
//!
//! ```text
//! cargo run --release --example soft_pile -- [rigid|soft] [SECONDS] [--export DIR] …
//! ```
//!
//! `-- --help` lists every option with its unit and default (the command line is in
//! `cli/soft_pile.rs`). Progress goes to standard error (a bar on a terminal, a line per 10 %
//! otherwise).

use clap::Parser;
use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder};
use tetpbd::generators::{self, CellSplit};
use tetpbd::{Particles, SoftBodyBuilder, Solver, SolverSettings};
use tetpbd_rapier::{
    CoupledWorld, CouplingSettings, DeformationDamping, SoftContactSettings, SoftContacts,
};

#[path = "cli/soft_pile.rs"]
mod cli;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let cli = cli::Cli::parse();
    let mut viz = tetpbd_viz::Viz::from_options(cli.viz)?;
    let soft_ground = cli.ground == cli::Ground::Soft;
    let seconds = cli.seconds;
    let solver = SolverSettings {
        substeps: 20,
        // The soft slab needs some drag; on rigid ground the coupling's deformation damping
        // is enough.
        damping: if soft_ground { 1.0 } else { 0.0 },
        ..SolverSettings::default()
    };
    let mut scene = CoupledWorld::new(solver.clone(), CouplingSettings::default())?;
    if soft_ground {
        spawn_slab(&mut scene.soft)?;
    } else {
        scene.physics.insert(
            RigidBodyBuilder::fixed().translation(Vector::new(0.0, -0.1, 0.0)),
            ColliderBuilder::cuboid(12.0, 0.1, 12.0),
        );
    }
    // fem_bench layout: 3 × 3 grid of 1 m pitch, cube i centred at height 0.55 + 1.05 i.
    let cube = generators::box_grid(Vector3::repeat(1.0), [4, 4, 4], CellSplit::Six)?;
    for i in 0..9 {
        let at = Vector3::new(
            (i % 3) as f32 - 1.0,
            0.55 + i as f32 * 1.05,
            (i / 3) as f32 - 1.0,
        );
        let e = SoftBodyBuilder::new(cube.clone())
            .density(1000.0)
            .edges(0.0)
            .volume(0.0)
            .translation(at)
            .build()?
            .spawn(&mut scene.soft);
        if !soft_ground {
            scene.soft.insert_one(e, DeformationDamping::new(5.0)?)?;
        }
    }

    let mut core = Solver::new(solver)?;
    let mut contacts = SoftContacts::new(SoftContactSettings::default())?;
    let frames_per_second = (1.0 / core.settings.dt).round() as u32;
    println!(
        "ground: {}\n  t (s)   max|v| (m/s)   soft pen. (m)   ground pen. (m)   soft contacts   clamps   ms/frame",
        if soft_ground { "pinned soft slab" } else { "rigid (rapier)" }
    );
    let mut progress =
        tetpbd_viz::Progress::new("soft_pile frames", u64::from(seconds * frames_per_second));
    for second in 1..=seconds {
        let (mut v, mut pen, mut ground, mut clamps, mut ms) = (0.0f32, 0.0f32, 0.0f32, 0u64, 0.0);
        for _ in 0..frames_per_second {
            let t = std::time::Instant::now();
            if soft_ground {
                core.step_with(&mut scene.soft, &mut contacts)?;
            } else {
                ground = ground.max(scene.step_with(&mut contacts)?.max_penetration);
            }
            ms += t.elapsed().as_secs_f64() * 1e3;
            viz.frame(&scene)?;
            progress.inc(1);
            let c = contacts.stats();
            pen = pen.max(c.max_penetration);
            clamps += c.clamps;
            for p in scene.soft.query_mut::<&Particles>() {
                v = v.max(p.max_speed());
            }
        }
        progress.suspend(|| {
            println!(
                "{second:>7} {v:>14.4} {pen:>15.5} {ground:>17.5} {:>15} {clamps:>8} {:>10.2}",
                contacts.stats().contacts,
                ms / f64::from(frames_per_second)
            )
        });
    }
    progress.finish();
    viz.finish()?;
    Ok(())
}

/// An 8 m × 0.2 m × 8 m soft slab with its top at y = 0, bottom and sides pinned.
fn spawn_slab(world: &mut hecs::World) -> Result<(), Box<dyn std::error::Error>> {
    let slab = generators::box_grid(Vector3::new(8.0, 0.2, 8.0), [16, 1, 16], CellSplit::Six)?;
    let pinned: Vec<u32> = (0..slab.vertices.len() as u32)
        .filter(|&i| {
            let v = slab.vertices[i as usize];
            v.y < -0.1 + 1e-4 || v.x.abs() > 4.0 - 1e-4 || v.z.abs() > 4.0 - 1e-4
        })
        .collect();
    SoftBodyBuilder::new(slab)
        .edges(0.0)
        .volume(0.0)
        .pinned(pinned)
        .translation(Vector3::new(0.0, -0.1, 0.0))
        .build()?
        .spawn(world);
    Ok(())
}
