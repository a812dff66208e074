//! `Skin::deform` allocates nothing (a counting global allocator, in its own test binary).
#![cfg(feature = "mesher")]

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use nalgebra::Vector3;
use tetpbd::generators::{self, CellSplit};
use tetpbd_io::Skin;

struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

// SAFETY: forwards every call to the system allocator unchanged; only counts them.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::SeqCst);
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: `ptr` was allocated by `System` with `layout`.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::SeqCst);
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn deform_does_not_allocate() {
    let mesh = generators::box_grid(Vector3::repeat(1.0), [4, 4, 4], CellSplit::Six).unwrap();
    let points: Vec<_> = (0..1000)
        .map(|i| Vector3::new((i % 10) as f32, ((i / 10) % 10) as f32, (i / 100) as f32) / 9.0)
        .map(|p| p - Vector3::repeat(0.5))
        .collect();
    let skin = Skin::embed(&mesh.vertices, &mesh.tets, &points).unwrap();
    let moved: Vec<_> = mesh.vertices.iter().map(|p| p * 1.5).collect();
    let mut out = vec![Vector3::zeros(); points.len()];
    let before = ALLOCATIONS.load(Ordering::SeqCst);
    for _ in 0..10 {
        skin.deform(&moved, &mut out).unwrap();
    }
    let after = ALLOCATIONS.load(Ordering::SeqCst);
    assert_eq!(after - before, 0, "deform allocated");
    assert!(
        (out[999] - Vector3::repeat(0.75)).norm() < 1e-5,
        "{}",
        out[999]
    );
}
