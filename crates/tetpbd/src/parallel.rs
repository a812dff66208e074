//! Parallel Gauss–Seidel (feature `parallel`): within a colour class no two constraints
//! share a particle, so a class's projections run concurrently on rayon's pool and the
//! result is bit-identical to the serial sweep, for any number of threads. Classes run one
//! after another; the overflow class (see [`crate::ordering`]) runs serially.

use nalgebra::Vector3;
use rayon::prelude::*;
use wide::f32x4;

use crate::families::{EdgeConstraints, VertexFaceConstraints, VolumeConstraints};
use crate::mesh::Tetrahedra;
use crate::projection::ParticleAccess;
use crate::runs::{edge_run, vertex_face_run, volume_run};
use crate::systems::{Kernel, ProjectionCount};
use crate::work::{Slot, WorkAccess};

/// Bodies with fewer constraints in a family than this take the serial path.
const MIN_PARALLEL: usize = 4096;

/// Whether a family of `len` constraints runs on the pool: large enough, and the pool has
/// more than one thread (on one thread the serial sweep does the same work without the
/// per-class task overhead; the results are bit-identical either way).
pub(crate) fn worth_it(len: usize) -> bool {
    len >= MIN_PARALLEL && rayon::current_num_threads() > 1
}

/// Items per rayon task (a multiple of the SIMD lanes).
const CHUNK: usize = 256;

/// Shared access to a body's working copy for the projections of one colour class.
#[derive(Clone, Copy)]
struct SharedAccess {
    slots: *mut Slot,
    rest: *const Vector3<f32>,
    len: usize,
}

// SAFETY: a `SharedAccess` is only handed to the projections of one colour class, which
// touch pairwise disjoint particles (greedy colouring; the overflow class, whose items may
// overlap, never runs in parallel). The slices it points into outlive the parallel loop and
// are borrowed mutably by it, so no other access exists meanwhile.
unsafe impl Send for SharedAccess {}
// SAFETY: as above.
unsafe impl Sync for SharedAccess {}

impl SharedAccess {
    fn new(acc: &mut WorkAccess<'_>) -> SharedAccess {
        SharedAccess {
            slots: acc.slots.as_mut_ptr(),
            rest: acc.rest.as_ptr(),
            len: acc.slots.len().min(acc.rest.len()),
        }
    }
}

impl ParticleAccess for SharedAccess {
    #[inline(always)]
    fn row(&self, i: usize) -> f32x4 {
        assert!(i < self.len);
        // SAFETY: in bounds (checked); no other thread writes particle `i` (colour class).
        unsafe { (*self.slots.add(i)).xw }
    }
    #[inline(always)]
    fn rest(&self, i: usize) -> Vector3<f32> {
        assert!(i < self.len);
        // SAFETY: in bounds (checked, `rest` has `len` items); never written during a sweep.
        unsafe { *self.rest.add(i) }
    }
    #[inline(always)]
    fn add_row(&mut self, i: usize, d: f32x4) {
        assert!(i < self.len);
        // SAFETY: in bounds (checked); particle `i` belongs to this item alone within the
        // running colour class, so this is the only reference to it.
        unsafe { (*self.slots.add(i)).add(d) }
    }
}

/// Runs `f` over every class: independent classes split into chunks of [`CHUNK`] items
/// run in parallel, the overflow class serially. `f` gets the access, the run's first item
/// index, the run's multipliers and whether the run is independent.
fn sweep<T: Send>(
    classes: &crate::ordering::ColourClasses,
    items: &mut [T],
    acc: SharedAccess,
    f: impl Fn(&mut SharedAccess, usize, &mut [T], bool) -> ProjectionCount + Sync,
) -> ProjectionCount {
    let mut total = ProjectionCount::default();
    for (range, independent) in classes.ranges() {
        let start = range.start;
        let class = &mut items[range];
        if independent {
            total += class
                .par_chunks_mut(CHUNK)
                .enumerate()
                .map(|(c, chunk)| f(&mut { acc }, start + c * CHUNK, chunk, true))
                .reduce(ProjectionCount::default, |mut a, b| {
                    a += b;
                    a
                });
        } else {
            total += f(&mut { acc }, start, class, false);
        }
    }
    total
}

pub(crate) fn edges(
    p: &mut WorkAccess<'_>,
    e: &mut EdgeConstraints,
    alpha_tilde: f32,
    kernel: Kernel,
) -> ProjectionCount {
    let acc = SharedAccess::new(p);
    let (edges, rest) = (&e.edges, &e.rest_lengths);
    sweep(&e.classes, &mut e.lambdas, acc, |a, s, lam, ind| {
        let r = s..s + lam.len();
        edge_run(
            a,
            &edges[r.clone()],
            &rest[r],
            lam,
            alpha_tilde,
            kernel,
            ind,
        )
    })
}

pub(crate) fn volume(
    p: &mut WorkAccess<'_>,
    tets: &Tetrahedra,
    vol: &mut VolumeConstraints,
    alpha_tilde: f32,
    kernel: Kernel,
) -> ProjectionCount {
    let acc = SharedAccess::new(p);
    sweep(&tets.classes, &mut vol.lambdas, acc, |a, s, lam, ind| {
        let r = s..s + lam.len();
        let (t, rest) = (&tets.indices[r.clone()], &tets.rest_volumes[r]);
        volume_run(a, t, rest, lam, alpha_tilde, kernel, ind)
    })
}

pub(crate) fn vertex_face(
    p: &mut WorkAccess<'_>,
    tets: &Tetrahedra,
    vf: &mut VertexFaceConstraints,
    alpha_tilde: f32,
    kernel: Kernel,
) -> ProjectionCount {
    let acc = SharedAccess::new(p);
    let heights = &vf.rest_heights;
    sweep(&tets.classes, &mut vf.lambdas, acc, |a, s, lam, ind| {
        let r = s..s + lam.len();
        vertex_face_run(
            a,
            &tets.indices[r.clone()],
            &heights[r],
            lam,
            alpha_tilde,
            kernel,
            ind,
        )
    })
}
