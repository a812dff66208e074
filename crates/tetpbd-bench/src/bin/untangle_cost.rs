//! Cost of the tangle recovery ([`tetpbd::Untangle`]) on ordinary frames: a free, calm,
//! untangled cube of about 1k, 10k and 100k tetrahedra in zero gravity (the recovery's most
//! expensive ordinary case: checked once per window, never moved), stepped with the recovery
//! on and off in alternating frames (two copies of the body, so a change of the machine's
//! load hits both alike). Prints the mean ms per frame of each (the check runs once per window
//! of frames, so the mean, not the median, carries it), their ratio, and the frames in which
//! the recovery moved the body (0: it found it untangled, as it should).
//!
//! ```text
//! cargo run --release -p tetpbd-bench --bin untangle_cost [-- --frames F --set edges+volume|vertex-face]
//! ```

use clap::Parser;
use nalgebra::Vector3;
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{SoftBodyBuilder, Solver, SolverSettings, StepStats, Untangle};
use tetpbd_bench::{FamilySet, DT};

/// Cost of the tangle recovery: free calm cubes of about 1k, 10k and 100k tetrahedra stepped
/// with the recovery on and off in alternating frames.
#[derive(Parser)]
#[command(name = "untangle_cost")]
struct Args {
    /// Frames measured per column (the mean is printed).
    #[arg(long, default_value_t = 120)]
    frames: usize,
    /// The family set of the cube.
    #[arg(long, value_enum, default_value = "edges+volume")]
    set: FamilySet,
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let Args { frames, set } = Args::parse();
    let set = set.name();
    println!("free cube at rest, {set}, zero gravity, never sleeping; 10 substeps × 1 iteration per 1/60 s frame; mean of {frames} frames per column");
    println!("| tetrahedra | off, ms/frame | on, ms/frame | on/off | frames moved |");
    println!("|---|---|---|---|---|");
    for cells in [6u32, 13, 28] {
        let mesh = box_grid(Vector3::new(1.0, 1.0, 1.0), [cells; 3], CellSplit::Five)?;
        let tets = mesh.tets.len();
        let mut worlds = Vec::new();
        for on in [false, true] {
            let b = SoftBodyBuilder::new(mesh.clone()).density(1000.0);
            let b = if set == "vertex-face" {
                b.vertex_face(1e-6)
            } else {
                b.edges(1e-6).volume(1e-9)
            };
            let mut world = hecs::World::new();
            let e = b.build()?.spawn(&mut world);
            world.insert_one(e, tetpbd::Activation::never_sleeps())?;
            world.get::<&mut Untangle>(e)?.disabled = !on;
            let solver = Solver::new(SolverSettings {
                dt: DT,
                gravity: Vector3::zeros(),
                ..Default::default()
            })?;
            worlds.push((world, solver, 0.0f64, 0usize));
        }
        for f in 0..frames + 2 {
            for (world, solver, total, moved) in worlds.iter_mut() {
                let s: StepStats = solver.step(world)?;
                if f >= 2 {
                    *total += s.total_time.as_secs_f64() * 1e3 / frames as f64;
                    *moved += s.bodies_untangled;
                }
            }
        }
        let (off, on) = (worlds[0].2, worlds[1].2);
        println!(
            "| {tets} | {off:.3} | {on:.3} | {:.3} | {} |",
            on / off,
            worlds[1].3
        );
    }
    Ok(())
}
