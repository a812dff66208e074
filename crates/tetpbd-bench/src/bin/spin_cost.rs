//! Cost of [`tetpbd::SafetySettings::conserve_angular_momentum`]: a free cube (no pinned
//! particle, so the spin removal runs) of about 1k, 10k and 100k tetrahedra, stepped with
//! the removal on and off in alternating frames (two copies of the body, so a change of the
//! machine's load hits both alike). Prints median ms per frame of each, their ratio, and the
//! median ms per frame in the removal, including the copy back from the working copy it takes
//! over ([`tetpbd::StepStats::spin_time`]).
//!
//! ```text
//! cargo run --release -p tetpbd-bench --bin spin_cost [-- --frames F --set edges+volume|vertex-face]
//! ```

use clap::Parser;
use nalgebra::Vector3;
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{SoftBodyBuilder, Solver, SolverSettings, StepStats};
use tetpbd_bench::{median, FamilySet, DT};

/// Cost of the angular-momentum removal: free cubes of about 1k, 10k and 100k tetrahedra
/// stepped with the removal on and off in alternating frames.
#[derive(Parser)]
#[command(name = "spin_cost")]
struct Args {
    /// Frames measured per column (the median is printed).
    #[arg(long, default_value_t = 40)]
    frames: usize,
    /// The family set of the cube.
    #[arg(long, value_enum, default_value = "edges+volume")]
    set: FamilySet,
}

fn ms(d: std::time::Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let Args { frames, set } = Args::parse();
    let set = set.name();
    println!("free cube, {set}, zero gravity, slowly spinning; 10 substeps × 1 iteration per 1/60 s frame; median of {frames} frames per column");
    println!(
        "| tetrahedra | particles | off, ms/frame | on, ms/frame | on/off | removal with the copy back, ms/frame |"
    );
    println!("|---|---|---|---|---|---|");
    for cells in [6u32, 13, 28] {
        let mesh = box_grid(Vector3::new(1.0, 1.0, 1.0), [cells; 3], CellSplit::Five)?;
        let tets = mesh.tets.len();
        let mut worlds = Vec::new();
        for conserve in [false, true] {
            let b = SoftBodyBuilder::new(mesh.clone()).density(1000.0);
            let b = if set == "vertex-face" {
                b.vertex_face(1e-6)
            } else {
                b.edges(1e-6).volume(1e-9)
            };
            let mut world = hecs::World::new();
            let e = b.build()?.spawn(&mut world);
            // Benchmarks time the solver on awake bodies: sleeping would end the work being measured.
            world.insert_one(e, tetpbd::Activation::never_sleeps())?;
            {
                // A slow spin, so the corrections are not zero.
                let mut p = world.get::<&mut tetpbd::Particles>(e)?;
                let c = p.center_of_mass();
                for i in 0..p.len() {
                    let v = Vector3::new(0.0, 2.0, 0.0).cross(&(p.positions()[i] - c));
                    p.set_velocity(i, v)?;
                }
            }
            let solver = Solver::new(SolverSettings {
                dt: DT,
                gravity: Vector3::zeros(),
                safety: tetpbd::SafetySettings {
                    conserve_angular_momentum: conserve,
                    ..Default::default()
                },
                ..Default::default()
            })?;
            worlds.push((world, solver, Vec::new(), Vec::new()));
        }
        let particles = {
            let (w, _, _, _) = &mut worlds[0];
            w.query_mut::<&tetpbd::Particles>()
                .into_iter()
                .map(|p| p.len())
                .sum::<usize>()
        };
        for f in 0..frames + 2 {
            for (world, solver, total, spin) in worlds.iter_mut() {
                let s: StepStats = solver.step(world)?;
                if f >= 2 {
                    total.push(ms(s.total_time));
                    spin.push(ms(s.spin_time));
                }
            }
        }
        let off = median(worlds[0].2.clone());
        let on = median(worlds[1].2.clone());
        let removal = median(worlds[1].3.clone());
        println!(
            "| {tets} | {particles} | {off:.3} | {on:.3} | {:.3} | {removal:.3} |",
            on / off
        );
    }
    Ok(())
}
