//! A soft cube dropped onto rigid ground and left to rest, in tetpbd (through
//! `tetpbd-rapier`) and in rapier 0.36's built-in soft bodies, same mesh, same frame dt and
//! substeps, in one process.
//!
//! ```text
//! cargo run --release -p tetpbd-bench --bin vs_rapier [-- --frames F]
//! ```
//!
//! Prints, per engine and size: median wall ms per frame over the resting phase (from 2 s
//! on), the settled max |v| and penetration, and the volume error at the end. tetpbd runs
//! twice: undamped, and with `DeformationDamping` 5/s (rapier's springs are critically
//! damped), then with more substeps (20, 40, 80, 160) until its volume error is at most
//! rapier's: the speed-up at equal error.

use std::time::Instant;

use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{
    ColliderBuilder, PhysicsWorld, RigidBodyBuilder, SoftBodyBuilder as RapierBuilder,
    SoftBodyCellModel, SoftBodyMaterial, SoftBodySolver, SpringCoefficients,
};
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{Particles, SoftBodyBuilder, SolverSettings, TetMesh, Tetrahedra};
use tetpbd_rapier::{CoupledWorld, CouplingSettings, DeformationDamping, SoftCollider};

const SUBSTEPS: u32 = 10;
/// rapier's frequency standing for "hard" (see `error_vs_time`).
const RAPIER_HARD_HZ: f32 = 1.0e6;

