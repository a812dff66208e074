//! Cost of the coupling's stacking pass (`tetpbd-rapier`'s `stacking` module): a 1000 kg
//! rigid box resting on a 1 kg soft slab (2 × 0.4 × 2 m, edges + volume, α = 0) on the
//! ground, for slabs of increasing resolution, at the default 10 substeps × 1 iteration.
//!
//! ```text
//! cargo run --release -p tetpbd-bench --bin stacking [-- --frames F] [--vertex-face]
//! ```
//!
//! `--vertex-face`: the slab with vertex–face + edges constraints instead of edges + volume.
//!
//! Prints, per slab, medians over the measured frames (after 60 frames of settling): ms per
//! coupled frame, ms of it spent in the stacking passes (`CouplingStats::stacking_time`),
//! and the same frame with the pass off (`stacking: None`, where the box sinks
//! into the slab), plus the box bottom at the end of each run.

use clap::Parser;
use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder};
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{SoftBodyBuilder, SolverSettings};

/// Cost of the coupling's stacking pass: a 1000 kg rigid box resting on a 1 kg soft slab on
/// the ground, for slabs of increasing resolution.
#[derive(Parser)]
#[command(name = "stacking")]
struct Args {
    /// Frames measured after 60 frames of settling.
    #[arg(long, default_value_t = 120)]
    frames: usize,
    /// The slab with vertex–face + edges constraints instead of edges + volume.
    #[arg(long)]
    vertex_face: bool,
}
use tetpbd_rapier::{CoupledWorld, CouplingSettings, SoftCollider};

/// What one run measured.
struct Run {
    frame_ms: f64,
    stacking_ms: f64,
    passes: f64,
    box_bottom: f32,
    tets: usize,
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

fn run(
    cells: [u32; 3],
    ratio: f32,
    frames: usize,
    vertex_face: bool,
) -> Result<Run, Box<dyn std::error::Error>> {
    let settings = CouplingSettings {
        stacking: Some(tetpbd_rapier::StackingSettings {
            mass_ratio: ratio,
            ..Default::default()
        }),
        ..CouplingSettings::default()
    };
    let mut s = CoupledWorld::new(SolverSettings::default(), settings)?;
    s.physics.insert(
        RigidBodyBuilder::fixed().translation(Vector::new(0.0, -0.5, 0.0)),
        ColliderBuilder::cuboid(20.0, 0.5, 20.0),
    );
    let size = Vector3::new(2.0, 0.4, 2.0);
    let mesh = box_grid(size, cells, CellSplit::Six)?;
    let tets = mesh.tets.len();
    let b = SoftBodyBuilder::new(mesh)
        .density(1.0 / (size.x * size.y * size.z))
        .edges(0.0)
        .translation(Vector3::new(0.0, 0.2 + 0.003, 0.0));
    let body = if vertex_face {
        b.vertex_face(0.0)
    } else {
        b.volume(0.0)
    }
    .build()?;
    let e = body.spawn(&mut s.soft);
    // Benchmarks time the solver on awake bodies: sleeping would end the work being measured.
    s.soft.insert(
        e,
        (SoftCollider::default(), tetpbd::Activation::never_sleeps()),
    )?;
    let (rb, _) = s.physics.insert(
        RigidBodyBuilder::dynamic().translation(Vector::new(0.0, 0.403 + 0.25 + 0.005, 0.0)),
        ColliderBuilder::cuboid(0.25, 0.25, 0.25).mass(1000.0),
    );
    let (mut total, mut stacking, mut passes) = (Vec::new(), Vec::new(), Vec::new());
    for f in 0..60 + frames {
        let stats = s.step()?;
        if f >= 60 {
            total.push(stats.total_time.as_secs_f64() * 1e3);
            stacking.push(stats.stacking_time.as_secs_f64() * 1e3);
            passes.push(stats.stacking_passes as f64);
        }
    }
    let box_bottom = s
        .physics
        .bodies
        .get(rb)
        .map_or(f32::NAN, |b| b.translation().y)
        - 0.25;
    Ok(Run {
        frame_ms: median(&mut total),
        stacking_ms: median(&mut stacking),
        passes: median(&mut passes),
        box_bottom,
        tets,
    })
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let Args {
        frames,
        vertex_face,
    } = Args::parse();
    println!(
        "| slab cells | tetrahedra | ms/frame | of it stacking, ms | passes/frame | box bottom, m | pass off: ms/frame | pass off: box bottom, m |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for cells in [[4, 1, 4], [8, 2, 8], [16, 4, 16], [32, 8, 32]] {
        let on = run(
            cells,
            CouplingSettings::default().stacking_mass_ratio(),
            frames,
            vertex_face,
        )?;
        let off = run(cells, f32::INFINITY, frames, vertex_face)?;
        println!(
            "| {}×{}×{} | {} | {:.3} | {:.3} ({:.0} %) | {:.0} | {:.3} | {:.3} | {:.3} |",
            cells[0],
            cells[1],
            cells[2],
            on.tets,
            on.frame_ms,
            on.stacking_ms,
            100.0 * on.stacking_ms / on.frame_ms,
            on.passes,
            on.box_bottom,
            off.frame_ms,
            off.box_bottom
        );
    }
    Ok(())
}
