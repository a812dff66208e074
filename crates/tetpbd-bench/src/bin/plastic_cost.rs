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
use tetpbd::{Particles, PlasticitySettings, SoftBodyBuilder, Solver, SolverSettings};
use tetpbd_bench::{median, DT};

/// Cost of plasticity: free cubes of about 1k, 10k and 100k tetrahedra with and without the
/// component, then the flow pass alone with every tetrahedron flowing.
#[derive(Parser)]
#[command(name = "plastic_cost")]
struct Args {
    /// Frames measured per column (the median is printed).
    #[arg(long, default_value_t = 40)]
    frames: usize,
}

fn body(mesh: &tetpbd::TetMesh, plastic: bool) -> Result<tetpbd::SoftBody, tetpbd::BuildError> {
    let b = SoftBodyBuilder::new(mesh.clone())
        .density(1000.0)
        .edges(1e-6)
        .volume(1e-9);
    let b = if plastic {
        b.plasticity(PlasticitySettings::default())
    } else {
        b
    };
    b.build()
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
            let mut world = hecs::World::new();
            let e = body(&mesh, plastic)?.spawn(&mut world);
            world.insert_one(e, tetpbd::Activation::never_sleeps())?;
            {
                let mut p = world.get::<&mut Particles>(e)?;
                let c = p.center_of_mass();
                for i in 0..p.len() {
                    let v = Vector3::new(0.0, 2.0, 0.0).cross(&(p.positions()[i] - c));
                    p.set_velocity(i, v)?;
                }
            }
            let solver = Solver::new(SolverSettings {
                dt: DT,
                gravity: Vector3::zeros(),
                ..Default::default()
            })?;
            runs.push((world, solver, Vec::new()));
        }
        for f in 0..frames + 2 {
            for (world, solver, times) in runs.iter_mut() {
                let t = Instant::now();
                solver.step(world)?;
                if f >= 2 {
                    times.push(t.elapsed().as_secs_f64() * 1e3);
                }
            }
        }
        let without = median(std::mem::take(&mut runs[0].2));
        let with = median(std::mem::take(&mut runs[1].2));
        // Every tetrahedron past the yield: twisted by 1 rad/m, pinned there.
        let mut world = hecs::World::new();
        let e = body(&mesh, true)?.spawn(&mut world);
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
