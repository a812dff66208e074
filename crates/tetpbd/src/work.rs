//! The layout the projections run on: a working copy of the particles, one 32-byte slot
//! each, position and inverse mass in one 16-byte row, rounding residual in the next.
//!
//! [`crate::Particles`] keeps one flat `Vector3` array per quantity (its public slices).
//! A 12-byte `Vector3` needs three scalar loads per gather and three scalar stores per
//! scatter, and the inverse mass and residual live in other arrays (other cache lines).
//! Each family system copies the particles into their slots ([`load`]), sweeps, and copies
//! them back ([`store`]): one aligned load fetches a particle's position and inverse mass, a
//! 4 × 4 transpose turns four of them into lanes (see [`crate::lanes`]), and the compensated
//! update of a particle is a handful of 4-wide operations on its two rows. The copies cost
//! two streaming passes over the particles per sweep, a fraction of the sweep itself (about
//! five tetrahedra or six edges per particle).

use std::fmt;

use nalgebra::Vector3;
use wide::f32x4;

use crate::particles::Particles;
use crate::projection::ParticleAccess;

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
    /// residual: [`crate::systems::add_compensated`] on four lanes (the inverse mass lane
    /// adds 0 and stays as it is).
    #[inline(always)]
    pub fn add(&mut self, d: f32x4) {
        let old = self.xw;
        let new = old + d;
        self.r += d - (new - old);
        self.xw = new;
    }
}

/// The working copy of one body's particles (scratch, not state: always equal, never
/// serialized, rebuilt by every sweep).
#[derive(Clone, Default)]
pub(crate) struct WorkCopy(pub(crate) Vec<Slot>);

impl PartialEq for WorkCopy {
    fn eq(&self, _: &WorkCopy) -> bool {
        true
    }
}

impl fmt::Debug for WorkCopy {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "WorkCopy({} slots)", self.0.len())
    }
}

/// Copies positions, inverse masses and residuals into the slots (sized on first use).
pub(crate) fn load(p: &mut Particles) {
    let n = p.positions.len();
    let slots = &mut p.work.0;
    if slots.len() != n {
        slots.resize(n, Slot::default());
    }
    for (((s, x), w), r) in slots
        .iter_mut()
        .zip(&p.positions)
        .zip(&p.inv_masses)
        .zip(&p.residuals)
    {
        s.xw = f32x4::new([x.x, x.y, x.z, *w]);
        s.r = f32x4::new([r.x, r.y, r.z, 0.0]);
    }
}

/// Copies positions and residuals back from the slots.
pub(crate) fn store(p: &mut Particles) {
    for ((s, x), r) in p.work.0.iter().zip(&mut p.positions).zip(&mut p.residuals) {
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
}

/// Runs `f` on the body's slots between [`load`] and [`store`].
pub(crate) fn with_access<T>(p: &mut Particles, f: impl FnOnce(&mut WorkAccess<'_>) -> T) -> T {
    load(p);
    let out = f(&mut WorkAccess {
        slots: &mut p.work.0,
        rest: &p.rest_positions,
    });
    store(p);
    out
}
