//! The stacking pass: shock propagation through a soft body that carries a heavy rigid
//! body on an immovable support.
//!
//! One Gauss–Seidel iteration per substep cannot carry a large mass ratio through a soft
//! body: a 1000 kg box on a 1 kg slab pushes the particles under it down by its share of
//! `g·h²` every substep, the slab's own constraints (projected with the particles' masses)
//! give back only part of it, and the slab is crushed within a second (before this pass,
//! under every configuration of the stability matrix at 10 substeps × 1 iteration).
//!
//! So after the ordinary projections of an iteration, a soft body that
//!
//! * touches an immovable support — a fixed or kinematic collider, a *supported* rigid
//!   body (infinitely heavy inside the substeps, `rigid::body` module docs), an anchored body
//!   its own supports hold in the substep (`contacts::support` module docs: a light box on
//!   the ground under a soft slab carrying a heavy box) — or has pinned particles, and
//! * carries a dynamic rigid body at least [`crate::StackingSettings::mass_ratio`]
//!   times heavier than the particles it touches (the body's generalized mass at the
//!   contact against the particle's mass, or the triangle's mean particle mass),
//!
//! is swept once more from the ground up, as Guendelman et al. (2003) propagate shocks
//! through a stack of rigid bodies:
//!
//! 1. the particles in an active contact with an immovable support, and pinned particles,
//!    are the roots (the levels are kept while the roots stay the same);
//! 2. the body's own constraints are projected once more, level by level away from the
//!    roots, with the roots held ([`tetpbd::GroundUpSweep`]): each level is corrected
//!    against the levels below it, which were corrected just before, so the support's
//!    reaction reaches the top of the body within the sweep. (Holding every lower level,
//!    as shock propagation holds the lower bodies of a rigid stack, blew bodies of 8 levels
//!    and more up under a heavy box: the module docs of the core's `stabilisation::ground_up`.)
//! 3. with every particle frozen, the contacts and rigid-point contacts of the dynamic
//!    bodies are projected once more: a heavy body is pushed out of the soft surface
//!    entirely instead of pushing the particles into the body.
//!
//! After the substep's velocity update, the separating velocity the pass gave a dynamic
//! body at its active contacts with a stacked soft body is removed with the soft surface
//! frozen ([`stacked_velocity_pass`]), as the ordinary velocity pass removes the one a
//! projection gives a particle: the body is pushed out of the surface, not thrown off it
//! (without this, the thickness skin a box is created in turned into 2.3 m/s upwards).
//!
//! The pass is one-way by design (the roots and, in step 3, the soft surface act as
//! infinitely heavy), so it does not conserve momentum: the impulses it leaves out are those the
//! immovable support would take, which is right for a load resting on the ground through
//! the soft body and wrong for a free one; hence the two conditions. The ordinary
//! projections still run first, so soft bodies that are not stacked (and every scene
//! without such a heavy load) behave exactly as without it. Counted in
//! [`crate::CouplingStats::stacking_passes`].
//!
//! With [`crate::StackingSettings::self_weight`] step 2 runs on every soft body
//! with roots, loaded or not: a body resting under its own weight then sags by far less
//! than one iteration per substep leaves (the setting's docs give the figures). Steps 3 and
//! the velocity pass still run only under a heavy load, and only those count as stacked.
//!
//! Cost: per iteration of a stacked soft body, one breadth-first pass over its tetrahedra,
//! about one more sweep over its constraints (each constraint at most once, in SIMD lanes,
//! colour class by colour class within a level) and one more sweep over its contacts with
//! dynamic bodies.

use hecs::{Entity, World};
use rapier3d::geometry::ColliderSet;
use tetpbd::{GroundUpSweep, Particles, SubstepContext, Surface};

use crate::contacts::corner::{project_corners, CornerContact, CornerPass};
use crate::contacts::particle::project_contacts;
use crate::contacts::particle::ParticleContact;
use crate::rigid::body::{BodyKind, BodyProxy};
use crate::rigid::collider::ColliderProxy;
use nalgebra::Vector3;
use tetpbd::ImpactReach;

