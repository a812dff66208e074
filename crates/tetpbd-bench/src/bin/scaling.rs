//! ms per frame for bodies of about 1k, 10k, 100k and 1M tetrahedra (10 substeps of a
//! 1/60 s frame), for edges + volume and for vertex–face, on 1 and 2 threads.
//!
//! ```text
//! cargo run --release -p tetpbd-bench --features parallel --bin scaling [-- --max-cells N --frames F]
//! ```
//!
//! Without `--features parallel` only the single-threaded column is measured. Prints medians
//! over the measured frames (the first two frames are warm-up) and ns per tetrahedron per
//! substep.

use std::time::Instant;

use nalgebra::Vector3;
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{SoftBodyBuilder, Solver, SolverSettings, TetMesh};

fn arg(name: &str, default: usize) -> usize {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1))
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// Median ms per frame of a hanging cube (top face pinned).
fn frame_ms(mesh: &TetMesh, set: &str, frames: usize) -> Result<f64, Box<dyn std::error::Error>> {
    let top: Vec<u32> = (0..mesh.vertices.len() as u32)
        .filter(|&i| mesh.vertices[i as usize].y > 0.4999)
        .collect();
    let b = SoftBodyBuilder::new(mesh.clone())
        .density(1000.0)
        .pinned(top);
    let b = if set == "edges+volume" {
        b.edges(1e-7).volume(1e-10)
    } else {
        b.vertex_face(1e-7)
    };
    let mut world = hecs::World::new();
    b.build()?.spawn(&mut world);
    let mut solver = Solver::new(SolverSettings {
        substeps: 10,
        ..Default::default()
    })?;
    let mut times = Vec::with_capacity(frames);
    for f in 0..frames + 2 {
        let t = Instant::now();
        solver.step(&mut world)?;
        if f >= 2 {
            times.push(t.elapsed().as_secs_f64() * 1e3);
        }
    }
    times.sort_by(f64::total_cmp);
    Ok(times[times.len() / 2])
}

#[cfg(feature = "parallel")]
fn with_threads<T: Send>(n: usize, f: impl FnOnce() -> T + Send) -> T {
    match rayon::ThreadPoolBuilder::new().num_threads(n).build() {
        Ok(pool) => pool.install(f),
        Err(_) => f(),
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let max_cells = arg("--max-cells", 55) as u32;
    let frames = arg("--frames", 7);
    println!("hanging cube, top face pinned, 10 substeps × 1 iteration per 1/60 s frame; median of {frames} frames after 2 warm-up");
    println!("set            tets      particles   1 thread ms/frame  ns/tet/substep   2 threads ms/frame  speed-up");
    for cells in [6u32, 12, 26, 55].into_iter().filter(|c| *c <= max_cells) {
        let mesh = box_grid(Vector3::new(1.0, 1.0, 1.0), [cells; 3], CellSplit::Six)?;
        for set in ["edges+volume", "vertex-face"] {
            #[cfg(feature = "parallel")]
            let (one, two) = (
                with_threads(1, || {
                    frame_ms(&mesh, set, frames).map_err(|e| e.to_string())
                })?,
                Some(with_threads(2, || {
                    frame_ms(&mesh, set, frames).map_err(|e| e.to_string())
                })?),
            );
            #[cfg(not(feature = "parallel"))]
            let (one, two): (f64, Option<f64>) = (frame_ms(&mesh, set, frames)?, None);
            let per_tet = one * 1e6 / (mesh.tets.len() as f64 * 10.0);
            let two_s = two.map_or("-".to_string(), |t| format!("{t:.2}"));
            let speed = two.map_or("-".to_string(), |t| format!("{:.2}×", one / t));
            println!(
                "{set:13} {:9} {:10}   {one:17.2}  {per_tet:14.1}   {two_s:>18}  {speed:>8}",
                mesh.tets.len(),
                mesh.vertices.len()
            );
        }
    }
    Ok(())
}
