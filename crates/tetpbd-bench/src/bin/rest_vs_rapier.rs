//! Rest and sleep, tetpbd (through `tetpbd-rapier`, default settings, soft–soft contacts
//! on) against rapier 0.36's built-in soft bodies on the same two scenes, in one process:
//!
//! * **stack**: five 0.5 m cubes of 4³ cells (1000 kg/m³) stacked 2 cm apart on rigid ground;
//! * **pile**: twenty such cubes dropped in layers of 3 × 3, each layer shifted by a quarter
//!   cube (the layout of `examples/sleeping_pile.rs`).
//!
//! ```text
//! cargo run --release -p tetpbd-bench --bin rest_vs_rapier [-- --substeps N] [--stack] [--pile]
//! ```
//!
//! Each engine runs each scene twice. **Awake** (sleeping off in both engines: the rest is
//! the solver's): the time after which the largest particle speed (displacement over a frame
//! / dt) stays below 1e-3 m/s to the end of the run ("—": not at rest by then), that speed
//! over the last second and its largest value after the time the scene should be at rest by
//! (a late topple shows there), how far any particle of the top body moves over the last 10 s
//! (from 3 s on for the stack, 6 s on for the pile), and the deepest interpenetration of two
//! bodies over the whole run (a surface particle inside another body's tetrahedra, m).
//! **Sleeping** (each engine's defaults: tetpbd's `Activation`, rapier's `can_sleep`): the
//! time at which every body is asleep, and the median wall ms per frame over the 60 frames
//! before (awake) and the 60 after (asleep; the last 60 frames when they never sleep).
//! Ratios are tetpbd / rapier. rapier: the Volume cell model with hard edges and volumes
//! (`tetpbd_bench::rapier_material`), `num_solver_iterations` = substeps (default 10 in both).

use std::error::Error;
use std::time::Instant;

use clap::Parser;
use nalgebra::Vector3;
use rapier3d::math::Vector;
use rapier3d::prelude::{
    ColliderBuilder, PhysicsWorld, RigidBodyBuilder, SoftBodyBuilder as RapierBuilder,
    SoftBodyCellModel, SoftBodyHandle, SoftBodySolver,
};
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{hecs, is_sleeping, unique_edges, Activation, SoftBodyBuilder, SolverSettings};
use tetpbd::{Particles, Surface, TetMesh};
use tetpbd_bench::{
    interpenetration, lumped_masses, rapier_material, to_rapier, ContactKind, ContactScene, DT,
};
use tetpbd_rapier::{CoupledWorld, CouplingSettings};

type Res<T> = Result<T, Box<dyn Error>>;

/// Rest and sleep, tetpbd against rapier 0.36's soft bodies on a stack of five cubes and a
/// pile of twenty, awake and sleeping.
#[derive(Parser)]
#[command(name = "rest_vs_rapier")]
struct Args {
    /// Substeps per 1/60 s frame (and rapier's solver iterations).
    #[arg(long, default_value_t = 10)]
    substeps: u32,
    /// The stack only.
    #[arg(long, conflicts_with = "pile")]
    stack: bool,
    /// The pile only.
    #[arg(long)]
    pile: bool,
}

/// Cube edge, m.
const SIZE: f32 = 0.5;
/// Density, kg/m³.
const DENSITY: f32 = 1000.0;
/// Largest particle speed counted as at rest, m/s.
const REST_SPEED: f32 = 1e-3;

/// A scene: name, cube centres, when it should be at rest (s) and how long it runs (s).
struct Layout {
    name: &'static str,
    at: Vec<Vector3<f32>>,
    rest_by: f32,
    seconds: f32,
}

fn stack() -> Layout {
    let at = (0..5)
        .map(|i| Vector3::new(0.0, 0.01 + 0.5 * SIZE + i as f32 * (SIZE + 0.02), 0.0))
        .collect();
    Layout {
        name: "stack of 5",
        at,
        rest_by: 3.0,
        seconds: 13.0,
    }
}