/// What the pass borrows besides one soft body's contacts.
pub(crate) struct Stacking<'a> {
    pub bodies: &'a mut [BodyProxy],
    pub colliders: &'a [ColliderProxy],
    pub set: &'a ColliderSet,
    /// The ground-up sweep of this soft body, kept across substeps and frames (its levels
    /// are rebuilt when the entity, its mesh size or its roots change).
    pub sweep: &'a mut GroundUpSweep,
    /// Scratch: which particles were pinned before freezing.
    pub pinned: &'a mut Vec<bool>,
    /// Mass ratio from which a dynamic body counts as heavy.
    pub ratio: f32,
    /// `StackingSettings::self_weight`: the sweep (step 2) runs without a heavy
    /// load too.
    pub self_weight: bool,
    /// The substep (its length, and the solver's family order and kernel for the sweep).
    pub substep: SubstepContext,
    pub max_push: f32,
}

/// Whether a collider is an immovable support in the current substep: fixed, kinematic, a
/// supported body, or an anchored body its own supports hold (`contacts::support` module
/// docs; a held body takes no soft impulse, so it is a support like the ground).
pub(crate) fn immovable(cp: &ColliderProxy, bodies: &[BodyProxy]) -> bool {
    cp.body.is_none_or(|b| {
        let body = &bodies[b];
        body.is_held()
            || matches!(
                body.kind,
                BodyKind::Fixed | BodyKind::Kinematic | BodyKind::Supported
            )
    })
}

/// The proxy index of a collider's body when that body moves under soft impulses in the
/// current substep (dynamic, not held).
fn dynamic(cp: &ColliderProxy, bodies: &[BodyProxy]) -> Option<usize> {
    cp.body
        .filter(|&b| bodies[b].kind == BodyKind::Dynamic && !bodies[b].is_held())
}

/// Whether the soft body carries a dynamic body at least `ratio` times heavier than the
/// particles it touches.
fn carries_heavy(
    contacts: &[ParticleContact],
    corners: &[CornerContact],
    p: &Particles,
    surface: &Surface,
    s: &Stacking<'_>,
) -> bool {
    let heavy = |w_particle: f32, b: usize, q, n| {
        let w_body = s.bodies[b].inv_mass_at(q, n);
        w_body > 0.0 && w_particle >= s.ratio * w_body
    };
    let by_particle = contacts
        .iter()
        .filter(|c| c.ever_active && c.solve)
        .any(|c| {
            dynamic(&s.colliders[c.collider], s.bodies)
                .is_some_and(|b| heavy(p.inv_masses()[c.particle as usize], b, &c.point, &c.normal))
        });
    by_particle
        || corners.iter().filter(|k| k.ever_active).any(|k| {
            let Some(tri) = surface.triangles().get(k.triangle as usize) else {
                return false;
            };
            let w = tri.iter().map(|&i| p.inv_masses()[i as usize]).sum::<f32>() / 3.0;
            dynamic(&s.colliders[k.collider], s.bodies)
                .is_some_and(|b| heavy(w, b, &k.point, &k.normal))
        })
}

/// End of the run of items with the same collider as `items[start]`.
fn run_end<T>(items: &[T], start: usize, collider: impl Fn(&T) -> usize) -> usize {
    let key = collider(&items[start]);
    start
        + items[start..]
            .iter()
            .take_while(|t| collider(t) == key)
            .count()
}

/// Runs the stacking pass (module docs) on one soft body if it is stacked; returns `None`
/// if it did not run, otherwise whether it carried a heavy load (steps 1–3 ran; without
/// one, under [`Stacking::self_weight`], only steps 1–2).
pub(crate) fn stacking_pass(
    world: &mut World,
    entity: Entity,
    contacts: &mut [ParticleContact],
    corners: &mut [CornerContact],
    s: &mut Stacking<'_>,
) -> Option<bool> {
    let (p, surface) = world.query_one_mut::<(&Particles, &Surface)>(entity).ok()?;
    let heavy = carries_heavy(contacts, corners, p, surface, s);
    if !heavy && !s.self_weight {
        return None;
    }
    // Roots: particles in contact with an immovable support in this substep (the sweep adds
    // the pinned ones). (Those in contact at any time in the frame would change less often,
    // but keep particles frozen that already left the support, which speeds up a body
    // jumping out of the ground's contact skin.)
    let supported = contacts
        .iter()
        .filter(|c| c.active && c.solve && immovable(&s.colliders[c.collider], s.bodies))
        .map(|c| c.particle);
    let levels = s.sweep.project(world, entity, supported, &s.substep);
    if levels.unwrap_or(0) == 0 {
        return None;
    }
    if !heavy {
        return Some(false);
    }
    let (p, surface) = world
        .query_one_mut::<(&mut Particles, &Surface)>(entity)
        .ok()?;
    project_on_frozen_surface(contacts, corners, p, surface, s);
    Some(true)
}

