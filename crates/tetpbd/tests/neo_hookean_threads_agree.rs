//! A body with the Neo-Hookean material and the seed's families steps bit-identically on any
//! number of threads (feature `parallel`): the material's sweep, like the families', splits
//! each colour class among the threads (from 4096 tetrahedra: the 16³-cell body) and is
//! bit-identical to the serial sweep.
#![cfg(feature = "parallel")]

mod common;

use tetpbd::generators::CellSplit;
use tetpbd::{Activation, Material, Particles, SoftBodyBuilder, Solver, SolverSettings};

/// Positions and velocities as bits after 10 frames of a hanging 1 m cube of `cells³` cells
/// with the material, soft edges and hard volumes, on a pool of `threads` threads.
fn run(threads: usize, cells: u32) -> Vec<[u32; 3]> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let mesh = common::cube(cells, CellSplit::Six);
        let top = common::top(&mesh);
        let mut world = hecs::World::new();
        let body = SoftBodyBuilder::new(mesh)
            .material(Material::SOFT_TISSUE)
            .edges(1e-3)
            .volume(0.0)
            .pinned(top);
        let e = body.build().unwrap().spawn(&mut world);
        *world.get::<&mut Activation>(e).unwrap() = Activation::never_sleeps();
        let mut solver = Solver::new(SolverSettings::default()).unwrap();
        for _ in 0..10 {
            solver.step(&mut world).unwrap();
        }
        let p = world.get::<&Particles>(e).unwrap();
        common::state_bits(&p)
    })
}

#[test]
fn material_bodies_agree_bit_for_bit_across_threads() {
    for cells in [4, 16] {
        let one = run(1, cells);
        for threads in [2, 3] {
            assert!(
                one == run(threads, cells),
                "{cells}³ cells: {threads} threads differ from one"
            );
        }
    }
}
