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
//! copies are two streaming passes over the particles, a few nanoseconds per particle for
//! both on one thread, run in parallel on large bodies with the `parallel` feature.

use hecs::World;

use crate::body::families::{EdgeConstraints, VertexFaceConstraints, VolumeConstraints};
use crate::body::mesh::Tetrahedra;
use crate::body::particles::Particles;
use crate::kernels::slots::{load_run, store_run, Slot, WorkAccess};

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

/// Copies positions and residuals back from the slots.
pub(crate) fn store(p: &mut Particles) {
    #[cfg(feature = "parallel")]
    if crate::parallel::sweeps::particles_worth_it(p.positions.len()) {
        crate::parallel::sweeps::store(&p.work.0, &mut p.positions, &mut p.residuals);
        return;
    }
    store_run(&p.work.0, &mut p.positions, &mut p.residuals);
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
/// vertex–face or volume family or a material.
type Swept<'a> = (
    &'a mut Particles,
    Option<&'a EdgeConstraints>,
    Option<&'a Tetrahedra>,
    Option<&'a VertexFaceConstraints>,
    Option<&'a VolumeConstraints>,
    Option<&'a crate::NeoHookeanMaterial>,
);

/// Runs `f` on every body a family system sweeps.
pub(crate) fn for_each_swept(world: &mut World, mut f: impl FnMut(&mut Particles)) {
    let swept = world.query_mut::<Swept<'_>>();
    for (p, e, t, vf, vol, m) in swept.without::<&crate::Asleep>() {
        if e.is_some() || (t.is_some() && (vf.is_some() || vol.is_some() || m.is_some())) {
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
