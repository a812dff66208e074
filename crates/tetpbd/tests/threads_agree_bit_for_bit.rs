//! With the `parallel` feature, results are bit-identical for any number of threads, with
//! every [`ParallelSettings`] option, and on the caller's pool or one given to the solver.
#![cfg(feature = "parallel")]

mod common;

use std::sync::Arc;
use std::time::Duration;

use tetpbd::{ParallelSettings, Particles, Solver, SolverSettings, SubstepContext, SubstepHook};

/// A hook slower than the time the step's helper threads wait for work (they leave, and the
/// passes after it wake the pool through rayon instead).
struct Slow;

impl SubstepHook for Slow {
    fn begin_substep(&mut self, _: &mut hecs::World, _: SubstepContext) {
        std::thread::sleep(Duration::from_millis(2));
    }
}

/// Runs `f` on a pool of `threads` threads.
fn on_threads<R: Send>(threads: usize, f: impl FnOnce() -> R + Send) -> R {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}

/// Positions and velocities, as bits, after `frames` frames of a hanging cube of `cells³`
/// cells on a pool of `threads` threads, with or without the slow hook.
fn run(threads: usize, cells: u32, substeps: u32, frames: usize, slow: bool) -> Vec<[u32; 3]> {
    run_parts(threads, cells, 0, substeps, frames, slow)
}

/// [`run`] with the body cut into `parts` slabs (0: the builder's choice).
fn run_parts(
    threads: usize,
    cells: u32,
    parts: usize,
    substeps: u32,
    frames: usize,
    slow: bool,
) -> Vec<[u32; 3]> {
    on_threads(threads, || {
        hanging_cube_bits(
            None,
            ParallelSettings::default(),
            cells,
            parts,
            substeps,
            frames,
            slow,
        )
    })
}

/// Steps a hanging cube on this thread, on `pool` if given, with `parallel`; its state as
/// bits.
fn hanging_cube_bits(
    pool: Option<Arc<rayon::ThreadPool>>,
    parallel: ParallelSettings,
    cells: u32,
    parts: usize,
    substeps: u32,
    frames: usize,
    slow: bool,
) -> Vec<[u32; 3]> {
    let mut world = hecs::World::new();
    let e = common::hanging_cube_parts(&mut world, cells, parts);
    let mut solver = Solver::new(SolverSettings {
        substeps,
        safety: tetpbd::SafetySettings {
            max_correction_speed: Some(5.0),
            ..Default::default()
        },
        parallel,
        ..Default::default()
    })
    .unwrap()
    .with_thread_pool(pool);
    for _ in 0..frames {
        if slow {
            solver.step_with(&mut world, &mut Slow).unwrap();
        } else {
            solver.step(&mut world).unwrap();
        }
    }
    let p = world.get::<&Particles>(e).unwrap();
    assert!(p.max_speed() > 0.01, "the body moves");
    common::state_bits(&p)
}

/// Every combination of the parallel options.
fn all_options() -> Vec<ParallelSettings> {
    let mut all = Vec::new();
    for serial in [false, true] {
        for keep_helpers_awake in [false, true] {
            for move_helpers_off_step_core in [false, true] {
                all.push(ParallelSettings {
                    serial,
                    keep_helpers_awake,
                    move_helpers_off_step_core,
                });
            }
        }
    }
    all
}

/// 16³ cells (every parallel pass, the particle passes included), with and without a hook
/// slower than the helpers' linger: every option, on 2 and 3 threads, run inside the pool
/// (`install`) and from a thread outside it with the pool given to the solver, agrees bit
/// for bit with one thread.
#[test]
fn every_option_and_a_given_pool_agree_bit_for_bit() {
    let (cells, substeps, frames) = (16, 2, 2);
    for slow in [false, true] {
        let one = run_parts(1, cells, 0, substeps, frames, slow);
        for threads in [2, 3] {
            let pool = Arc::new(
                rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap(),
            );
            for options in all_options() {
                let what = format!("{threads} threads, {options:?}, slow hook {slow}");
                let inside = pool
                    .install(|| hanging_cube_bits(None, options, cells, 0, substeps, frames, slow));
                assert_eq!(one, inside, "installed, {what}");
                let given = hanging_cube_bits(
                    Some(pool.clone()),
                    options,
                    cells,
                    0,
                    substeps,
                    frames,
                    slow,
                );
                assert_eq!(one, given, "given, {what}");
            }
        }
    }
}

/// 12³ cells × 6 = 10 368 tetrahedra: above the parallel threshold of every family (the
/// 2197 particles are below that of the particle passes).
#[test]
fn one_two_and_three_threads_agree_bit_for_bit() {
    let one = run(1, 12, 5, 10, false);
    assert_eq!(one, run(2, 12, 5, 10, false));
    assert_eq!(one, run(3, 12, 5, 10, false));
}

/// 16³ cells: 4913 particles, above the threshold of the particle passes too (prediction,
/// copies, multiplier reset, velocity update), with and without a hook slower than the
/// team's linger.
#[test]
fn large_body_agrees_bit_for_bit_with_and_without_a_slow_hook() {
    let one = run(1, 16, 3, 3, false);
    assert_eq!(one, run(2, 16, 3, 3, false));
    assert_eq!(one, run(3, 16, 3, 3, false));
    assert_eq!(one, run(2, 16, 3, 3, true));
}

/// Positions and velocities, as bits, after 2 frames of 3 substeps of a free mirrored cube
/// of 16³ cells (4913 particles, above the particle passes' threshold) released with the
/// safety net at 5 m/s on a pool of `threads` threads: the net clamps, and gives the
/// linear momentum back, every substep.
fn run_free_mirrored(threads: usize) -> Vec<[u32; 3]> {
    use tetpbd::generators::CellSplit;
    on_threads(threads, || {
        let mut world = hecs::World::new();
        let e = tetpbd::SoftBodyBuilder::new(common::cube(16, CellSplit::Six))
            .edges(0.0)
            .volume(0.0)
            .build()
            .unwrap()
            .spawn(&mut world);
        common::deform(&mut world, e, common::Deformation::Mirrored);
        let mut solver = Solver::new(SolverSettings {
            substeps: 3,
            safety: tetpbd::SafetySettings {
                max_correction_speed: Some(5.0),
                limit_correction_energy: false,
                ..Default::default()
            },
            ..Default::default()
        })
        .unwrap();
        let mut clamps = 0;
        for _ in 0..2 {
            clamps += solver.step(&mut world).unwrap().velocity_clamps;
        }
        assert!(clamps > 0, "the net acts");
        let p = world.get::<&Particles>(e).unwrap();
        common::state_bits(&p)
    })
}

#[test]
fn safety_net_momentum_restoration_agrees_bit_for_bit() {
    let one = run_free_mirrored(1);
    assert_eq!(one, run_free_mirrored(2));
    assert_eq!(one, run_free_mirrored(3));
}

/// A body cut into 2, 3 and 4 slabs (tasks of interiors and interfaces, then the rest's
/// classes): 1, 2 and 3 threads agree bit for bit for each cut.
#[test]
fn partitioned_bodies_agree_bit_for_bit() {
    for parts in [2, 3, 4] {
        let one = run_parts(1, 12, parts, 3, 4, false);
        assert_eq!(one, run_parts(2, 12, parts, 3, 4, false), "{parts} parts");
        assert_eq!(one, run_parts(3, 12, parts, 3, 4, false), "{parts} parts");
    }
}
