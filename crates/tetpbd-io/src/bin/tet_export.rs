//! `tet_export`: reads a tetrahedral mesh, hangs it from its highest vertices under gravity
//! and writes every frame's surface (OBJ) and tetrahedra (VTU) to a folder.
//!
//! ```text
//! cargo run -p tetpbd-io --features cli --bin tet_export -- <mesh.msh | mesh.node> <out_dir>
//!     [--frames 60] [--compliance 1e-6]
//! ```
//!
//! A `.node` file is read with the `.ele` file of the same stem; vertices no tetrahedron
//! uses are dropped. Frames are 1/60 s apart;
//! files are `<out_dir>/surface_0000.obj` and `<out_dir>/tets_0000.vtu` (frame 0 = rest).
//! Each frame prints its number of inverted tetrahedra and the lowest y, m.

use std::error::Error;
use std::path::{Path, PathBuf};

use tetpbd::hecs::World;
use tetpbd::{Particles, SoftBodyBuilder, Solver, SolverSettings, Surface, TetMesh, Tetrahedra};
use tetpbd_io::{
    drop_unreferenced_vertices, read_msh_file, read_tetgen_files, write_surface_obj,
    write_tetrahedra_vtu,
};

/// Options of the command line.
#[derive(clap::Parser, Debug)]
#[command(
    about = "Hangs a tetrahedral mesh from its highest vertices under gravity and writes every \
             frame's surface (OBJ) and tetrahedra (VTU)"
)]
struct Options {
    /// The mesh: a Gmsh `.msh` file, or a TetGen `.node` file read with the `.ele` file of
    /// the same stem.
    mesh: PathBuf,
    /// The folder the frames are written to (created if missing).
    out_dir: PathBuf,
    /// Frames to simulate, 1/60 s each (frame 0, the rest state, is written too).
    #[arg(long, default_value_t = 60)]
    frames: u32,
    /// Compliance of the edge constraints, m/N (0 = hard).
    #[arg(long, default_value_t = 1e-6, value_parser = non_negative)]
    compliance: f32,
}

/// Parses a finite, non-negative number.
fn non_negative(s: &str) -> Result<f32, String> {
    match s.parse::<f32>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        Ok(v) => Err(format!("{v} is not a finite, non-negative compliance")),
        Err(e) => Err(e.to_string()),
    }
}

fn read_mesh(path: &Path) -> Result<TetMesh, Box<dyn Error>> {
    match path.extension().and_then(|e| e.to_str()) {
        Some("msh") => Ok(read_msh_file(path)?),
        Some("node") => Ok(read_tetgen_files(path, path.with_extension("ele"))?),
        _ => Err(format!("{}: expected a .msh or .node file", path.display()).into()),
    }
}

/// Indices of the vertices within 0.1 % of the mesh height of its highest y.
fn top_vertices(mesh: &TetMesh) -> Vec<u32> {
    let (lo, hi) = mesh
        .vertices
        .iter()
        .fold((f32::MAX, f32::MIN), |(lo, hi), v| {
            (lo.min(v.y), hi.max(v.y))
        });
    let tolerance = 1e-3 * (hi - lo);
    (0..mesh.vertices.len() as u32)
        .filter(|&i| mesh.vertices[i as usize].y >= hi - tolerance)
        .collect()
}

fn run(options: Options) -> Result<(), Box<dyn Error>> {
    let Options {
        mesh: input,
        out_dir: out,
        frames,
        compliance,
    } = options;
    let read = read_mesh(&input)?;
    let (mesh, _) = drop_unreferenced_vertices(&read);
    if mesh.vertices.len() < read.vertices.len() {
        println!(
            "dropped {} vertices no tetrahedron uses",
            read.vertices.len() - mesh.vertices.len()
        );
    }
    std::fs::create_dir_all(&out)?;
    let pinned = top_vertices(&mesh);
    let mut world = World::new();
    // Mesh files may number vertices in any order: renumber the particles for locality
    // (pins are given by file vertex index; the outputs use the particle numbering).
    let body = SoftBodyBuilder::new(mesh)
        .spatial_order(true)
        .density(1000.0)
        .edges(compliance)
        .volume(0.0)
        .pinned(pinned.iter().copied())
        .build()?
        .spawn(&mut world);
    let mut solver = Solver::new(SolverSettings::default())?;
    println!("{} vertices pinned", pinned.len());
    for frame in 0..=frames {
        if frame > 0 {
            solver.step(&mut world)?;
        }
        let particles = world.get::<&Particles>(body)?;
        let tets = world.get::<&Tetrahedra>(body)?;
        let surface = world.get::<&Surface>(body)?;
        write_surface_obj(
            out.join(format!("surface_{frame:04}.obj")),
            &surface,
            particles.positions(),
        )?;
        write_tetrahedra_vtu(out.join(format!("tets_{frame:04}.vtu")), &particles, &tets)?;
        println!(
            "frame {frame}: {} inverted, lowest y {:.4} m",
            tets.count_inverted(particles.positions()),
            particles.aabb().0.y
        );
    }
    println!("wrote {} frames to {}", frames + 1, out.display());
    Ok(())
}

fn main() {
    let options = <Options as clap::Parser>::parse();
    if let Err(e) = run(options) {
        eprintln!("tet_export: {e}");
        std::process::exit(1);
    }
}
