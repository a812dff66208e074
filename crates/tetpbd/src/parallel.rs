//! Parallel Gauss–Seidel (feature `parallel`): within a colour class no two constraints
//! share a particle, so a class's projections run concurrently on rayon's pool and the
//! result is bit-identical to the serial sweep, for any number of threads. Classes run one
//! after another; the overflow class (see [`crate::ordering`]) runs serially.

use nalgebra::Vector3;
use rayon::prelude::*;

use crate::families::{EdgeConstraints, VertexFaceConstraints, VolumeConstraints};
use crate::mesh::Tetrahedra;
use crate::particles::Particles;
use crate::projection::ParticleAccess;
use crate::systems::{edge_run, vertex_face_run, volume_run, Kernel, ProjectionCount};

/// Bodies with fewer constraints in a family than this take the serial path.
pub(crate) const MIN_PARALLEL: usize = 4096;

/// Items per rayon task (a multiple of the SIMD lanes).
const CHUNK: usize = 256;

/// Shared access for the projections of one colour class.
#[derive(Clone, Copy)]
struct SharedAccess {
    x: *mut Vector3<f32>,
    r: *mut Vector3<f32>,
    w: *const f32,
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
    fn new(p: &mut Particles) -> SharedAccess {
        SharedAccess {
            x: p.positions.as_mut_ptr(),
            r: p.residuals.as_mut_ptr(),
            w: p.inv_masses.as_ptr(),
            rest: p.rest_positions.as_ptr(),
            len: p.positions.len(),
        }
    }
}

impl ParticleAccess for SharedAccess {
    #[inline(always)]
    fn x(&self, i: usize) -> Vector3<f32> {
        assert!(i < self.len);
        // SAFETY: in bounds (checked); no other thread writes particle `i` (colour class).
        unsafe { *self.x.add(i) }
    }
    #[inline(always)]
    fn w(&self, i: usize) -> f32 {
        assert!(i < self.len);
        // SAFETY: in bounds (checked); inverse masses are not written during a sweep.
        unsafe { *self.w.add(i) }
    }
    #[inline(always)]
    fn rest(&self, i: usize) -> Vector3<f32> {
        assert!(i < self.len);
        // SAFETY: in bounds (checked); rest positions are never written during a sweep.
        unsafe { *self.rest.add(i) }
    }
    #[inline(always)]
    fn add(&mut self, i: usize, d: Vector3<f32>) {
        assert!(i < self.len);
        // SAFETY: in bounds (checked); particle `i` belongs to this item alone within the
        // running colour class, so these are the only references to it.
        unsafe { crate::systems::add_compensated(&mut *self.x.add(i), &mut *self.r.add(i), d) }
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
    p: &mut Particles,
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
    p: &mut Particles,
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
    p: &mut Particles,
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
