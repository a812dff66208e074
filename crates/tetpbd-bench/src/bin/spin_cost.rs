//! Cost of [`tetpbd::SafetySettings::conserve_angular_momentum`]: a free cube (no pinned
//! particle, so the spin removal runs) of about 1k, 10k and 100k tetrahedra, stepped with
//! the removal on and off in alternating frames (two copies of the body, so a change of the
//! machine's load hits both alike). Prints median ms per frame of each, their ratio, and the
//! median ms per frame in the removal, including the copy back from the working copy it takes
//! over ([`tetpbd::StepStats::spin_time`]).
//!
//! ```text
//! cargo run --release -p tetpbd-bench --bin spin_cost [-- --frames F --set edges+volume|vertex-face|material]
//! ```

use clap::Parser;
use nalgebra::Vector3;
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd_bench::{free_body, median, step_alternately, zero_gravity_solver, FamilySet};

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

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let Args { frames, set } = Args::parse();
    println!("free cube, {}, zero gravity, slowly spinning; 10 substeps × 1 iteration per 1/60 s frame; median of {frames} frames per column", set.name());
    println!(
        "| tetrahedra | particles | off, ms/frame | on, ms/frame | on/off | removal with the copy back, ms/frame |"
    );
    println!("|---|---|---|---|---|---|");
    for cells in [6u32, 13, 28] {
        let mesh = box_grid(Vector3::new(1.0, 1.0, 1.0), [cells; 3], CellSplit::Five)?;
        let mut runs = Vec::new();
        for conserve in [false, true] {
            let (world, _) = free_body(&mesh, 2.0, |b| set.add_to(b))?;
            let solver = zero_gravity_solver(|s| s.safety.conserve_angular_momentum = conserve)?;
            runs.push((world, solver));
        }
        let (mut total, mut spin) = ([Vec::new(), Vec::new()], Vec::new());
        step_alternately(&mut runs, frames, |run, _, stats, _| {
            total[run].push(stats.total_time.as_secs_f64() * 1e3);
            if run == 1 {
                spin.push(stats.spin_time.as_secs_f64() * 1e3);
            }
            Ok(())
        })?;
        let [off, on] = total.map(median);
        println!(
            "| {} | {} | {off:.3} | {on:.3} | {:.3} | {:.3} |",
            mesh.tets.len(),
            mesh.vertices.len(),
            on / off,
            median(spin)
        );
    }
    Ok(())
}
