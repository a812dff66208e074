//! With the `parallel` feature, results are bit-identical for any number of threads.
#![cfg(feature = "parallel")]

use nalgebra::Vector3;
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::{Particles, SoftBodyBuilder, Solver, SolverSettings};

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
