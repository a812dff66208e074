//! Parallel Gauss–Seidel (feature `parallel`): within a colour class no two constraints
//! share a particle, so a class's projections run concurrently on rayon's pool and the
//! result is bit-identical to the serial sweep, for any number of threads. Classes run one
//! after another; the overflow class (see [`crate::ordering`]) runs serially.

use nalgebra::Vector3;
use rayon::prelude::*;

use crate::families::{EdgeConstraints, VertexFaceConstraints, VolumeConstraints};
use crate::mesh::Tetrahedra;
use crate::particles::Particles;
use crate::projection::{self, ParticleAccess};
use crate::systems::ProjectionCount;

/// Bodies with fewer constraints in a family than this take the serial path.
pub(crate) const MIN_PARALLEL: usize = 4096;

/// Items per rayon task.
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

/// Runs `f` over the items of every class: independent classes in parallel chunks,
/// the overflow class serially.
fn sweep<T: Send>(
    classes: &crate::ordering::ColourClasses,
    items: &mut [T],
    acc: SharedAccess,
    f: impl Fn(&mut SharedAccess, usize, &mut T) -> ProjectionCount + Sync,
) -> ProjectionCount {
    let mut total = ProjectionCount::default();
    for (range, independent) in classes.ranges() {
        let start = range.start;
        let class = &mut items[range];
        if independent {
            total += class
                .par_chunks_mut(CHUNK)
                .enumerate()
                .map(|(c, chunk)| {
                    let mut a = acc;
                    let mut n = ProjectionCount::default();
                    for (k, item) in chunk.iter_mut().enumerate() {
                        n += f(&mut a, start + c * CHUNK + k, item);
                    }
                    n
                })
                .reduce(ProjectionCount::default, |mut a, b| {
                    a += b;
                    a
                });
        } else {
            let mut a = acc;
            for (k, item) in class.iter_mut().enumerate() {
                total += f(&mut a, start + k, item);
            }
        }
    }
    total
}

fn one(o: projection::Outcome) -> ProjectionCount {
    let mut c = ProjectionCount::default();
    c.add(o);
    c
}

pub(crate) fn edges(
    p: &mut Particles,
    e: &mut EdgeConstraints,
    alpha_tilde: f32,
) -> ProjectionCount {
    let acc = SharedAccess::new(p);
    let (edges, rest) = (&e.edges, &e.rest_lengths);
    sweep(&e.classes, &mut e.lambdas, acc, |a, k, lambda| {
        one(projection::edge(a, edges[k], rest[k], lambda, alpha_tilde))
    })
}

pub(crate) fn volume(
    p: &mut Particles,
    tets: &Tetrahedra,
    vol: &mut VolumeConstraints,
    alpha_tilde: f32,
) -> ProjectionCount {
    let acc = SharedAccess::new(p);
    sweep(&tets.classes, &mut vol.lambdas, acc, |a, t, lambda| {
        one(projection::volume(
            a,
            tets.indices[t],
            tets.rest_volumes[t],
            lambda,
            alpha_tilde,
        ))
    })
}

pub(crate) fn vertex_face(
    p: &mut Particles,
    tets: &Tetrahedra,
    vf: &mut VertexFaceConstraints,
    alpha_tilde: f32,
) -> ProjectionCount {
    let acc = SharedAccess::new(p);
    let heights = &vf.rest_heights;
    sweep(&tets.classes, &mut vf.lambdas, acc, |a, t, lambdas| {
        let (applied, degenerate) =
            projection::vertex_face(a, tets.indices[t], &heights[t], lambdas, alpha_tilde);
        ProjectionCount {
            applied: u64::from(applied),
            degenerate: u64::from(degenerate),
        }
    })
}
