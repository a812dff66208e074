//! The memory of the working copy: one 32-byte slot per particle, the serial access the
//! kernels read and write it through, and the copies of a run of particles in and out.

use std::fmt;

use nalgebra::Vector3;
use wide::f32x4;

use crate::kernels::scalar::ParticleAccess;

/// One particle during a sweep.
#[derive(Clone, Copy, Default)]
#[repr(C)]
pub(crate) struct Slot {
    /// `[x, y, z, w]`: position (m) and inverse mass (1/kg).
    pub xw: f32x4,
    /// `[rx, ry, rz, 0]`: rounding residual of the substep's position updates (m).
    pub r: f32x4,
}

impl Slot {
    /// Moves the particle by `d` (`[dx, dy, dz, 0]`), keeping the rounding error in the
    /// residual: [`crate::solver::systems::add_compensated`] on four lanes (the inverse mass lane
    /// adds 0 and stays as it is).
    #[inline(always)]
    pub fn add(&mut self, d: f32x4) {
        let old = self.xw;
        let new = old + d;
        self.r += d - (new - old);
        self.xw = new;
    }
}

/// The working copy of one body's particles (scratch, not state: never compared, never
/// serialized, rebuilt by every sweep).
#[derive(Clone, Default)]
pub(crate) struct WorkCopy(pub(crate) Vec<Slot>);

impl fmt::Debug for WorkCopy {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "WorkCopy({} slots)", self.0.len())
    }
}

/// [`load`](crate::kernels::working_copy::load) of a run of particles.
pub(crate) fn load_run(slots: &mut [Slot], x: &[Vector3<f32>], w: &[f32], r: &[Vector3<f32>]) {
    for (((s, x), w), r) in slots.iter_mut().zip(x).zip(w).zip(r) {
        s.xw = f32x4::new([x.x, x.y, x.z, *w]);
        s.r = f32x4::new([r.x, r.y, r.z, 0.0]);
    }
}

/// [`store`](crate::kernels::working_copy::store) of a run of particles.
pub(crate) fn store_run(slots: &[Slot], x: &mut [Vector3<f32>], r: &mut [Vector3<f32>]) {
    for ((s, x), r) in slots.iter().zip(x).zip(r) {
        let [a, b, c, _] = s.xw.to_array();
        *x = Vector3::new(a, b, c);
        let [a, b, c, _] = s.r.to_array();
        *r = Vector3::new(a, b, c);
    }
}

/// Serial access to the slots.
pub(crate) struct WorkAccess<'a> {
    pub slots: &'a mut [Slot],
    pub rest: &'a [Vector3<f32>],
}

impl ParticleAccess for WorkAccess<'_> {
    #[inline(always)]
    fn row(&self, i: usize) -> f32x4 {
        self.slots[i].xw
    }
    #[inline(always)]
    fn rest(&self, i: usize) -> Vector3<f32> {
        self.rest[i]
    }
    #[inline(always)]
    fn add_row(&mut self, i: usize, d: f32x4) {
        self.slots[i].add(d);
    }
    #[inline(always)]
    fn len(&self) -> usize {
        self.slots.len()
    }
    #[inline(always)]
    unsafe fn row_unchecked(&self, i: usize) -> f32x4 {
        // SAFETY: `i < self.slots.len()` (the caller's contract).
        unsafe { self.slots.get_unchecked(i).xw }
    }
    #[inline(always)]
    unsafe fn add_row_unchecked(&mut self, i: usize, d: f32x4) {
        // SAFETY: `i < self.slots.len()` (the caller's contract).
        unsafe { self.slots.get_unchecked_mut(i).add(d) }
    }
}
