//! ms per frame for bodies of about 1k, 10k, 100k and 1M tetrahedra (10 substeps of a
//! 1/60 s frame), for edges + volume and for vertex–face, on 1 and 2 threads.
//!
//! ```text
//! cargo run --release -p tetpbd-bench --features parallel --bin scaling [-- --max-cells N --frames F --shuffle --spatial-order on|off|both --breakdown]
//! ```
//!
//! `--breakdown` also prints, per body and thread count, the median ms per frame spent in
//! prediction, the copies into and out of the working copy, each family's system and the
//! velocity update (from [`tetpbd::StepStats`]),
//! and the number of colour classes of the edges and tetrahedra (the phases of a parallel
//! sweep).
//!
//! `--shuffle` numbers each grid's vertices and tetrahedra in a random order (as mesh files
//! may); `--spatial-order` builds the bodies with the builder's particle renumbering on, off
//! or both (default: the builder's default).
//!
//! Without `--features parallel` only the single-threaded column is measured. Prints medians
//! over the measured frames (the first two frames are warm-up) and ns per tetrahedron per
//! substep.

use std::time::Instant;

use nalgebra::Vector3;
use tetpbd::generators::{box_grid, shuffled, CellSplit};
use tetpbd::{SoftBodyBuilder, Solver, SolverSettings, StepStats, TetMesh};
use tetpbd_bench::{arg, flag, orders};

/// Median ms per frame of a hanging cube (top face pinned), and the median ms per frame
/// of each phase: prediction, copies into and out of the working copy, volume, vertex–face,
/// edges, velocity update.
fn frame_ms(
    mesh: &TetMesh,
    set: &str,
    spatial: bool,
    frames: usize,
) -> Result<(f64, [f64; 6]), Box<dyn std::error::Error>> {
    let top: Vec<u32> = (0..mesh.vertices.len() as u32)
        .filter(|&i| mesh.vertices[i as usize].y > 0.4999)
        .collect();
    let b = SoftBodyBuilder::new(mesh.clone())
        .density(1000.0)
        .spatial_order(spatial)
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
    let mut phases: [Vec<f64>; 6] = Default::default();
    for f in 0..frames + 2 {
        let t = Instant::now();
        let s = solver.step(&mut world)?;
        if f >= 2 {
            times.push(t.elapsed().as_secs_f64() * 1e3);
            for (v, p) in phases.iter_mut().zip(phase_ms(&s)) {
                v.push(p);
            }
        }
    }
    Ok((median(&mut times), phases.map(|mut v| median(&mut v))))
}

fn phase_ms(s: &StepStats) -> [f64; 6] {
    [
        s.predict_time,
        s.copy_time,
        s.volume.time,
        s.vertex_face.time,
        s.edge.time,
        s.velocity_time,
    ]
    .map(|d| d.as_secs_f64() * 1e3)
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Colour classes of the mesh's edges and tetrahedra.
fn class_counts(mesh: &TetMesh) -> (usize, usize) {
    let n = mesh.vertices.len();
    let edges = tetpbd::unique_edges(&mesh.tets);
    (
        tetpbd::ordering::colour_order(&edges, n).1.len(),
        tetpbd::ordering::colour_order(&mesh.tets, n).1.len(),
    )
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
    let shuffle = flag("--shuffle");
    let breakdown = flag("--breakdown");
    let numbering = if shuffle { "shuffled" } else { "grid" };
    println!("hanging cube ({numbering} numbering), top face pinned, 10 substeps × 1 iteration per 1/60 s frame; median of {frames} frames after 2 warm-up");
    println!("set           spatial order      tets  particles   1 thread ms/frame  ns/tet/substep   2 threads ms/frame  speed-up");
    for cells in [6u32, 12, 26, 55].into_iter().filter(|c| *c <= max_cells) {
        let mut mesh = box_grid(Vector3::new(1.0, 1.0, 1.0), [cells; 3], CellSplit::Six)?;
        if shuffle {
            mesh = shuffled(&mesh, 1).0;
        }
        for (set, spatial) in ["edges+volume", "vertex-face"]
            .into_iter()
            .flat_map(|s| orders().into_iter().map(move |o| (s, o)))
        {
            #[cfg(feature = "parallel")]
            let (one, two) = (
                with_threads(1, || {
                    frame_ms(&mesh, set, spatial, frames).map_err(|e| e.to_string())
                })?,
                Some(with_threads(2, || {
                    frame_ms(&mesh, set, spatial, frames).map_err(|e| e.to_string())
                })?),
            );
            #[cfg(not(feature = "parallel"))]
            let (one, two): (_, Option<(f64, [f64; 6])>) =
                (frame_ms(&mesh, set, spatial, frames)?, None);
            let ((one, one_phases), two_phases) = (one, two.map(|t| t.1));
            let two = two.map(|t| t.0);
            let per_tet = one * 1e6 / (mesh.tets.len() as f64 * 10.0);
            let two_s = two.map_or("-".to_string(), |t| format!("{t:.2}"));
            let speed = two.map_or("-".to_string(), |t| format!("{:.2}×", one / t));
            println!(
                "{set:13} {:13} {:9} {:10}   {one:17.2}  {per_tet:14.1}   {two_s:>18}  {speed:>8}",
                if spatial { "on" } else { "off" },
                mesh.tets.len(),
                mesh.vertices.len()
            );
            if breakdown {
                let (e, t) = class_counts(&mesh);
                println!("    colour classes: {e} of edges, {t} of tetrahedra");
                for (threads, p) in [(1, Some(one_phases)), (2, two_phases)] {
                    if let Some([pr, co, vo, vf, ed, ve]) = p {
                        println!("    {threads} thread(s), ms/frame: predict {pr:.2}  copies {co:.2}  volume {vo:.2}  vertex-face {vf:.2}  edges {ed:.2}  velocities {ve:.2}");
                    }
                }
            }
        }
    }
    Ok(())
}
