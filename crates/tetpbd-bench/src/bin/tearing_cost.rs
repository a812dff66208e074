//! Cost of [`tetpbd::Tearing`]: a free cube of about 1k, 10k and 100k tetrahedra (edges +
//! volume), slowly spinning, stepped with and without the component in alternating frames
//! (two copies, so a change of the machine's load hits both alike) while nothing tears;
//! then the frame in which the same cube, stretched to twice its length, tears everywhere
//! (the tearing pass's time from [`tetpbd::StepStats::tearing_time`]) and a plane cut
//! through its middle ([`tetpbd::cut`]). Prints medians, ms per frame.
//!
//! ```text
//! cargo run --release -p tetpbd-bench --bin tearing_cost [-- --frames F]
//! ```

use std::time::Instant;

use clap::Parser;
use nalgebra::Vector3;
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{Blade, Particles, SoftBodyBuilder, TearingSettings};
use tetpbd_bench::{free_body, median, step_alternately, zero_gravity_solver};

/// Cost of tearing: free cubes of about 1k, 10k and 100k tetrahedra with and without the
/// component while nothing tears, then a frame that tears everywhere and a cut.
#[derive(Parser)]
#[command(name = "tearing_cost")]
struct Args {
    /// Frames measured per column (the median is printed).
    #[arg(long, default_value_t = 40)]
    frames: usize,
}

/// `b` with the benchmark's families, tearing at `strain` (`None`: without the component).
fn with_tearing(b: SoftBodyBuilder, strain: Option<f32>) -> SoftBodyBuilder {
    let b = b.edges(1e-6).volume(1e-9);
    match strain {
        Some(strain) => b.tearing(TearingSettings {
            strain: Some(strain),
            smoothing_time: 0.0,
            ..Default::default()
        }),
        None => b,
    }
}

/// Median ms per frame without and with the component, spinning at 2 rad/s, nothing torn,
/// and the median ms of the tearing pass in the frames with it.
fn untorn(
    mesh: &tetpbd::TetMesh,
    frames: usize,
) -> Result<(f64, f64, f64), Box<dyn std::error::Error>> {
    let mut runs = Vec::new();
    for strain in [None, Some(0.5)] {
        let (world, _) = free_body(mesh, 2.0, |b| with_tearing(b, strain))?;
        runs.push((world, zero_gravity_solver(|_| ())?));
    }
    let (mut times, mut pass) = ([Vec::new(), Vec::new()], Vec::new());
    step_alternately(&mut runs, frames, |run, ms, stats, solver| {
        times[run].push(ms);
        if !stats.tearing_time.is_zero() {
            pass.push(stats.tearing_time.as_secs_f64() * 1e3);
        }
        if !solver.tear_events().is_empty() {
            return Err("the spinning cube tore".into());
        }
        Ok(())
    })?;
    let [without, with] = times.map(median);
    Ok((without, with, median(pass)))
}

/// The tearing pass's ms in the frame the cube, stretched to twice its length along x,
/// tears (strain 0.3), with the faces torn; then the ms of a plane cut through its middle.
fn torn(mesh: &tetpbd::TetMesh) -> Result<(f64, usize, f64), Box<dyn std::error::Error>> {
    let (mut world, e) = free_body(mesh, 0.0, |b| with_tearing(b, Some(0.3)))?;
    {
        let mut p = world.get::<&mut Particles>(e)?;
        for i in 0..p.len() {
            let x = p.rest_positions()[i];
            p.set_position(i, Vector3::new(2.0 * x.x, x.y, x.z))?;
        }
    }
    let mut solver = zero_gravity_solver(|_| ())?;
    let stats = solver.step(&mut world)?;
    let faces: usize = solver.tear_events().iter().map(|ev| ev.faces_torn).sum();
    let tearing = stats.tearing_time.as_secs_f64() * 1e3;
    let (mut world, e) = free_body(mesh, 0.0, |b| with_tearing(b, None))?;
    let blade = Blade::Plane {
        point: Vector3::new(0.013, 0.0, 0.0),
        normal: Vector3::x(),
    };
    let t = Instant::now();
    tetpbd::cut(&mut world, e, &blade)?;
    Ok((tearing, faces, t.elapsed().as_secs_f64() * 1e3))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let frames = Args::parse().frames;
    println!("free cube, edges 1e-6 m/N + volume 1e-9 m⁵/N, zero gravity; 10 substeps × 1 iteration per 1/60 s frame; median of {frames} frames");
    println!("| tetrahedra | without, ms/frame | with, nothing torn, ms/frame | with/without | its tearing pass, ms/frame | tearing pass of a frame tearing everywhere, ms (faces torn) | plane cut, ms |");
    println!("|---|---|---|---|---|---|---|");
    for cells in [6u32, 13, 28] {
        let mesh = box_grid(Vector3::new(1.0, 1.0, 1.0), [cells; 3], CellSplit::Five)?;
        let (without, with, pass) = untorn(&mesh, frames)?;
        let (tearing, faces, cut) = torn(&mesh)?;
        println!(
            "| {} | {without:.3} | {with:.3} | {:.3} | {pass:.3} | {tearing:.2} ({faces}) | {cut:.2} |",
            mesh.tets.len(),
            with / without,
        );
    }
    Ok(())
}