/// Layers of 3 × 3 cubes 5 cm apart, each layer shifted by a quarter cube.
fn pile() -> Layout {
    let at = (0..20)
        .map(|i| {
            let (layer, k) = (i / 9, i % 9);
            let shift = if layer % 2 == 1 { 0.25 * SIZE } else { 0.0 };
            let pitch = SIZE + 0.05;
            Vector3::new(
                (k % 3) as f32 * pitch - pitch + shift,
                0.5 * SIZE + 0.01 + layer as f32 * (SIZE + 0.1),
                (k / 3) as f32 * pitch - pitch + shift,
            )
        })
        .collect();
    Layout {
        name: "pile of 20",
        at,
        rest_by: 6.0,
        seconds: 16.0,
    }
}

/// One engine's running scene.
trait Sim {
    /// One frame; its wall time, ms.
    fn step(&mut self) -> Res<f64>;
    /// Particle positions of every body, bodies in layout order.
    fn positions(&self) -> Vec<Vec<Vector3<f32>>>;
    /// Bodies asleep.
    fn asleep(&self) -> usize;
}

fn ground() -> (RigidBodyBuilder, ColliderBuilder) {
    (
        RigidBodyBuilder::fixed().translation(Vector::new(0.0, -0.5, 0.0)),
        ColliderBuilder::cuboid(20.0, 0.5, 20.0),
    )
}

struct Ours {
    world: CoupledWorld,
    bodies: Vec<hecs::Entity>,
}

impl Ours {
    fn new(cube: &TetMesh, l: &Layout, substeps: u32, can_sleep: bool) -> Res<Ours> {
        let solver = SolverSettings {
            dt: DT,
            substeps,
            ..SolverSettings::default()
        };
        let mut world = CoupledWorld::new(solver, CouplingSettings::default())?;
        let (b, c) = ground();
        world.physics.insert(b, c);
        let mut bodies = Vec::new();
        for at in &l.at {
            let e = SoftBodyBuilder::new(cube.clone())
                .density(DENSITY)
                .edges(0.0)
                .volume(0.0)
                .translation(*at)
                .build()?
                .spawn(&mut world.soft);
            if !can_sleep {
                world.soft.insert_one(e, Activation::never_sleeps())?;
            }
            bodies.push(e);
        }
        Ok(Ours { world, bodies })
    }
}

impl Sim for Ours {
    fn step(&mut self) -> Res<f64> {
        let t = Instant::now();
        self.world.step()?;
        Ok(t.elapsed().as_secs_f64() * 1e3)
    }

    fn positions(&self) -> Vec<Vec<Vector3<f32>>> {
        let get = |&e: &hecs::Entity| {
            self.world
                .soft
                .get::<&Particles>(e)
                .map(|p| p.positions().to_vec())
                .unwrap_or_default()
        };
        self.bodies.iter().map(get).collect()
    }

    fn asleep(&self) -> usize {
        let asleep = |&&e: &&hecs::Entity| is_sleeping(&self.world.soft, e);
        self.bodies.iter().filter(asleep).count()
    }
}

struct Theirs {
    world: PhysicsWorld,
    bodies: Vec<SoftBodyHandle>,
}

impl Theirs {
    fn new(cube: &TetMesh, l: &Layout, substeps: u32, can_sleep: bool) -> Theirs {
        let mut world = PhysicsWorld::new();
        world.integration_parameters.dt = DT;
        world.integration_parameters.num_solver_iterations = substeps as usize;
        let (b, c) = ground();
        world.insert(b, c);
        let masses = lumped_masses(cube, DENSITY);
        let edges = unique_edges(&cube.tets);
        let bodies =
            l.at.iter()
                .map(|at| {
                    let x = cube.vertices.iter().map(|v| to_rapier(&(v + at))).collect();
                    let builder = RapierBuilder::new(x)
                        .cells(cube.tets.clone())
                        .masses(masses.clone())
                        .cell_model(SoftBodyCellModel::Volume)
                        .solver(SoftBodySolver::Constraints)
                        .material(rapier_material(SoftBodyCellModel::Volume, true))
                        .edges(edges.clone())
                        .can_sleep(can_sleep);
                    world.insert_soft_body(builder)
                })
                .collect();
        Theirs { world, bodies }
    }
}

