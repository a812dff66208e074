//! Headless soft pile: nine soft cubes (4×4×4 cells, 1 m) dropped in the layout of rapier's
//! `fem_bench` "jelly pile" onto a pinned soft slab, with [`SoftContacts`] as the solver's
//! hook. Prints, per second of simulated time, the largest particle speed and the largest
//! contact penetration of that second.
//!
//! ```text
//! cargo run --release --example soft_pile [seconds]
//! ```

use nalgebra::Vector3;
use tetpbd::generators::{self, CellSplit};
use tetpbd::{Particles, SoftBodyBuilder, Solver, SolverSettings};
use tetpbd_rapier::{SoftContactSettings, SoftContacts};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let seconds: u32 = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(5);
    let mut world = hecs::World::new();

    // Ground: an 8 m × 0.2 m × 8 m soft slab, top at y = 0, bottom and sides pinned.
    let size = Vector3::new(8.0, 0.2, 8.0);
    let slab = generators::box_grid(size, [16, 1, 16], CellSplit::Six)?;
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
        .spawn(&mut world);

    // fem_bench layout: 3 × 3 grid of 1 m pitch, cube i centred at height 0.55 + 1.05 i.
    let cube = generators::box_grid(Vector3::repeat(1.0), [4, 4, 4], CellSplit::Six)?;
    for i in 0..9 {
        let at = Vector3::new(
            (i % 3) as f32 - 1.0,
            0.55 + i as f32 * 1.05,
            (i / 3) as f32 - 1.0,
        );
        SoftBodyBuilder::new(cube.clone())
            .density(1000.0)
            .edges(0.0)
            .volume(0.0)
            .translation(at)
            .build()?
            .spawn(&mut world);
    }

    let mut solver = Solver::new(SolverSettings {
        substeps: 20,
        damping: 1.0,
        ..SolverSettings::default()
    })?;
    let mut contacts = SoftContacts::new(SoftContactSettings::default())?;
    let frames_per_second = (1.0 / solver.settings.dt).round() as u32;
    println!("  t (s)   max|v| (m/s)   max penetration (m)   contacts   deep   clamps   ms/frame");
    for second in 1..=seconds {
        let (mut v, mut pen, mut clamps, mut ms) = (0.0f32, 0.0f32, 0u64, 0.0f64);
        let mut last = *contacts.stats();
        for _ in 0..frames_per_second {
            let stats = solver.step_with(&mut world, &mut contacts)?;
            ms += stats.total_time.as_secs_f64() * 1e3;
            last = *contacts.stats();
            pen = pen.max(last.max_penetration);
            clamps += last.clamps;
            for p in world.query_mut::<&Particles>() {
                v = v.max(p.max_speed());
            }
        }
        println!(
            "{second:>7} {v:>14.4} {pen:>21.5} {:>10} {:>6} {clamps:>8} {:>10.2}",
            last.contacts,
            last.deep,
            ms / f64::from(frames_per_second)
        );
    }
    Ok(())
}
