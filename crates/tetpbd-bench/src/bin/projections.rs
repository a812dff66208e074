//! ns per constraint projection, per family, single-threaded, on a ~40k-tetrahedron grid.
//!
//! ```text
//! cargo run --release -p tetpbd-bench --bin projections [-- --cells N --repeats R --shuffle --spatial-order on|off|both --simd-only]
//! ```
//!
//! Each family is measured alone (a body with only that family's component), and the
//! Neo-Hookean material (`neo-hookean`, `Material::SOFT_TISSUE`; one projection is a
//! tetrahedron's two coupled constraints), as full
//! Gauss–Seidel sweeps of the family's system over a slightly perturbed grid so every
//! projection does real work. Prints the median and the spread over the repeats.
//!
//! `--shuffle` numbers the grid's vertices and tetrahedra in a random order (as mesh files
//! may); `--spatial-order` builds the body with the builder's particle renumbering on, off
//! or both (default: the builder's default). `--simd-only` skips the scalar kernels.

use std::time::Instant;

use clap::Parser;
use nalgebra::Vector3;
use tetpbd::generators::{box_grid, shuffled, CellSplit};
use tetpbd::systems::{self, Kernel};
use tetpbd::{Material, Particles, SoftBodyBuilder};
use tetpbd_bench::{orders, perturb, SpatialOrder};

/// ns per constraint projection, per family and kernel, single-threaded, on a grid of
/// `cells`³ × 6 tetrahedra.
#[derive(Parser)]
#[command(name = "projections")]
struct Args {
    /// Cells per side of the grid (19: about 41k tetrahedra).
    #[arg(long, default_value_t = 19)]
    cells: u32,
    /// Samples of 10 sweeps each (median, min and max printed).
    #[arg(long, default_value_t = 15)]
    repeats: usize,
    /// Number the grid's vertices and tetrahedra in a random order.
    #[arg(long)]
    shuffle: bool,
    /// Particle orders to measure (default: the builder's).
    #[arg(long, value_enum)]
    spatial_order: Option<SpatialOrder>,
    /// Skip the seed families' scalar kernels.
    #[arg(long)]
    simd_only: bool,
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args = Args::parse();
    let (cells, repeats) = (args.cells, args.repeats);
    let sweeps = 10;
    let h = 1.0 / 600.0;
    let mut mesh = box_grid(Vector3::new(1.0, 1.0, 1.0), [cells; 3], CellSplit::Six)?;
    let shuffle = args.shuffle;
    if shuffle {
        mesh = shuffled(&mesh, 1).0;
    }
    let numbering = if shuffle { "shuffled" } else { "grid" };
    println!(
        "grid {cells}³ cells × 6 = {} tetrahedra, {} particles, {numbering} numbering; {sweeps} sweeps per sample, {repeats} samples",
        mesh.tets.len(),
        mesh.vertices.len()
    );
    println!("family        kernel  spatial order  projections/sweep   median ns/projection   min      max");
    for (family, kernel, spatial) in ["edge", "volume", "vertex-face", "neo-hookean"]
        .into_iter()
        .flat_map(|f| [(f, Kernel::Scalar), (f, Kernel::Simd)])
        .filter(|(_, k)| *k == Kernel::Simd || !args.simd_only)
        .flat_map(|(f, k)| {
            orders(args.spatial_order)
                .into_iter()
                .map(move |o| (f, k, o))
        })
    {
        let mut world = hecs::World::new();
        let b = SoftBodyBuilder::new(mesh.clone())
            .density(1000.0)
            .spatial_order(spatial);
        let b = match family {
            "edge" => b.edges(1e-6),
            "volume" => b.volume(1e-9),
            "neo-hookean" => b.material(Material::SOFT_TISSUE),
            _ => b.vertex_face(1e-6),
        };
        let e = b.build()?.spawn(&mut world);
        // A deterministic perturbation of 1 % of the cell size.
        let original: Vec<Vector3<f32>> = {
            let mut p = world.get::<&mut Particles>(e)?;
            perturb(&mut p, 1.0 / cells as f32)?;
            p.positions().to_vec()
        };
        let mut samples = Vec::with_capacity(repeats);
        let mut per_sweep = 0;
        for _ in 0..repeats + 2 {
            world
                .get::<&mut Particles>(e)?
                .positions_mut()
                .copy_from_slice(&original);
            systems::reset_lambdas(&mut world);
            let t = Instant::now();
            let mut n = 0;
            for _ in 0..sweeps {
                let c = match family {
                    "edge" => systems::project_edges_with(&mut world, h, kernel),
                    "volume" => systems::project_volume_with(&mut world, h, kernel),
                    "neo-hookean" => systems::project_neo_hookean_with(&mut world, h, kernel),
                    _ => systems::project_vertex_face_with(&mut world, h, kernel),
                };
                n += c.applied + c.degenerate;
            }
            let ns = t.elapsed().as_secs_f64() * 1e9 / n as f64;
            per_sweep = n / sweeps;
            samples.push(ns);
        }
        samples.drain(..2); // warm-up
        let lo = samples.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = samples.iter().copied().fold(0.0, f64::max);
        println!(
            "{family:12}  {:6}  {:13}  {per_sweep:17}   {:20.1}   {lo:6.1}   {hi:6.1}",
            format!("{kernel:?}"),
            if spatial { "on" } else { "off" },
            median(&mut samples)
        );
    }
    Ok(())
}
