//! Cost of the tangle recovery ([`tetpbd::Untangle`]) on ordinary frames: a free, calm,
//! untangled cube of about 1k, 10k and 100k tetrahedra in zero gravity (the recovery's most
//! expensive ordinary case: checked once per window, never moved), stepped with the recovery
//! on and off in alternating frames (two copies of the body, so a change of the machine's
//! load hits both alike). Prints the mean ms per frame of each (the check runs once per window
//! of frames, so the mean, not the median, carries it), their ratio, and the frames in which
//! the recovery moved the body (0: it found it untangled, as it should).
//!
//! ```text
//! cargo run --release -p tetpbd-bench --bin untangle_cost [-- --frames F --set edges+volume|vertex-face|material]
//! ```

use clap::Parser;
use nalgebra::Vector3;
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::Untangle;
use tetpbd_bench::{free_body, step_alternately, zero_gravity_solver, FamilySet};

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
    println!("free cube at rest, {}, zero gravity, never sleeping; 10 substeps × 1 iteration per 1/60 s frame; mean of {frames} frames per column", set.name());
    println!("| tetrahedra | off, ms/frame | on, ms/frame | on/off | frames moved |");
    println!("|---|---|---|---|---|");
    for cells in [6u32, 13, 28] {
        let mesh = box_grid(Vector3::new(1.0, 1.0, 1.0), [cells; 3], CellSplit::Five)?;
        let mut runs = Vec::new();
        for on in [false, true] {
            let (world, e) = free_body(&mesh, 0.0, |b| set.add_to(b))?;
            world.get::<&mut Untangle>(e)?.disabled = !on;
            runs.push((world, zero_gravity_solver(|_| ())?));
        }
        let (mut total, mut moved) = ([0.0f64; 2], 0usize);
        step_alternately(&mut runs, frames, |run, _, stats, _| {
            total[run] += stats.total_time.as_secs_f64() * 1e3 / frames as f64;
            if run == 1 {
                moved += stats.bodies_untangled;
            }
            Ok(())
        })?;
        let [off, on] = total;
        println!(
            "| {} | {off:.3} | {on:.3} | {:.3} | {moved} |",
            mesh.tets.len(),
            on / off
        );
    }
    Ok(())
}
