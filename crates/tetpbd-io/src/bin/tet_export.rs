//! `tet_export`: reads a tetrahedral mesh, hangs it from its highest vertices under gravity
//! and writes every frame's surface (OBJ) and tetrahedra (VTU) to a folder.
//!
//! ```text
//! tet_export <mesh.msh | mesh.node> <out_dir> [frames = 60] [edge compliance = 1e-6]
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

const USAGE: &str =
    "usage: tet_export <mesh.msh | mesh.node> <out_dir> [frames = 60] [edge compliance = 1e-6]";

fn read_mesh(path: &Path) -> Result<TetMesh, Box<dyn Error>> {
    match path.extension().and_then(|e| e.to_str()) {
        Some("msh") => Ok(read_msh_file(path)?),
        Some("node") => Ok(read_tetgen_files(path, path.with_extension("ele"))?),
        _ => Err(format!("{}: expected a .msh or .node file\n{USAGE}", path.display()).into()),
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

fn run() -> Result<(), Box<dyn Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 2 || args.len() > 4 {
        return Err(USAGE.into());
    }
    let frames: u32 = args.get(2).map_or(Ok(60), |s| s.parse())?;
    let compliance: f32 = args.get(3).map_or(Ok(1e-6), |s| s.parse())?;
    let read = read_mesh(Path::new(&args[0]))?;
    let (mesh, _) = drop_unreferenced_vertices(&read);
    if mesh.vertices.len() < read.vertices.len() {
        println!(
            "dropped {} vertices no tetrahedron uses",
            read.vertices.len() - mesh.vertices.len()
        );
    }
    let out = PathBuf::from(&args[1]);
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
    if let Err(e) = run() {
        eprintln!("tet_export: {e}");
        std::process::exit(1);
    }
}
