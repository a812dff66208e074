//! Does a stack of soft cubes on rigid ground come to rest, awake? The probe behind
//! `docs/decisions/resting-contacts.md`: default settings, sleeping off, and switches that
//! take one ingredient away at a time.
//!
//! ```text
//! cargo run --release -p tetpbd-bench --bin stack_rest -- [--cubes 5] [--size-mm 500]
//!     [--substeps 10] [--iterations 1] [--seconds 13] [--column] [--damping RATE]
//!     [--soft-friction-off] [--skin-speed-mm-s 100] [--touching] [--every-frames 30]
//!     [--five] [--spin-off] [--energy-limit-off] [--stacking-off] [--self-weight]
//! ```
//!
//! * `--column`: one body as tall as the stack (4 × 4·cubes × 4 cells) instead of cubes;
//! * `--damping RATE`: `DeformationDamping` (1/s) on every body;
//! * `--soft-friction-off`: friction 0 between the soft bodies (each body's `SoftCollider`
//!   friction 0, the ground's 1, so the ground contact keeps the default 0.5 by the average
//!   combine rule);
//! * `--skin-speed-mm-s`: `SoftContactSettings::skin_speed` in mm/s (default 100);
//! * `--touching`: the cubes start at the contact thickness instead of 2 cm apart;
//! * `--five`: cells split in five tetrahedra instead of six around the diagonal;
//! * `--spin-off`, `--energy-limit-off`: `SafetySettings::conserve_angular_momentum`,
//!   `limit_correction_energy` off; `--stacking-off`: `CouplingSettings::stacking` `None`;
//!   `--self-weight`: `StackingSettings::self_weight` on.
//!
//! Prints every `--every-frames` frames the mean kinetic energy since the last print, the
//! largest particle speed per body (bottom first) and the top body's centre, then the largest
//! speed over the last second, how far any particle of the top body moved over the last 10 s,
//! from when on every particle stayed below 1 mm/s, and per interface of two cubes the largest change of
//! their horizontal offset over those 10 s (the upper cube's bottom-face centre against the
//! lower cube's top-face centre: slip and rocking at the contact).

use clap::Parser;
use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{ColliderBuilder, RigidBodyBuilder};
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{hecs, Activation, DeformationDamping, Particles, SoftBodyBuilder, SolverSettings};
use tetpbd_bench::DT;

/// Does a stack of soft cubes on rigid ground come to rest, awake? Default settings, sleeping
/// off, and switches that take one ingredient away at a time.
#[derive(Parser)]
#[command(name = "stack_rest")]
struct Args {
    /// Cubes in the stack (at least 1).
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..))]
    cubes: u32,
    /// Side of each cube, mm.
    #[arg(long, default_value_t = 500)]
    size_mm: u32,
    /// Substeps per 1/60 s frame.
    #[arg(long, default_value_t = 10)]
    substeps: u32,
    /// Solver iterations per substep.
    #[arg(long, default_value_t = 1)]
    iterations: u32,
    /// Simulated time, s.
    #[arg(long, default_value_t = 13)]
    seconds: u32,
    /// Print the speeds every this many frames (at least 1).
    #[arg(long, default_value_t = 30, value_parser = clap::value_parser!(u32).range(1..))]
    every_frames: u32,
    /// `DeformationDamping` rate on every body, 1/s (none by default).
    #[arg(long, value_name = "RATE")]
    damping: Option<f32>,
    /// Friction 0 between the soft bodies (the ground contact keeps the default 0.5).
    #[arg(long)]
    soft_friction_off: bool,
    /// `SoftContactSettings::skin_speed`, mm/s (the default's otherwise).
    #[arg(long)]
    skin_speed_mm_s: Option<f32>,
    /// The cubes start at the contact thickness instead of 2 cm apart.
    #[arg(long)]
    touching: bool,
    /// One body as tall as the stack (4 × 4·cubes × 4 cells) instead of cubes.
    #[arg(long)]
    column: bool,
    /// `SafetySettings::conserve_angular_momentum` off.
    #[arg(long)]
    spin_off: bool,
    /// `SafetySettings::limit_correction_energy` off.
    #[arg(long)]
    energy_limit_off: bool,
    /// `CouplingSettings::stacking` off.
    #[arg(long)]
    stacking_off: bool,
    /// The cubes' cells split in five tetrahedra (mirrored in alternate cells) instead of six
    /// around the main diagonal.
    #[arg(long)]
    five: bool,
    /// `StackingSettings::self_weight` on.
    #[arg(long)]
    self_weight: bool,
}
use tetpbd_rapier::{CoupledWorld, CouplingSettings, SoftColliderBuilder};

