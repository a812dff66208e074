//! Criterion benchmarks of the performance issue's figures (the `projections`, `scaling` and
//! `vs_rapier` binaries print the same quantities as medians, with more options):
//!
//! * `projection/<family>/<kernel>`: one Gauss–Seidel sweep of one family's system over a
//!   19³-cell grid (41,154 tetrahedra) perturbed by 1 % of a cell, reset before every
//!   sweep; the throughput is projections, so criterion's time per element is the ns per
//!   projection;
//! * `frame/<set>/<tets>`: one 1/60 s frame (10 substeps) of a hanging 1 m cube (top face
//!   pinned) of about 1k, 10k and 100k tetrahedra, one thread;
//! * `resting/<scene>/<engine>`: one frame of a settled contact scene (a 1 m cube of 4³ or
//!   8³ cells resting on rigid ground) in tetpbd (with and without the self-weight sweep)
//!   and in rapier 0.36's built-in soft bodies (`Constraints`, hard), same mesh, 10
//!   substeps, in one process.
//!
//! ```text
//! cargo bench -p tetpbd-bench --bench kernels [-- FILTER]
//! ```

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use nalgebra::Vector3;
use rapier3d::prelude::{SoftBodyCellModel, SoftBodySolver};
use tetpbd::generators::{box_grid, CellSplit};
use tetpbd::systems::{self, Kernel};
use tetpbd::{Particles, SoftBodyBuilder, Solver, SolverSettings};
use tetpbd_bench::{build_contact, perturb, ContactEngine, ContactScene};

/// Substep length of the projection sweeps, s.
const H: f32 = 1.0 / 600.0;

/// A body with one family on a `cells`³ grid, its particles moved by up to 1 % of a cell.
fn perturbed(family: &str, cells: u32) -> (hecs::World, hecs::Entity, Vec<Vector3<f32>>) {
    let mesh = box_grid(Vector3::repeat(1.0), [cells; 3], CellSplit::Six).expect("mesh");
    let b = SoftBodyBuilder::new(mesh).density(1000.0);
    let b = match family {
        "edge" => b.edges(1e-6),
        "volume" => b.volume(1e-9),
        _ => b.vertex_face(1e-6),
    };
    let mut world = hecs::World::new();
    let e = b.build().expect("body").spawn(&mut world);
    let mut p = world.get::<&mut Particles>(e).expect("particles");
    perturb(&mut p, 1.0 / cells as f32).expect("finite");
    let original = p.positions().to_vec();
    drop(p);
    (world, e, original)
}

fn sweep(world: &mut hecs::World, family: &str, kernel: Kernel) -> u64 {
    let c = match family {
        "edge" => systems::project_edges_with(world, H, kernel),
        "volume" => systems::project_volume_with(world, H, kernel),
        _ => systems::project_vertex_face_with(world, H, kernel),
    };
    c.applied + c.degenerate
}

fn projections(c: &mut Criterion) {
    let mut g = c.benchmark_group("projection");
    for family in ["edge", "volume", "vertex-face"] {
        let (mut world, e, original) = perturbed(family, 19);
        let per_sweep = sweep(&mut world, family, Kernel::Simd);
        g.throughput(Throughput::Elements(per_sweep));
        for kernel in [Kernel::Scalar, Kernel::Simd] {
            let id = BenchmarkId::new(family, format!("{kernel:?}"));
            g.bench_function(id, |b| {
                b.iter_custom(|iters| {
                    let mut total = Duration::ZERO;
                    for _ in 0..iters {
                        if let Ok(mut p) = world.get::<&mut Particles>(e) {
                            p.positions_mut().copy_from_slice(&original);
                        }
                        systems::reset_lambdas(&mut world);
                        let t = Instant::now();
                        black_box(sweep(&mut world, family, kernel));
                        total += t.elapsed();
                    }
                    total
                })
            });
        }
    }
    g.finish();
}

fn frames(c: &mut Criterion) {
    let mut g = c.benchmark_group("frame");
    g.sample_size(20);
    for set in ["edges+volume", "vertex-face"] {
        for cells in [6u32, 12, 26] {
            let mesh = box_grid(Vector3::repeat(1.0), [cells; 3], CellSplit::Six).expect("mesh");
            let top: Vec<u32> = (0..mesh.vertices.len() as u32)
                .filter(|&i| mesh.vertices[i as usize].y > 0.4999)
                .collect();
            let tets = mesh.tets.len();
            let b = SoftBodyBuilder::new(mesh).density(1000.0).pinned(top);
            let b = match set {
                "edges+volume" => b.edges(1e-7).volume(1e-10),
                _ => b.vertex_face(1e-7),
            };
            let mut world = hecs::World::new();
            b.build().expect("body").spawn(&mut world);
            let mut solver = Solver::new(SolverSettings::default()).expect("settings");
            g.throughput(Throughput::Elements(tets as u64));
            g.bench_function(BenchmarkId::new(set, tets), |b| {
                b.iter(|| black_box(solver.step(&mut world).expect("step")))
            });
        }
    }
    g.finish();
}

fn resting(c: &mut Criterion) {
    let mut g = c.benchmark_group("resting");
    g.sample_size(20);
    let engines = [
        (
            "tetpbd",
            ContactEngine::Tetpbd {
                damping: 0.0,
                self_weight: false,
            },
        ),
        (
            "tetpbd self-weight",
            ContactEngine::Tetpbd {
                damping: 0.0,
                self_weight: true,
            },
        ),
        (
            "rapier",
            ContactEngine::Rapier {
                cell: SoftBodyCellModel::Volume,
                solver: SoftBodySolver::Constraints,
                hard: true,
            },
        ),
    ];
    for cells in [4u32, 8] {
        let scene = ContactScene::drop(cells, 1).expect("scene");
        for (name, engine) in engines {
            let mut sim = build_contact(engine, &scene, 10, 1).expect("scene");
            for _ in 0..120 {
                sim.step().expect("step");
            }
            let id = BenchmarkId::new(format!("cube {cells}³"), name);
            g.bench_function(id, |b| b.iter(|| black_box(sim.step().expect("step"))));
        }
    }
    g.finish();
}

criterion_group!(benches, projections, frames, resting);
criterion_main!(benches);
