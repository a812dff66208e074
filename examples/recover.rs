//! A soft cube is mirrored (every tetrahedron inverted), flattened or scrambled, then
//! released; prints its recovery frame by frame with the solver's step statistics.
//!
//! ```text
//! cargo run --release --example recover -- [mirror|flatten|scramble|squash|nudge] [vf|ev|vfe|e]
//!     [FRAMES] [SUBSTEPS] [CELLS] [--alpha ALPHA] [--max-correction-speed M_PER_S] [--export DIR] …
//! ```
//!
//! `vf` = vertex–face constraints alone, `ev` = edges + volume, `vfe` = vertex–face + edges,
//! `e` = edges alone (which cannot un-invert a mirrored body). `--alpha` sets the compliance of
//! every family (m/N; volume m⁵/N), default 0; `--max-correction-speed` turns on the solver's
//! safety net (m/s). Defaults: mirror, vfe, 120 frames, 10 substeps, 4³ cells. `-- --help`
//! lists every option with its unit and default (the command line is in `cli/recover.rs`).

use clap::{Parser, ValueEnum};
use nalgebra::Vector3;
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{Particles, SoftBodyBuilder, Solver, SolverSettings, Tetrahedra};

#[path = "cli/recover.rs"]
mod cli;

use cli::{Families, Mode};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let cli = cli::Cli::parse();
    let mut viz = tetpbd_viz::Viz::from_options(cli.viz)?;
    let (mode, families, frames, substeps, cells) =
        (cli.mode, cli.families, cli.frames, cli.substeps, cli.cells);
    let (alpha, max_correction_speed) = (cli.alpha, cli.max_correction_speed);

    let mut world = hecs::World::new();
    let mesh = box_grid(Vector3::new(1.0, 1.0, 1.0), [cells; 3], CellSplit::Five)?;
    let b = SoftBodyBuilder::new(mesh).density(1000.0);
    let b = match families {
        Families::VertexFace => b.vertex_face(alpha),
        Families::EdgesVolume => b.edges(alpha).volume(alpha),
        Families::VertexFaceEdges => b.vertex_face(alpha).edges(alpha),
        Families::Edges => b.edges(alpha),
    };
    let body = b.build()?.spawn(&mut world);
    {
        let mut p = world.get::<&mut Particles>(body)?;
        let mut seed = 0x2545_F491_4F6C_DD1Du64;
        let mut rand = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 40) as f32 / (1u64 << 24) as f32 - 0.5
        };
        for i in 0..p.len() {
            let x = p.positions()[i];
            let y = match mode {
                Mode::Mirror => Vector3::new(-x.x, x.y, x.z),
                Mode::Flatten => Vector3::new(x.x, 0.0, x.z),
                Mode::Squash => Vector3::new(x.x, 0.5 * x.y, x.z),
                Mode::Nudge => Vector3::new(x.x, 0.95 * x.y, x.z),
                Mode::Scramble => Vector3::new(rand(), rand(), rand()),
            };
            p.set_position(i, y)?;
        }
    }
    let mut solver = Solver::new(SolverSettings {
        gravity: Vector3::zeros(),
        substeps,
        damping: 1.0,
        safety: tetpbd::SafetySettings {
            max_correction_speed,
            ..Default::default()
        },
        diagnostics: tetpbd::DiagnosticSettings {
            measure_error: true,
            ..Default::default()
        },
        ..Default::default()
    })?;
    println!(
        "mode {}, constraints {} (α = {alpha}), {cells}³ cells, {substeps} substeps × 1 iteration, dt 1/60 s, safety net {max_correction_speed:?}",
        name(mode),
        name(families)
    );
    println!(
        "frame  inverted  volume%   max|C|edge  max|C|vf   max|C|vol   degenerate  max|v|     ms"
    );
    let mut recovered = None;
    for frame in 1..=frames {
        let s = solver.step(&mut world)?;
        viz.frame(&world)?;
        let p = world.get::<&Particles>(body)?;
        let t = world.get::<&Tetrahedra>(body)?;
        let ratio = t.volume_ratio(p.positions());
        let inverted = s.inverted.unwrap_or(0);
        if recovered.is_none() && inverted == 0 && (ratio - 1.0).abs() < 0.01 {
            recovered = Some(frame);
        }
        let f = |x: Option<tetpbd::ErrorStats>| x.map_or(0.0, |e| e.max);
        println!(
            "{frame:5}  {inverted:8}  {:7.2}   {:9.2e}  {:9.2e}  {:9.2e}  {:10}  {:8.3}  {:6.3}",
            ratio * 100.0,
            f(s.edge.after),
            f(s.vertex_face.after),
            f(s.volume.after),
            s.degenerate(),
            p.max_speed(),
            s.total_time.as_secs_f64() * 1e3
        );
    }
    match recovered {
        Some(f) => println!("recovered (0 inverted, volume within 1 %) at frame {f}"),
        None => println!("not recovered within {frames} frames"),
    }
    viz.finish()?;
    Ok(())
}

/// The name a value has on the command line.
fn name(value: impl ValueEnum) -> String {
    value
        .to_possible_value()
        .map_or_else(String::new, |v| v.get_name().to_owned())
}