struct Result {
    ms: f64,
    max_speed: f32,
    penetration: f32,
    volume_error: f32,
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn volume(mesh: &TetMesh, x: &[Vector3<f32>]) -> f32 {
    mesh.tets
        .iter()
        .map(|t| {
            let [a, b, c, d] = t.map(|i| x[i as usize]);
            (b - a).dot(&(c - a).cross(&(d - a))) / 6.0
        })
        .sum()
}

/// tetpbd with deformation damping `rate` (1/s; 0 = none).
fn ours(
    mesh: &TetMesh,
    frames: usize,
    rate: f32,
    substeps: u32,
) -> std::result::Result<Result, Box<dyn std::error::Error>> {
    let solver = SolverSettings {
        substeps,
        ..SolverSettings::default()
    };
    let mut scene = CoupledWorld::new(solver, CouplingSettings::default())?;
    scene.physics.insert(
        RigidBodyBuilder::fixed().translation(Vector::new(0.0, -0.5, 0.0)),
        ColliderBuilder::cuboid(10.0, 0.5, 10.0),
    );
    let e = SoftBodyBuilder::new(mesh.clone())
        .density(1000.0)
        .edges(0.0)
        .volume(0.0)
        .translation(Vector3::new(0.0, 0.55, 0.0))
        .build()?
        .spawn(&mut scene.soft);
    scene.soft.insert_one(e, SoftCollider::default())?;
    if rate > 0.0 {
        scene.soft.insert_one(e, DeformationDamping::new(rate)?)?;
    }
    let mut times = Vec::new();
    for f in 0..frames {
        let t = Instant::now();
        scene.step()?;
        if f >= 120 {
            times.push(t.elapsed().as_secs_f64() * 1e3);
        }
    }
    let p = scene.soft.get::<&Particles>(e)?;
    let t = scene.soft.get::<&Tetrahedra>(e)?;
    Ok(Result {
        ms: median(times),
        max_speed: p.max_speed(),
        penetration: (-p.aabb().0.y).max(0.0),
        volume_error: (t.volume_ratio(p.positions()) - 1.0).abs(),
    })
}

fn rapier(mesh: &TetMesh, frames: usize) -> Result {
    let mut world = PhysicsWorld::new();
    world.integration_parameters.num_solver_iterations = SUBSTEPS as usize;
    world.insert(
        RigidBodyBuilder::fixed().translation(Vector::new(0.0, -0.5, 0.0)),
        ColliderBuilder::cuboid(10.0, 0.5, 10.0),
    );
    let k = SpringCoefficients::new(RAPIER_HARD_HZ, 1.0);
    let material = SoftBodyMaterial {
        edge_softness: k,
        volume_softness: k,
        ..Default::default()
    };
    let mut masses = vec![0.0f32; mesh.vertices.len()];
    for t in &mesh.tets {
        let [a, b, c, d] = t.map(|i| mesh.vertices[i as usize]);
        let v = ((b - a).dot(&(c - a).cross(&(d - a))) / 6.0).abs();
        for &i in t {
            masses[i as usize] += 1000.0 * v / 4.0;
        }
    }
    let b = RapierBuilder::new(
        mesh.vertices
            .iter()
            .map(|v| Vector::new(v.x, v.y + 0.55, v.z))
            .collect(),
    )
    .cells(mesh.tets.clone())
    .masses(masses)
    .edges(tetpbd::unique_edges(&mesh.tets))
    .cell_model(SoftBodyCellModel::Volume)
    .solver(SoftBodySolver::Constraints)
    .material(material)
    .can_sleep(false);
    let h = world.insert_soft_body(b);
    let mut times = Vec::new();
    for f in 0..frames {
        let t = Instant::now();
        world.step();
        if f >= 120 {
            times.push(t.elapsed().as_secs_f64() * 1e3);
        }
    }
    let x: Vec<Vector3<f32>> = world.soft_bodies[h]
        .particle_positions()
        .map(|p| Vector3::new(p.x, p.y, p.z))
        .collect();
    let v = world.soft_bodies[h]
        .particle_velocities()
        .map(|v| v.length())
        .fold(0.0, f32::max);
    let moved: Vec<Vector3<f32>> = mesh.vertices.clone();
    let v0 = volume(mesh, &moved);
    Result {
        ms: median(times),
        max_speed: v,
        penetration: (-x.iter().map(|p| p.y).fold(f32::INFINITY, f32::min)).max(0.0),
        volume_error: (volume(mesh, &x) / v0 - 1.0).abs(),
    }
}

fn main() -> std::result::Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let frames = args
        .iter()
        .position(|a| a == "--frames")
        .and_then(|i| args.get(i + 1))
        .and_then(|v| v.parse().ok())
        .unwrap_or(300usize)
        .max(121);
    println!("1 m soft cube (hard edges + volume), dropped 5 cm onto rigid ground, {SUBSTEPS} substeps, dt 1/60 s, {frames} frames");
    println!("engine                      tets   median ms/frame (rest)   max|v| m/s   penetration m   volume error %");
    for cells in [4u32, 8, 12] {
        let mesh = box_grid(Vector3::repeat(1.0), [cells; 3], CellSplit::Six)?;
        let o = ours(&mesh, frames, 0.0, SUBSTEPS)?;
        let d = ours(&mesh, frames, 5.0, SUBSTEPS)?;
        let r = rapier(&mesh, frames);
        for (name, x) in [
            ("tetpbd", &o),
            ("tetpbd, damping 5/s", &d),
            ("rapier Constraints Volume", &r),
        ] {
            println!(
                "{name:26} {:6}   {:22.3}   {:10.2e}   {:13.2e}   {:14.3}",
                mesh.tets.len(),
                x.ms,
                x.max_speed,
                x.penetration,
                x.volume_error * 100.0
            );
        }
        println!(
            "  speed-up (rapier ms / tetpbd ms): {:.2}× undamped, {:.2}× damped",
            r.ms / o.ms,
            r.ms / d.ms
        );
        // Equal error: the fewest tetpbd substeps whose volume error is at most rapier's. (The
        // settled max |v| is not used: in f32 it is a noise floor of about ulp(x)/h that grows
        // with the substep count, 1e-4 m/s at 10 substeps to 2e-3 at 160 for this cube.)
        let mut equal = None;
        for substeps in [20u32, 40, 80, 160] {
            let x = ours(&mesh, frames, 0.0, substeps)?;
            if x.volume_error <= r.volume_error {
                equal = Some((substeps, x));
                break;
            }
        }
        match equal {
            Some((n, x)) => println!(
                "  at equal or better volume error: tetpbd {n} substeps, {:.3} ms, max|v| {:.2e}, volume {:.4} %: {:.2}× rapier's speed",
                x.ms,
                x.max_speed,
                x.volume_error * 100.0,
                r.ms / x.ms
            ),
            None => println!("  at equal or better volume error: not reached with up to 160 substeps"),
        }
    }
    Ok(())
}
