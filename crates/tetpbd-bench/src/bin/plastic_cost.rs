//! Cost of [`tetpbd::Plasticity`]: a free cube of about 1k, 10k and 100k tetrahedra (edges +
//! volume), stepped with and without the component in alternating frames (two copies, so a
//! change of the machine's load hits both alike), slowly spinning within the yield; then the
//! flow pass alone ([`tetpbd::systems::flow_plastically`]) on a copy held twisted in a mould
//! past the yield, where every tetrahedron flows every frame. Prints medians, ms per frame.
//!
//! ```text
//! cargo run --release -p tetpbd-bench --bin plastic_cost [-- --frames F]
//! ```

use std::time::Instant;

use clap::Parser;
use nalgebra::Vector3;
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{Particles, PlasticitySettings, SoftBodyBuilder};
use tetpbd_bench::{free_body, median, step_alternately, zero_gravity_solver, DT};

/// Cost of plasticity: free cubes of about 1k, 10k and 100k tetrahedra with and without the
/// component, then the flow pass alone with every tetrahedron flowing.
#[derive(Parser)]
#[command(name = "plastic_cost")]
struct Args {
    /// Frames measured per column (the median is printed).
    #[arg(long, default_value_t = 40)]
    frames: usize,
}

/// `b` with the benchmark's families and, for `plastic`, the default plasticity.
fn with_plasticity(b: SoftBodyBuilder, plastic: bool) -> SoftBodyBuilder {
    let b = b.edges(1e-6).volume(1e-9);
    if plastic {
        b.plasticity(PlasticitySettings::default())
    } else {
        b
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let frames = Args::parse().frames;
    println!("free cube, edges 1e-6 m/N + volume 1e-9 m⁵/N, zero gravity; 10 substeps × 1 iteration per 1/60 s frame; default plasticity settings; median of {frames} frames");
    println!("| tetrahedra | without, ms/frame | with, within the yield, ms/frame | with/without | flow pass, every tetrahedron flowing, ms/frame |");
    println!("|---|---|---|---|---|");
    for cells in [6u32, 13, 28] {
        let mesh = box_grid(Vector3::new(1.0, 1.0, 1.0), [cells; 3], CellSplit::Five)?;
        let tets = mesh.tets.len();
        let mut runs = Vec::new();
        for plastic in [false, true] {
            let (world, _) = free_body(&mesh, 2.0, |b| with_plasticity(b, plastic))?;
            runs.push((world, zero_gravity_solver(|_| ())?));
        }
        let mut times = [Vec::new(), Vec::new()];
        step_alternately(&mut runs, frames, |run, ms, _, _| {
            times[run].push(ms);
            Ok(())
        })?;
        let [without, with] = times.map(median);
        // Every tetrahedron past the yield: twisted by 1 rad/m, pinned there.
        let (mut world, e) = free_body(&mesh, 0.0, |b| with_plasticity(b, true))?;
        {
            let mut p = world.get::<&mut Particles>(e)?;
            for i in 0..p.len() {
                let x = p.rest_positions()[i];
                let (s, c) = x.x.sin_cos();
                p.set_position(i, Vector3::new(x.x, c * x.y - s * x.z, s * x.y + c * x.z))?;
            }
        }
        let mut flow = Vec::new();
        for _ in 0..frames {
            let t = Instant::now();
            let n = tetpbd::systems::flow_plastically(&mut world, DT);
            flow.push(t.elapsed().as_secs_f64() * 1e3);
            assert!(n > tets / 2, "only {n} of {tets} tetrahedra flowed");
        }
        println!(
            "| {tets} | {without:.3} | {with:.3} | {:.3} | {:.3} |",
            with / without,
            median(flow)
        );
    }
    Ok(())
}