impl Sim for Theirs {
    fn step(&mut self) -> Res<f64> {
        let t = Instant::now();
        self.world.step();
        Ok(t.elapsed().as_secs_f64() * 1e3)
    }

    fn positions(&self) -> Vec<Vec<Vector3<f32>>> {
        let get = |&h: &SoftBodyHandle| {
            self.world.soft_bodies[h]
                .particle_positions()
                .map(|p| Vector3::new(p.x, p.y, p.z))
                .collect()
        };
        self.bodies.iter().map(get).collect()
    }

    fn asleep(&self) -> usize {
        let asleep = |&&h: &&SoftBodyHandle| self.world.soft_bodies[h].is_sleeping();
        self.bodies.iter().filter(asleep).count()
    }
}

/// What the awake run gave (module docs).
struct Rest {
    at: Option<f32>,
    last_second: f32,
    after_rest_by: f32,
    top_drift: f32,
    interpenetration: f32,
}

/// What the sleeping run gave (module docs).
struct Sleep {
    at: Option<f32>,
    awake_ms: f64,
    asleep_ms: f64,
}

/// The body whose centre is highest.
fn top(x: &[Vec<Vector3<f32>>]) -> usize {
    let height = |b: &Vec<Vector3<f32>>| b.iter().map(|p| p.y).sum::<f32>() / b.len() as f32;
    (0..x.len())
        .max_by(|&a, &b| height(&x[a]).total_cmp(&height(&x[b])))
        .unwrap_or(0)
}

fn awake_run(sim: &mut dyn Sim, l: &Layout, measure: &ContactScene) -> Res<Rest> {
    let frames = (l.seconds / DT).round() as usize;
    let from = (l.rest_by / DT).round() as usize;
    let mut prev = sim.positions();
    let (mut moving_until, mut last_second, mut inter) = (0usize, 0.0f32, 0.0f32);
    let mut after_rest_by = 0.0f32;
    let mut reference: Option<(usize, Vec<Vector3<f32>>)> = None;
    let mut drift = 0.0f32;
    for f in 1..=frames {
        sim.step()?;
        let x = sim.positions();
        let speed = x
            .iter()
            .flatten()
            .zip(prev.iter().flatten())
            .map(|(p, q)| (p - q).norm() / DT)
            .fold(0.0f32, f32::max);
        if speed.is_nan() || speed >= REST_SPEED {
            moving_until = f;
        }
        if f + 60 > frames {
            last_second = last_second.max(speed);
        }
        if f > from {
            after_rest_by = after_rest_by.max(speed);
        }
        // Every other frame while things land, then every 10th.
        if f % if f < from { 2 } else { 10 } == 0 || f == frames {
            inter = inter.max(interpenetration(measure, &x));
        }
        if f == from {
            let t = top(&x);
            reference = Some((t, x[t].clone()));
        }
        if let Some((t, x0)) = &reference {
            let d = x[*t].iter().zip(x0).map(|(p, q)| (p - q).norm());
            drift = d.fold(drift, f32::max);
        }
        prev = x;
    }
    Ok(Rest {
        at: (moving_until < frames).then_some(moving_until as f32 * DT),
        last_second,
        after_rest_by,
        top_drift: drift,
        interpenetration: inter,
    })
}

fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    match s.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => s[n / 2],
        n => 0.5 * (s[n / 2 - 1] + s[n / 2]),
    }
}

