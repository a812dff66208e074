//! With the `parallel` feature, the energy limit of the families' corrections gives the same
//! bits on any number of threads.
#![cfg(feature = "parallel")]

mod common;

use tetpbd::generators::CellSplit;
use tetpbd::{Particles, Solver, SolverSettings};

/// Positions and velocities, as bits, after 2 frames of 3 substeps of a free mirrored cube
/// of 16³ cells (4913 particles, above the particle passes' threshold) on `threads` threads:
/// the limit acts in every substep.
fn run_free_mirrored(threads: usize) -> Vec<[u32; 3]> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(|| {
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
                    limit_correction_energy: true,
                    ..Default::default()
                },
                ..Default::default()
            })
            .unwrap();
            let mut limited = 0;
            for _ in 0..2 {
                limited += solver.step(&mut world).unwrap().energy_limited;
            }
            assert!(limited > 0, "the limit acts");
            let p = world.get::<&Particles>(e).unwrap();
            common::state_bits(&p)
        })
}

#[test]
fn energy_limit_agrees_bit_for_bit_on_one_two_and_three_threads() {
    let one = run_free_mirrored(1);
    assert_eq!(one, run_free_mirrored(2));
    assert_eq!(one, run_free_mirrored(3));
}
