//! With the `parallel` feature, a step of a body large enough for every parallel path (the
//! colour-class sweeps, the copies into the working copy, prediction and the velocity update)
//! allocates nothing on any thread once the first frame has run.
//!
//! Its own test binary: the counter counts the allocations of every thread of the process,
//! and the only other thread is the test harness's, waiting for this test.
#![cfg(feature = "parallel")]

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicU64, Ordering};

use std::sync::Arc;

use tetpbd::{ParallelSettings, Particles, Solver, SolverSettings};

/// Counts the allocations of all threads.
struct Counting;

static ALLOCATIONS: AtomicU64 = AtomicU64::new(0);

// SAFETY: forwards every call to the system allocator unchanged; only counts.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        // SAFETY: same contract as ours.
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: same contract as ours.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        // SAFETY: same contract as ours.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Allocations in 10 steps (after a first one) of a large hanging cube and a partitioned
/// one, with `parallel`, on a pool of two threads: run inside it, or given to the solver
/// and stepped from this thread (where rayon's queue that hands each pass to the pool
/// allocates a block now and then).
fn allocations_in_steps(parallel: ParallelSettings, given: bool) -> u64 {
    let pool = Arc::new(
        rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap(),
    );
    let mut world = hecs::World::new();
    // 16³ cells: 4913 particles and 24 576 tetrahedra, above every parallel threshold; a
    // second copy cut into 4 slabs (the partitioned sweep's tasks).
    let body = common::hanging_cube(&mut world, 16);
    let parted = common::hanging_cube_parts(&mut world, 16, 4);
    let mut solver = Solver::new(SolverSettings {
        substeps: 4,
        safety: tetpbd::SafetySettings {
            max_correction_speed: Some(10.0),
            ..Default::default()
        },
        parallel,
        ..Default::default()
    })
    .unwrap();
    if given {
        solver.set_thread_pool(Some(pool.clone()));
    }
    let mut steps = || {
        solver.step(&mut world).unwrap();
        let before = ALLOCATIONS.load(Ordering::SeqCst);
        for _ in 0..10 {
            solver.step(&mut world).unwrap();
        }
        ALLOCATIONS.load(Ordering::SeqCst) - before
    };
    let counted = if given { steps() } else { pool.install(steps) };
    for e in [body, parted] {
        let p = world.get::<&Particles>(e).unwrap();
        assert!(p.max_speed() > 0.01, "the body moves");
    }
    counted
}

/// Stepped on one of the pool's threads, with the helpers sleeping between passes (the
/// default) or kept awake.
#[test]
fn parallel_steps_after_the_first_allocate_nothing() {
    let before = ALLOCATIONS.load(Ordering::SeqCst);
    std::hint::black_box(vec![1u8; 16]);
    assert!(
        ALLOCATIONS.load(Ordering::SeqCst) > before,
        "the counter counts"
    );
    let awake = ParallelSettings {
        keep_helpers_awake: true,
        ..Default::default()
    };
    for parallel in [ParallelSettings::default(), awake] {
        let counted = allocations_in_steps(parallel, false);
        assert_eq!(counted, 0, "allocations in 10 parallel steps, {parallel:?}");
    }
}