fn sleep_run(sim: &mut dyn Sim, l: &Layout) -> Res<Sleep> {
    let frames = (l.seconds / DT).round() as usize;
    let n = l.at.len();
    let mut ms = Vec::with_capacity(frames + 60);
    let mut at = None;
    for f in 1..=frames {
        ms.push(sim.step()?);
        if sim.asleep() == n {
            at = Some(f);
            break;
        }
    }
    let Some(slept) = at else {
        let tail = &ms[ms.len().saturating_sub(60)..];
        return Ok(Sleep {
            at: None,
            awake_ms: median(tail),
            asleep_ms: f64::NAN,
        });
    };
    let awake_ms = median(&ms[ms.len().saturating_sub(61)..ms.len() - 1]);
    let asleep: Vec<f64> = (0..60).map(|_| sim.step()).collect::<Res<_>>()?;
    Ok(Sleep {
        at: Some(slept as f32 * DT),
        awake_ms,
        asleep_ms: median(&asleep),
    })
}

fn secs(t: Option<f32>) -> String {
    t.map_or_else(|| "—".to_string(), |t| format!("{t:.2} s"))
}

fn ratio(a: f64, b: f64) -> String {
    let r = a / b;
    if r.is_finite() {
        format!("{r:.2}")
    } else {
        "—".to_string()
    }
}

fn compare(cube: &TetMesh, l: &Layout, substeps: u32) -> Res<()> {
    let measure = ContactScene {
        kind: ContactKind::Pile,
        name: l.name,
        cube: cube.clone(),
        cells: 4,
        surface: Surface::from_tetrahedra(&cube.tets, &cube.vertices),
        placements: l.at.clone(),
        density: DENSITY,
        frames: 0,
        rest_from: 0,
        rest_volume: 0.0,
    };
    println!(
        "\n{} ({} s, at rest by {} s), {substeps} substeps",
        l.name, l.seconds, l.rest_by
    );
    println!(
        "{:8} {:>10} {:>12} {:>12} {:>12} {:>12} {:>10} {:>12} {:>12} {:>8}",
        "engine",
        "rest at",
        "|v| last 1s",
        "|v| after",
        "top moves",
        "interpen.",
        "asleep at",
        "ms awake",
        "ms asleep",
        "asleep %"
    );
    let mut rows = Vec::new();
    for engine in ["tetpbd", "rapier"] {
        let build = |can_sleep| -> Res<Box<dyn Sim>> {
            Ok(match engine {
                "tetpbd" => Box::new(Ours::new(cube, l, substeps, can_sleep)?),
                _ => Box::new(Theirs::new(cube, l, substeps, can_sleep)),
            })
        };
        let rest = awake_run(build(false)?.as_mut(), l, &measure)?;
        let sleep = sleep_run(build(true)?.as_mut(), l)?;
        println!(
            "{engine:8} {:>10} {:>12.2e} {:>12.2e} {:>10.2} mm {:>9.2} mm {:>10} {:>12.3} {:>12.3} {:>8.1}",
            secs(rest.at),
            rest.last_second,
            rest.after_rest_by,
            rest.top_drift * 1e3,
            rest.interpenetration * 1e3,
            secs(sleep.at),
            sleep.awake_ms,
            sleep.asleep_ms,
            100.0 * sleep.asleep_ms / sleep.awake_ms
        );
        rows.push((rest, sleep));
    }
    let ((r0, s0), (r1, s1)) = (&rows[0], &rows[1]);
    let t = |r: &Rest| r.at.map_or(f64::NAN, f64::from);
    let st = |s: &Sleep| s.at.map_or(f64::NAN, f64::from);
    println!(
        "tetpbd / rapier: time to rest {}, time to sleep {}, ms awake {}, ms asleep {}",
        ratio(t(r0), t(r1)),
        ratio(st(s0), st(s1)),
        ratio(s0.awake_ms, s1.awake_ms),
        ratio(s0.asleep_ms, s1.asleep_ms)
    );
    Ok(())
}

fn main() -> Res<()> {
    let Args {
        substeps,
        stack: only_stack,
        pile: only_pile,
    } = Args::parse();
    let cube = box_grid(Vector3::repeat(SIZE), [4, 4, 4], CellSplit::Six)?;
    if !only_pile {
        compare(&cube, &stack(), substeps)?;
    }
    if !only_stack {
        compare(&cube, &pile(), substeps)?;
    }
    Ok(())
}
