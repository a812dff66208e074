//! The cost of one optional piece of the solver (a component or a setting): two copies of the
//! same free cube, one with the piece and one without, stepped in alternating frames, so a
//! change of the machine's load hits both alike. `spin_cost`, `untangle_cost`, `plastic_cost`
//! and `tearing_cost` measure this way.

use std::error::Error;
use std::time::Instant;

use nalgebra::Vector3;
use tetpbd::{Particles, SoftBodyBuilder, Solver, SolverSettings, StepStats, TetMesh};

use crate::DT;

/// Frames stepped before the measured ones (first-frame set-up and caches).
const WARM_UP_FRAMES: usize = 2;

/// One copy of the scene: its world and its solver.
pub type Run = (hecs::World, Solver);

/// A free body from `mesh` (1000 kg/m³) in a world of its own, its families and the piece under
/// test added by `finish`, never sleeping (sleeping would end the work being measured), and,
/// for `spin` ≠ 0, spinning about y through its centre of mass at `spin` rad/s, so the
/// corrections are not zero.
pub fn free_body(
    mesh: &TetMesh,
    spin: f32,
    finish: impl FnOnce(SoftBodyBuilder) -> SoftBodyBuilder,
) -> Result<(hecs::World, hecs::Entity), Box<dyn Error>> {
    let mut world = hecs::World::new();
    let e = finish(SoftBodyBuilder::new(mesh.clone()).density(1000.0))
        .build()?
        .spawn(&mut world);
    world.insert_one(e, tetpbd::Activation::never_sleeps())?;
    if spin != 0.0 {
        let mut p = world.get::<&mut Particles>(e)?;
        let c = p.center_of_mass();
        for i in 0..p.len() {
            let v = Vector3::new(0.0, spin, 0.0).cross(&(p.positions()[i] - c));
            p.set_velocity(i, v)?;
        }
    }
    Ok((world, e))
}

/// A solver at the benchmarks' frame step [`DT`] with zero gravity, its settings otherwise the
/// defaults changed by `change`.
pub fn zero_gravity_solver(
    change: impl FnOnce(&mut SolverSettings),
) -> Result<Solver, tetpbd::SettingsError> {
    let mut settings = SolverSettings {
        dt: DT,
        gravity: Vector3::zeros(),
        ..Default::default()
    };
    change(&mut settings);
    Solver::new(settings)
}

/// Steps every run in turn, frame by frame: two warm-up frames, then `frames` measured ones,
/// each handed to `record` as (the run's index, its wall time in ms, its statistics, its
/// solver).
pub fn step_alternately(
    runs: &mut [Run],
    frames: usize,
    mut record: impl FnMut(usize, f64, &StepStats, &Solver) -> Result<(), Box<dyn Error>>,
) -> Result<(), Box<dyn Error>> {
    for f in 0..frames + WARM_UP_FRAMES {
        for (i, (world, solver)) in runs.iter_mut().enumerate() {
            let t = Instant::now();
            let stats = solver.step(world)?;
            let ms = t.elapsed().as_secs_f64() * 1e3;
            if f >= WARM_UP_FRAMES {
                record(i, ms, &stats, solver)?;
            }
        }
    }
    Ok(())
}
