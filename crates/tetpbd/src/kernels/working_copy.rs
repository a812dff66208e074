//! The layout the projections run on: a working copy of the particles, one 32-byte slot
//! each, position and inverse mass in one 16-byte row, rounding residual in the next.
//!
//! [`crate::Particles`] keeps one flat `Vector3` array per quantity (its public slices).
//! A 12-byte `Vector3` needs three scalar loads per gather and three scalar stores per
//! scatter, and the inverse mass and residual live in other arrays (other cache lines).
//! The particles are copied into their slots ([`load`]), swept, and copied back
//! ([`store`]): one aligned load fetches a particle's position and inverse mass, a 4 × 4
//! transpose turns four of them into lanes (see [`crate::kernels::lanes`]), and the compensated
//! update of a particle is a handful of 4-wide operations on its two rows. A public family
//! system copies in and out around its own sweep ([`CopyMode::PerSweep`]); the solver copies
//! once per iteration around all the families of a body ([`CopyMode::Resident`]). The
//! copies are two streaming passes over the particles, about 3 ns per particle for both on
//! one thread (0.55 ms per frame of 10 substeps for 19,683 particles, docs/performance.md,
//! "Scaling"), run in parallel on large bodies with the `parallel` feature.

use std::fmt;

use hecs::World;
use nalgebra::Vector3;
use wide::f32x4;

use crate::body::families::{EdgeConstraints, VertexFaceConstraints, VolumeConstraints};
use crate::body::mesh::Tetrahedra;
use crate::body::particles::Particles;
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
    #[cfg(feature = "parallel")]
    if crate::parallel::sweeps::particles_worth_it(n) {
        crate::parallel::sweeps::load(slots, &p.positions, &p.inv_masses, &p.residuals);
        return;
    }
    load_run(slots, &p.positions, &p.inv_masses, &p.residuals);
}

/// [`load`] of a run of particles.
pub(crate) fn load_run(slots: &mut [Slot], x: &[Vector3<f32>], w: &[f32], r: &[Vector3<f32>]) {
    for (((s, x), w), r) in slots.iter_mut().zip(x).zip(w).zip(r) {
        s.xw = f32x4::new([x.x, x.y, x.z, *w]);
        s.r = f32x4::new([r.x, r.y, r.z, 0.0]);
    }
}

/// Copies positions and residuals back from the slots.
pub(crate) fn store(p: &mut Particles) {
    #[cfg(feature = "parallel")]
    if crate::parallel::sweeps::particles_worth_it(p.positions.len()) {
        crate::parallel::sweeps::store(&p.work.0, &mut p.positions, &mut p.residuals);
        return;
    }
    store_run(&p.work.0, &mut p.positions, &mut p.residuals);
}

/// [`store`] of a run of particles.
pub(crate) fn store_run(slots: &[Slot], x: &mut [Vector3<f32>], r: &mut [Vector3<f32>]) {
    for ((s, x), r) in slots.iter().zip(x).zip(r) {
        let [a, b, c, _] = s.xw.to_array();
        *x = Vector3::new(a, b, c);
        let [a, b, c, _] = s.r.to_array();
        *r = Vector3::new(a, b, c);
    }
}

/// Whether a family system copies the particles into the working copy and back itself
/// ([`CopyMode::PerSweep`], what the public systems do: `Particles` is up to date between
/// any two of them), or finds them there ([`CopyMode::Resident`]: the solver loads every
/// body once per iteration with [`load_bodies`], runs the families, and stores once with
/// [`store_bodies`]; nothing reads `Particles` in between).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum CopyMode {
    /// Load before the sweep, store after it.
    PerSweep,
    /// The slots hold the body (loaded by [`load_bodies`]).
    Resident,
}

/// The bodies some family system sweeps: those with edges, or with tetrahedra and a
/// vertex–face or volume family.
type Swept<'a> = (
    &'a mut Particles,
    Option<&'a EdgeConstraints>,
    Option<&'a Tetrahedra>,
    Option<&'a VertexFaceConstraints>,
    Option<&'a VolumeConstraints>,
);

/// Runs `f` on every body a family system sweeps.
pub(crate) fn for_each_swept(world: &mut World, mut f: impl FnMut(&mut Particles)) {
    for (p, e, t, vf, vol) in world.query_mut::<Swept<'_>>() {
        if e.is_some() || (t.is_some() && (vf.is_some() || vol.is_some())) {
            f(p);
        }
    }
}

/// [`load`] for every body a family system sweeps.
pub(crate) fn load_bodies(world: &mut World) {
    for_each_swept(world, load);
}

/// [`store`] for every body a family system sweeps.
pub(crate) fn store_bodies(world: &mut World) {
    for_each_swept(world, store);
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

/// Runs `f` on the body's slots: between [`load`] and [`store`] in [`CopyMode::PerSweep`],
/// on the slots as they are in [`CopyMode::Resident`].
pub(crate) fn with_access<T>(
    p: &mut Particles,
    mode: CopyMode,
    f: impl FnOnce(&mut WorkAccess<'_>) -> T,
) -> T {
    if mode == CopyMode::PerSweep {
        load(p);
    }
    debug_assert_eq!(p.work.0.len(), p.positions.len(), "the body was loaded");
    let out = f(&mut WorkAccess {
        slots: &mut p.work.0,
        rest: &p.rest_positions,
    });
    if mode == CopyMode::PerSweep {
        store(p);
    }
    out
}