type Res<T> = Result<T, Box<dyn std::error::Error>>;

fn main() -> Res<()> {
    let args = Args::parse();
    let n = args.cubes as usize;
    let size = args.size_mm as f32 * 1e-3;
    let (substeps, iterations) = (args.substeps, args.iterations);
    let seconds = args.seconds as f32;
    let every = args.every_frames as usize;
    let (damping, soft_friction_off) = (args.damping, args.soft_friction_off);
    let mut solver = SolverSettings {
        dt: DT,
        substeps,
        iterations,
        ..SolverSettings::default()
    };
    solver.safety.conserve_angular_momentum &= !args.spin_off;
    solver.safety.limit_correction_energy &= !args.energy_limit_off;
    let mut coupling = CouplingSettings::default();
    if args.stacking_off {
        coupling.stacking = None;
    }
    if let (true, Some(s)) = (args.self_weight, coupling.stacking.as_mut()) {
        s.self_weight = true;
    }
    let mut ground = ColliderBuilder::cuboid(20.0, 0.5, 20.0);
    if soft_friction_off {
        coupling.default_collider = SoftColliderBuilder::new()
            .friction(0.0)
            .static_friction(0.0)
            .build()?;
        ground = ground.friction(1.0);
    }
    if let (Some(v), Some(s)) = (args.skin_speed_mm_s, coupling.soft_contacts.as_mut()) {
        s.skin_speed = v * 1e-3;
    }
    let thickness = coupling.default_collider.thickness();
    let mut w = CoupledWorld::new(solver, coupling)?;
    w.physics.insert(
        RigidBodyBuilder::fixed().translation(Vector::new(0.0, -0.5, 0.0)),
        ground,
    );
    let (gap, lift) = if args.touching {
        (2.0 * thickness, thickness)
    } else {
        (0.02, 0.01)
    };
    let shapes: Vec<(Vector3<f32>, [u32; 3], f32)> = if args.column {
        let h = size * n as f32;
        vec![(
            Vector3::new(size, h, size),
            [4, 4 * n as u32, 4],
            lift + 0.5 * h,
        )]
    } else {
        (0..n)
            .map(|i| {
                let y = lift + 0.5 * size + i as f32 * (size + gap);
                (Vector3::repeat(size), [4, 4, 4], y)
            })
            .collect()
    };
    let split = if args.five {
        CellSplit::Five
    } else {
        CellSplit::Six
    };
    let mut bodies = Vec::new();
    for (extent, cells, y) in shapes {
        let e = SoftBodyBuilder::new(box_grid(extent, cells, split)?)
            .density(1000.0)
            .edges(0.0)
            .volume(0.0)
            .translation(Vector3::new(0.0, y, 0.0))
            .build()?
            .spawn(&mut w.soft);
        w.soft.insert_one(e, Activation::never_sleeps())?;
        if let Some(rate) = damping {
            w.soft.insert_one(e, DeformationDamping::new(rate)?)?;
        }
        bodies.push(e);
    }
    let speed = |w: &CoupledWorld, e: hecs::Entity| -> Res<f32> {
        Ok(w.soft.get::<&Particles>(e)?.max_speed())
    };
    let top = *bodies.last().ok_or("no body")?;
    let frames = (seconds / DT).round() as usize;
    let from = frames.saturating_sub((10.0 / DT) as usize).max(1);
    let (mut last_second, mut drift) = (0.0f32, 0.0f32);
    let mut reference: Option<Vec<Vector3<f32>>> = None;
    let mut offsets0: Vec<Vector3<f32>> = Vec::new();
    let mut slip = vec![0.0f32; bodies.len().saturating_sub(1)];
    let mut ke_sum = 0.0f64;
    // The last frame at which some particle moved at 1 mm/s or faster.
    let mut last_moving = 0usize;
    for f in 1..=frames {
        w.step()?;
        for &e in &bodies {
            ke_sum += f64::from(w.soft.get::<&Particles>(e)?.kinetic_energy());
        }
        let speeds: Vec<f32> = bodies.iter().map(|&e| speed(&w, e)).collect::<Res<_>>()?;
        let max = speeds.iter().copied().fold(0.0f32, f32::max);
        if f + 60 > frames {
            last_second = last_second.max(max);
        }
        if max >= 1e-3 {
            last_moving = f;
        }
        let offsets = interface_offsets(&w, &bodies)?;
        if f == from {
            offsets0 = offsets.clone();
        }
        for ((s, o), o0) in slip.iter_mut().zip(&offsets).zip(&offsets0) {
            *s = s.max((o - o0).norm());
        }
        let p = w.soft.get::<&Particles>(top)?;
        if f == from {
            reference = Some(p.positions().to_vec());
        }
        if let Some(x0) = &reference {
            let d = p.positions().iter().zip(x0).map(|(a, b)| (a - b).norm());
            drift = d.fold(drift, f32::max);
        }
        if f % every == 0 {
            let c = p.center_of_mass();
            let per: Vec<String> = speeds.iter().map(|v| format!("{v:.4}")).collect();
            println!(
                "t {:5.2} s  mean KE {:.2e} J  max|v| {max:.5} m/s  per body [{}]  top centre ({:.4}, {:.4}, {:.4}) m",
                f as f32 * DT,
                ke_sum / every as f64,
                per.join(" "),
                c.x,
                c.y,
                c.z
            );
            ke_sum = 0.0;
        }
    }
    println!(
        "largest speed over the last second {last_second:.2e} m/s; top body moved {:.2} mm over the last {:.0} s",
        drift * 1e3,
        (frames - from) as f32 * DT
    );
    println!(
        "below 1 mm/s for good from t = {:.2} s{}",
        last_moving as f32 * DT,
        if last_moving == frames {
            " (never)"
        } else {
            ""
        }
    );
    let slip: Vec<String> = slip.iter().map(|s| format!("{:.2}", s * 1e3)).collect();
    println!(
        "interfaces, bottom first: horizontal offset changed by [{}] mm",
        slip.join(" ")
    );
    Ok(())
}

/// Per pair of consecutive bodies: the horizontal offset of the upper body's lowest particles'
/// centre from the lower body's highest particles' centre, m.
fn interface_offsets(w: &CoupledWorld, bodies: &[hecs::Entity]) -> Res<Vec<Vector3<f32>>> {
    let face = |e: hecs::Entity, top: bool| -> Res<Vector3<f32>> {
        let p = w.soft.get::<&Particles>(e)?;
        let y = |x: &Vector3<f32>| if top { x.y } else { -x.y };
        let far = p
            .positions()
            .iter()
            .map(y)
            .fold(f32::NEG_INFINITY, f32::max);
        let face: Vec<&Vector3<f32>> = p.positions().iter().filter(|x| y(x) > far - 0.02).collect();
        let c = face.iter().copied().sum::<Vector3<f32>>() / face.len().max(1) as f32;
        Ok(Vector3::new(c.x, 0.0, c.z))
    };
    bodies
        .windows(2)
        .map(|pair| Ok(face(pair[1], false)? - face(pair[0], true)?))
        .collect()
}
