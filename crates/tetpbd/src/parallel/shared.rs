//! Memory the threads of one parallel region share, each writing its own part: the one
//! place the parallel sweeps reach for raw pointers.
//!
//! * [`Shared`] — a mutable slice cut into disjoint runs, one per call of a region's work
//!   ([`Disjoint`] and [`for_runs`] hand the runs out without `unsafe` at the call site);
//! * [`SharedAccess`] — the working copy of a body, read and written by the projections of
//!   one colour class (or of one phase of a partitioned sweep), which touch disjoint
//!   particles.

use std::marker::PhantomData;
use std::ops::Range;

use nalgebra::Vector3;
use wide::f32x4;

use crate::kernels::scalar::ParticleAccess;
use crate::kernels::slots::{Slot, WorkAccess};
use crate::parallel::schedule::{run_phases, Split};

/// A mutable slice shared by the threads of one parallel region, each taking disjoint runs.
pub(crate) struct Shared<'a, T> {
    ptr: *mut T,
    len: usize,
    _borrow: PhantomData<&'a mut [T]>,
}

// SAFETY: the threads of a region take the runs of [`Shared::run`] as [`run_phases`] hands
// them out, every item of a phase to exactly one call; the slice is borrowed mutably for as
// long as the `Shared` lives (`Shared::new`), so no other access exists meanwhile.
unsafe impl<T: Send> Sync for Shared<'_, T> {}

impl<'a, T> Shared<'a, T> {
    /// Shares `items` (borrowed mutably for as long as the `Shared` lives).
    pub fn new(items: &'a mut [T]) -> Shared<'a, T> {
        Shared {
            ptr: items.as_mut_ptr(),
            len: items.len(),
            _borrow: PhantomData,
        }
    }

    /// The items `range`.
    ///
    /// # Safety
    /// No other live reference may overlap `range`.
    #[allow(clippy::mut_from_ref)]
    pub unsafe fn run(&self, range: Range<usize>) -> &mut [T] {
        assert!(range.start <= range.end && range.end <= self.len);
        // SAFETY: in bounds (checked); exclusive by the caller's guarantee.
        unsafe { std::slice::from_raw_parts_mut(self.ptr.add(range.start), range.len()) }
    }
}

/// Shared slices cut into the same runs: one [`Shared`] or a tuple of them.
pub(crate) trait Disjoint: Sync {
    /// The runs of one range.
    type Run<'r>
    where
        Self: 'r;

    /// The runs `range` of every slice.
    ///
    /// # Safety
    /// No other live run may overlap `range`.
    unsafe fn runs(&self, range: Range<usize>) -> Self::Run<'_>;
}

impl<T: Send> Disjoint for Shared<'_, T> {
    type Run<'r>
        = &'r mut [T]
    where
        Self: 'r;

    unsafe fn runs(&self, range: Range<usize>) -> &mut [T] {
        // SAFETY: the caller's guarantee, passed on.
        unsafe { self.run(range) }
    }
}

impl<A: Disjoint, B: Disjoint> Disjoint for (A, B) {
    type Run<'r>
        = (A::Run<'r>, B::Run<'r>)
    where
        Self: 'r;

    unsafe fn runs(&self, range: Range<usize>) -> Self::Run<'_> {
        // SAFETY: the caller's guarantee, passed on to each slice.
        unsafe { (self.0.runs(range.clone()), self.1.runs(range)) }
    }
}

impl<A: Disjoint, B: Disjoint, C: Disjoint, D: Disjoint> Disjoint for (A, B, C, D) {
    type Run<'r>
        = (A::Run<'r>, B::Run<'r>, C::Run<'r>, D::Run<'r>)
    where
        Self: 'r;

    unsafe fn runs(&self, range: Range<usize>) -> Self::Run<'_> {
        // SAFETY: the caller's guarantee, passed on to each slice.
        unsafe {
            (
                self.0.runs(range.clone()),
                self.1.runs(range.clone()),
                self.2.runs(range.clone()),
                self.3.runs(range),
            )
        }
    }
}

/// Runs `f` over `len` items in runs of `chunk` on the pool (one phase of independent items,
/// see [`run_phases`]), handing each call its range and the matching runs of `shared`;
/// returns the sum of what `f` returned.
pub(crate) fn for_runs<'s, S: Disjoint, C: Default + std::ops::AddAssign + Send>(
    len: usize,
    chunk: usize,
    shared: &'s S,
    f: impl Fn(Range<usize>, S::Run<'s>) -> C + Sync,
) -> C {
    run_phases(
        1,
        chunk,
        |_| (len, Split::Lanes),
        |_, r| {
            // SAFETY: `run_phases` hands each item of the phase to exactly one call, so the runs
            // of two calls never overlap, and `shared` borrows its slices mutably meanwhile.
            let runs = unsafe { shared.runs(r.clone()) };
            f(r, runs)
        },
    )
}

/// Shared access to a body's working copy for the projections of one colour class.
#[derive(Clone, Copy)]
pub(crate) struct SharedAccess {
    slots: *mut Slot,
    rest: *const Vector3<f32>,
    len: usize,
}

// SAFETY: a `SharedAccess` is only handed to the projections of one colour class, which
// touch pairwise disjoint particles (greedy colouring; the overflow class, whose items may
// overlap, never runs in parallel), or to the tasks of one phase of a partitioned sweep,
// which touch disjoint slabs of particles (crate::ordering::partition). The slices it points into outlive the parallel loop and
// are borrowed mutably by it, so no other access exists meanwhile.
unsafe impl Send for SharedAccess {}
// SAFETY: as above.
unsafe impl Sync for SharedAccess {}

impl SharedAccess {
    pub(crate) fn new(acc: &mut WorkAccess<'_>) -> SharedAccess {
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
    #[inline(always)]
    fn len(&self) -> usize {
        self.len
    }
    #[inline(always)]
    unsafe fn row_unchecked(&self, i: usize) -> f32x4 {
        // SAFETY: `i < self.len` (the caller's contract); no other thread writes particle
        // `i` (colour class, as in `row`).
        unsafe { (*self.slots.add(i)).xw }
    }
    #[inline(always)]
    unsafe fn add_row_unchecked(&mut self, i: usize, d: f32x4) {
        // SAFETY: `i < self.len` (the caller's contract); particle `i` is this item's alone
        // within the running colour class, as in `add_row`.
        unsafe { (*self.slots.add(i)).add(d) }
    }
}
