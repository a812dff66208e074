//! A committed sample asset (OBJ surface) is filled with tetrahedra, dropped on fixed ground,
//! and its fine surface mesh is driven by the coarse simulation through barycentric skinning.
//!
//! Headless; prints one line of statistics per frame. Run with
//! `cargo run --release --example asset_drop -- [OBJ [FRAMES [CELL_M]]] [--export DIR] …`
//! (defaults: `examples/assets/bunny_blob.obj`, 180 frames, 0.07 m cells); `-- --help` lists
//! every option with its unit and default (the command line is in `cli/asset_drop.rs`).

use std::time::Instant;

use clap::Parser;

use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder};
use tetpbd::{Particles, SoftBodyBuilder, SolverSettings, Tetrahedra};
use tetpbd_io::{Skin, SurfaceMesh, TetrahedralizeBuilder};
use tetpbd_rapier::{CoupledWorld, CouplingSettings, DeformationDamping, SoftColliderBuilder};

#[path = "cli/asset_drop.rs"]
mod cli;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let cli = cli::Cli::parse();
    let mut viz = tetpbd_viz::Viz::from_options(cli.viz)?;
    let (path, frames, cell) = (cli.obj.display(), cli.frames, cli.cell);

    let t = Instant::now();
    let render = SurfaceMesh::read_obj(&cli.obj)?;
    let mesh = TetrahedralizeBuilder::new(cell)
        .smoothing(3)
        .build(&render)?;
    let mesh_ms = t.elapsed().as_secs_f64() * 1e3;

    let solver = SolverSettings {
        substeps: 10,
        ..SolverSettings::default()
    };
    let mut scene = CoupledWorld::new(solver, CouplingSettings::default())?;
    scene.physics.insert(
        RigidBodyBuilder::fixed().translation(Vector::new(0.0, -0.5, 0.0)),
        ColliderBuilder::cuboid(5.0, 0.5, 5.0),
    );
    // Lift the asset so that its lowest surface point starts 0.4 m above the ground.
    let lowest = render.vertices.iter().map(|v| v.y).fold(f32::MAX, f32::min);
    let lift = Vector3::new(0.0, 0.4 - lowest, 0.0);
    let body = SoftBodyBuilder::new(mesh)
        .density(300.0)
        .edges(1e-6)
        .volume(0.0)
        .translation(lift)
        .build()?;
    // Embed the render vertices in the body's own (solver-ordered) tetrahedra.
    let points: Vec<_> = render.vertices.iter().map(|v| v + lift).collect();
    let t = Instant::now();
    let skin = Skin::embed(
        body.particles.positions(),
        body.tetrahedra.indices(),
        &points,
    )?;
    let embed_ms = t.elapsed().as_secs_f64() * 1e3;
    println!(
        "# {path}: {} surface triangles, {} vertices -> {} tetrahedra, {} particles \
         (cell {cell} m, {mesh_ms:.1} ms); skin embedded in {embed_ms:.2} ms, points \
         outside: {}",
        render.triangles.len(),
        render.vertices.len(),
        body.tetrahedra.len(),
        body.particles.len(),
        skin.outside_count()
    );
    let e = body.spawn(&mut scene.soft);
    scene.soft.insert_one(
        e,
        // Rolling resistance: without it the blob rocks on its round belly for tens of
        // seconds (tetpbd_rapier::Coupling docs).
        SoftColliderBuilder::new()
            .friction(0.6)
            .rolling_resistance(0.01)
            .build()?,
    )?;
    scene.soft.insert_one(e, DeformationDamping::new(5.0)?)?;

    let mut skinned = vec![Vector3::zeros(); points.len()];
    println!(
        "frame contacts max_penetration_m max_speed_m_s volume_ratio inverted sim_min_y_m \
         skin_min_y_m ms_per_frame"
    );
    for frame in 0..frames {
        let t = Instant::now();
        let stats = scene.step()?;
        viz.frame(&scene)?;
        let (p, tets) = scene.soft.query_one_mut::<(&Particles, &Tetrahedra)>(e)?;
        skin.deform(p.positions(), &mut skinned)?;
        let ms = t.elapsed().as_secs_f64() * 1e3;
        let skin_low = skinned.iter().map(|v| v.y).fold(f32::MAX, f32::min);
        println!(
            "{frame} {} {:.6} {:.4} {:.4} {} {:.4} {skin_low:.4} {ms:.3}",
            stats.contacts,
            stats.max_penetration,
            p.max_speed(),
            tets.volume_ratio(p.positions()),
            tets.count_inverted(p.positions()),
            p.aabb().0.y,
        );
    }
    viz.finish()?;
    Ok(())
}
