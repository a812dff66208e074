//! With the `parallel` feature, results are bit-identical for any number of threads.
#![cfg(feature = "parallel")]

use std::time::Duration;

use nalgebra::Vector3;
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{Particles, SoftBodyBuilder, Solver, SolverSettings, SubstepHook};

fn run(threads: usize) -> Vec<[u32; 3]> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let mut world = hecs::World::new();
        // 12³ cells × 6 = 10 368 tetrahedra: above the parallel threshold for every family.
        let mesh = box_grid(Vector3::new(1.0, 1.0, 1.0), [12; 3], CellSplit::Six).unwrap();
        let top: Vec<u32> = (0..mesh.vertices.len() as u32)
            .filter(|&i| mesh.vertices[i as usize].y > 0.49)
            .collect();
        let e = SoftBodyBuilder::new(mesh)
            .edges(1e-6)
            .volume(0.0)
            .vertex_face(1e-5)
            .pinned(top)
            .build()
            .unwrap()
            .spawn(&mut world);
        let mut solver = Solver::new(SolverSettings {
            substeps: 5,
            ..Default::default()
        })
        .unwrap();
        for _ in 0..10 {
            solver.step(&mut world).unwrap();
        }
        let p = world.get::<&Particles>(e).unwrap();
        assert!(p.max_speed() > 0.01, "the body moves");
        p.positions()
            .iter()
            .map(|x| x.map(f32::to_bits).into())
            .collect()
    })
}

#[test]
fn one_two_and_three_threads_agree_bit_for_bit() {
    let one = run(1);
    assert_eq!(one, run(2));
    assert_eq!(one, run(3));
}

/// A hook slower than the time the step's helper threads wait for work (they leave, and the
/// passes after it wake the pool through rayon instead).
struct Slow;

impl SubstepHook for Slow {
    fn begin_substep(&mut self, _: &mut hecs::World, _: f32) {
        std::thread::sleep(Duration::from_millis(2));
    }
}

/// A body above the parallel threshold of the particle passes too (prediction, copies,
/// velocity update: 4096 particles), stepped with and without a slow hook.
fn run_large(threads: usize, slow: bool) -> Vec<[u32; 3]> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let mut world = hecs::World::new();
        // 16³ cells: 4913 particles, 24 576 tetrahedra.
        let mesh = box_grid(Vector3::new(1.0, 1.0, 1.0), [16; 3], CellSplit::Six).unwrap();
        let top: Vec<u32> = (0..mesh.vertices.len() as u32)
            .filter(|&i| mesh.vertices[i as usize].y > 0.49)
            .collect();
        let e = SoftBodyBuilder::new(mesh)
            .edges(1e-6)
            .volume(0.0)
            .vertex_face(1e-5)
            .pinned(top)
            .build()
            .unwrap()
            .spawn(&mut world);
        let mut solver = Solver::new(SolverSettings {
            substeps: 3,
            max_correction_speed: Some(5.0),
            ..Default::default()
        })
        .unwrap();
        for _ in 0..3 {
            if slow {
                solver.step_with(&mut world, &mut Slow).unwrap();
            } else {
                solver.step(&mut world).unwrap();
            }
        }
        let p = world.get::<&Particles>(e).unwrap();
        assert!(p.max_speed() > 0.01, "the body moves");
        p.positions()
            .iter()
            .chain(p.velocities())
            .map(|x| x.map(f32::to_bits).into())
            .collect()
    })
}

#[test]
fn large_body_agrees_bit_for_bit_with_and_without_a_slow_hook() {
    let one = run_large(1, false);
    assert_eq!(one, run_large(2, false));
    assert_eq!(one, run_large(3, false));
    assert_eq!(one, run_large(2, true));
}