/// After a substep in which the soft body was stacked: at every active contact with a
/// dynamic body, the body's normal velocity separating it from the soft surface is removed
/// by changing the body's velocity only (the surface frozen, as in the pass). The surface's
/// own normal velocity counts only as far as it does not separate faster than the roots
/// (the particles on the immovable support, their mean velocity without the separating
/// velocity the ordinary velocity pass removes): the push-out of the
/// surface from the support's contact thickness gives its upper particles a transient
/// velocity of `Δx/h` that a heavy body must not take over.
pub(crate) fn stacked_velocity_pass(
    contacts: &[ParticleContact],
    corners: &[CornerContact],
    p: &Particles,
    surface: &Surface,
    bodies: &mut [BodyProxy],
    colliders: &[ColliderProxy],
) {
    let (mut momentum, mut mass) = (Vector3::zeros(), 0.0f32);
    for c in contacts
        .iter()
        .filter(|c| c.active && c.solve && immovable(&colliders[c.collider], bodies))
    {
        // The root's velocity once the ordinary velocity pass has removed its separating
        // velocity from the support.
        let i = c.particle as usize;
        let v = p.velocities()[i];
        let v_support = colliders[c.collider]
            .body
            .map_or(Vector3::zeros(), |b| bodies[b].velocity_at(&c.point));
        let v = v - c.normal * c.normal.dot(&(v - v_support)).max(0.0);
        momentum += v * p.masses()[i];
        mass += p.masses()[i];
    }
    let v_roots = if mass > 0.0 {
        momentum / mass
    } else {
        Vector3::zeros()
    };
    let soft = contacts.iter().filter(|c| c.active && c.solve).map(|c| {
        (
            c.collider,
            c.point,
            c.normal,
            p.velocities()[c.particle as usize],
        )
    });
    let tri = corners.iter().filter(|k| k.active).filter_map(|k| {
        let t = surface.triangles().get(k.triangle as usize)?;
        let v: Vector3<f32> = (0..3)
            .map(|j| p.velocities()[t[j] as usize] * k.beta[j])
            .sum();
        Some((k.collider, k.point, k.normal, v))
    });
    for (collider, q, n, v_soft) in soft.chain(tri) {
        let Some(b) = dynamic(&colliders[collider], bodies) else {
            continue;
        };
        let body = &mut bodies[b];
        let v_ref = n.dot(&v_soft).max(n.dot(&v_roots));
        let vn = v_ref - n.dot(&body.velocity_at(&q));
        let w = body.inv_mass_at(&q, &n);
        if vn > 0.0 && w > 0.0 {
            body.apply_velocity_impulse(&(n * (vn / w)), &q);
        }
    }
}

/// The contacts of dynamic bodies projected once more against the soft surface frozen (every
/// particle pinned for the pass, then unpinned again unless it was pinned before).
fn project_on_frozen_surface(
    contacts: &mut [ParticleContact],
    corners: &mut [CornerContact],
    p: &mut Particles,
    surface: &Surface,
    s: &mut Stacking<'_>,
) {
    // The dynamic bodies against the frozen soft surface.
    s.pinned.clear();
    s.pinned.extend((0..p.len()).map(|i| p.is_pinned(i)));
    for i in 0..p.len() {
        // In range by construction.
        let _ = p.set_pinned(i, true);
    }
    // Only the runs of dynamic colliders (candidates are gathered collider by collider):
    // against a frozen surface nothing else can move.
    let mut i = 0;
    while i < contacts.len() {
        let end = run_end(contacts, i, |c| c.collider);
        if dynamic(&s.colliders[contacts[i].collider], s.bodies).is_some() {
            project_contacts(
                &mut contacts[i..end],
                p,
                s.bodies,
                s.colliders,
                s.set,
                s.max_push,
                &mut ImpactReach::new(f32::INFINITY),
            );
        }
        i = end;
    }
    let mut i = 0;
    while i < corners.len() {
        let end = run_end(corners, i, |k| k.collider);
        if dynamic(&s.colliders[corners[i].collider], s.bodies).is_some() {
            project_corners(
                &mut corners[i..end],
                contacts,
                p,
                surface,
                s.bodies,
                s.colliders,
                s.set,
                CornerPass::Frozen,
                s.max_push,
                &mut ImpactReach::new(f32::INFINITY),
            );
        }
        i = end;
    }
    for (i, &was) in s.pinned.iter().enumerate() {
        if !was {
            let _ = p.set_pinned(i, false);
        }
    }
}
